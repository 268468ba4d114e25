// Grid Laplacian of a particle state variable, for nonlocal (gradient-
// regularised) models such as the damage length scale of AnisoMPM (Wolper,
// Chen, Li, Fang, Jiang 2020, "AnisoMPM", ACM TOG 39(4): the l0^2 lap d term
// of the damage evolution; REFERENCE.md "Damage").
//
// A model asks for it through ConstitutiveModel::laplacian_request(): the
// step calls apply() after G2P (positions at time n+1) and before return_map.
// The operator, for the particles of every requesting material together:
//   1. mass-weighted transfer to the grid, q_i = sum_p w_ip m_p q_p / sum_p w_ip m_p;
//   2. the standard (2 Dim + 1)-point finite-difference Laplacian at every node
//      with mass, lap_i = sum_a (q_{i+e_a} - 2 q_i + q_{i-e_a}) / dx^2, where a
//      neighbour without mass takes the value q_i (a mirror node: zero normal
//      derivative at the material's boundary, the natural boundary condition of
//      the regularised damage equation);
//   3. interpolation back, lap_p = sum_i w_ip lap_i.
// Exactness: on a particle lattice symmetric about every node (uniform ppc,
// uniform mass, away from the boundary) step 1 maps a polynomial of degree
// <= 3 to itself plus a polynomial of degree <= 1 (the kernel's even moments
// times the field's second and third derivatives); step 2 is exact on cubics,
// so lap_i is the exact Laplacian, a polynomial of degree <= 1; step 3
// reproduces linear fields (sum_i w_ip = 1, sum_i w_ip x_i = x_p for the
// B-splines). The particle Laplacian of a cubic is therefore exact to
// round-off; for degree 4 the error is O(dx^2).
// The step writes lap_p to q[target] and the magnitude 2 Dim / dx^2 of the
// grid operator's diagonal to q[target + 1], for a linearly implicit update.
// The cost follows the particles: the transfer scatters in parallel over block
// colours as P2G does (core/particle_blocks.hpp; the summation order, and so
// the result, does not depend on the thread count), and the grid passes sweep
// only the box of nodes the particles reach.
#pragma once

#include <algorithm>
#include <vector>

#include "core/particle_blocks.hpp"
#include "core/state.hpp"
#include "core/stencil.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class NonlocalLaplacian {
  using StencilT = Stencil<Dim, Kernel>;

 public:
  void apply(State<Dim>& s) {
    requests_.resize(s.materials.size());
    bool any = false;
    for (std::size_t k = 0; k < s.materials.size(); ++k) {
      requests_[k] = s.materials[k]->laplacian_request();
      any = any || requests_[k].active();
    }
    if (!any) return;
    rebin(s);
    transfer_to_grid(s);
    grid_laplacian(s.grid.geo);
    interpolate_back(s);
  }

 private:
  bool requested(const Particles<Dim>& P, std::size_t p) const {
    return requests_[P.material[p]].active();
  }

  // Zeroes the fields over the box of the previous call, then bins the particles
  // at their current positions into a new box: outside it every field is zero.
  void rebin(const State<Dim>& s) {
    const auto& geo = s.grid.geo;
    const auto n = static_cast<std::size_t>(geo.node_count());
    if (m_.size() != n) {
      m_.assign(n, 0), q_.assign(n, 0), lap_.assign(n, 0);
    } else {
      box_.for_each_row(geo.strides(), [&](long first, long count) {
        std::fill_n(m_.begin() + first, count, Real(0));
        std::fill_n(q_.begin() + first, count, Real(0));
        std::fill_n(lap_.begin() + first, count, Real(0));
      });
    }
    blocks_.bin(s.particles.x, geo, box_);
  }

  void transfer_to_grid(const State<Dim>& s) {
    const auto& P = s.particles;
    const auto& geo = s.grid.geo;
    blocks_.for_each_coloured(s, [&](int p) {
      if (!requested(P, p)) return;
      const Real mp = P.m[p], mq = mp * P.state_of(p)[requests_[P.material[p]].source];
      StencilT(P.x[p], geo)
          .for_each_node(geo, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
            m_[node] += w * mp;
            q_[node] += w * mq;
          });
    });
    box_.for_each_node(geo.strides(), [&](long i) {
      if (m_[i] > 0) q_[i] /= m_[i];
    });
  }

  // Over the box: a node with mass lies inside the particles' stencils, its
  // neighbours inside the box's pad layers.
  void grid_laplacian(const GridGeometry<Dim>& geo) {
    const Real inv_dx2 = 1 / (geo.dx * geo.dx);
    box_.for_each_node(geo.strides(), [&](long i) {
      if (!(m_[i] > 0)) return;
      const auto idx = geo.multi_index(i);
      Real sum = 0;
      for (int a = 0; a < Dim; ++a) {
        const long stride = geo.strides()[a];
        // A neighbour off the grid or without mass mirrors the node (zero flux).
        const Real lo = idx[a] > 0 && m_[i - stride] > 0 ? q_[i - stride] : q_[i];
        const Real hi = idx[a] + 1 < geo.nodes(a) && m_[i + stride] > 0 ? q_[i + stride] : q_[i];
        sum += (hi - q_[i]) + (lo - q_[i]);
      }
      lap_[i] = sum * inv_dx2;
    });
  }

  void interpolate_back(State<Dim>& s) {
    auto& P = s.particles;
    const auto& geo = s.grid.geo;
    const Real diagonal = 2 * Dim / (geo.dx * geo.dx);
    const long n = static_cast<long>(P.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      if (!requested(P, p)) continue;
      Real lap = 0;
      StencilT(P.x[p], geo)
          .for_each_node(geo, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
            lap += w * lap_[node];
          });
      Real* q = P.state_of(p);
      const int target = requests_[P.material[p]].target;
      q[target] = lap;
      q[target + 1] = diagonal;
    }
  }

  std::vector<LaplacianRequest> requests_;
  std::vector<Real> m_, q_, lap_;  // over the whole grid, zero outside box_
  NodeBox<Dim> box_;
  ParticleBlocks<Dim, Kernel> blocks_;
};

}  // namespace mpmtb
