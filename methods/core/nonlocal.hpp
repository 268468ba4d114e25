// Grid Laplacian of a particle state variable, for nonlocal (gradient-
// regularised) models such as the damage length scale of AnisoMPM (Wolper,
// Chen, Li, Fang, Jiang 2020, "AnisoMPM", ACM TOG 39(4): the l0^2 lap d term
// of the damage evolution; REFERENCE.md "Damage"), and its anisotropic form
// div(A grad q) for a grain in the length scale (below).
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
//
// Anisotropic operator div(A grad q), for a request with a structural tensor
// (LaplacianRequest::anisotropic(): A_p = I + alpha sum_f a_f a_f^T from the
// particle's fibres; the regularisation of anisotropic phase-field fracture,
// Teichtmeister, Kienle, Aldakheel, Keip 2017, "Phase field modeling of
// fracture in anisotropic brittle solids", Int. J. Non-Linear Mech. 97: the
// crack density (d^2 + l0^2 grad d . A grad d) / (2 l0)). When any material
// asks for it, every requesting particle takes this path (A_p = I for an
// isotropic request); otherwise the isotropic path above runs, untouched.
//   1. A is transferred like q, A_i = sum_p w_ip m_p A_p / sum_p w_ip m_p, per
//      component of its upper triangle;
//   2. at every node with mass, in conservative flux form (a sum of
//      differences of fluxes between neighbouring nodes),
//        dx^2 div_i = sum_a [A_aa(i+1/2)(q_{i+e_a} - q_i) + A_aa(i-1/2)(q_{i-e_a} - q_i)]
//                   + sum_{a != b} [F_ab(i+e_a) - F_ab(i-e_a)] / 2,
//      A_aa(i+1/2) = (A_aa,i + A_aa,{i+e_a}) / 2 at the half-node, and the cross
//      flux F_ab(j) = A_ab,j (q_{j+e_b} - q_{j-e_b}) / 2 centred at node j. Zero
//      normal flux where the material ends, as in the isotropic operator: a
//      neighbour without mass (or off the grid) contributes no A_aa flux (it
//      mirrors q_i), a missing q_{j+-e_b} inside F_ab(j) mirrors q_j, and a
//      missing node j = i+-e_a carries F_ab(j) = -F_ab(i), so the cross flux
//      through the face between i and j, (F_ab(i) + F_ab(j)) / 2, is zero;
//   3. div_p = sum_i w_ip div_i, and the diagonal, the coefficient magnitude of
//      q_i in step 2, sum_a (A_aa(i+1/2) + A_aa(i-1/2)) / dx^2 (a missing
//      neighbour's half-node taking A_aa,i: 2 Dim / dx^2 for A = I, as above),
//      interpolated the same way.
// Exactness: for a constant A, step 1 returns A (to round-off), the three-point
// and the centred mixed differences of step 2 are exact on cubics, so the
// argument above carries over: div_p = A : H (H the Hessian) exactly for
// quadratic and cubic q away from the boundary. For a variable A the flux form
// is second order. Cost: Dim (Dim + 1) / 2 more fields in the transfer and,
// per node, 2 Dim + 6 Dim (Dim - 1) reads of q instead of 2 Dim.
// The cost follows the particles: the transfer scatters in parallel over block
// colours as P2G does (core/particle_blocks.hpp; the summation order, and so
// the result, does not depend on the thread count), and the grid passes sweep
// only the box of nodes the particles reach.
// The isotropic operator is local, and its exact zeros are kept exact: where no
// particle with q_p != 0 reaches a node (outside the box `source` of the nodes
// such particles reach), q_i = +0; lap_i = +0 at a node whose neighbours and
// itself are all such nodes (outside `source` grown by one node); and lap_p =
// +0 for a particle whose stencil reaches no node of that grown box. So only
// the particles whose stencils reach `source` grown by two nodes are
// transferred (those nodes' masses decide the mirror condition of the nodes
// within one), lap_i is formed within one node of `source`, and interpolated to
// the particles that reach it; every other particle takes +0, the bits the
// whole operator gives it (tests/unit/nonlocal_test.cpp compares the two). A
// field zero everywhere (the damage before the first crack) costs one sweep
// over the particles. The anisotropic path's diagonal is nonzero everywhere:
// it always runs whole.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/huge_pages.hpp"
#include "core/particle_blocks.hpp"
#include "core/state.hpp"
#include "core/stencil.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class NonlocalLaplacian {
  using StencilT = Stencil<Dim, Kernel>;

 public:
  // Sizes the grid fields and the binning's arrays for this state, when a
  // material asks for the Laplacian (Stepper::prepare, outside the timed steps):
  // their first touch in apply() cost the pinned block's first step 39 ms (1,900
  // fresh pages of records at about 20 us each in this VM), five ordinary steps.
  void prepare(const State<Dim>& s) {
    if (!read_requests(s)) return;
    size_fields(s.grid.geo);
    blocks_.size_for(s.particles.size());
  }

  void apply(State<Dim>& s) {
    if (!read_requests(s)) return;
    const auto& geo = s.grid.geo;
    NodeBox<Dim> transfer = everywhere(), laplacian = everywhere();
    if (!aniso_ && localised_) {
      const NodeBox<Dim> source = source_nodes(s);
      // q_p = 0 everywhere: lap_p = +0 everywhere, which source_nodes wrote.
      if (source.nodes() == 0) return;
      transfer = grown(source, 2), laplacian = grown(source, 1);
    }
    mark_reach(s, transfer, laplacian);
    rebin(s);
    transfer_to_grid(s, intersection(box_, transfer));
    if (aniso_) {
      grid_divergence(geo);
    } else {
      grid_laplacian(geo, intersection(box_, laplacian));
    }
    interpolate_back(s);
  }
  // Off: the isotropic operator runs over every particle (the reference that
  // the tests compare the local operator with).
  void localise(bool on) { localised_ = on; }

 private:
  static constexpr int kComponents = Dim * (Dim + 1) / 2;
  // The transfer's node records (Stencil::add_to_records): m_i, then q_i m_i (q_i
  // after the division), then on the anisotropic path A_i's components; padded
  // so that a row of the stencil's records fills whole 16-byte registers (Strip).
  static constexpr int padded_width(int values) {
    int w = values;
    while (StencilT::S * w * static_cast<int>(sizeof(Real)) % 16 != 0) ++w;
    return w;
  }
  static constexpr int kIsoWidth = padded_width(2);
  static constexpr int kAnisoWidth = padded_width(2 + kComponents);
  static constexpr int kM = 0, kQ = 1, kA = 2;  // slots of a record
  // Index of A_ab (either order) among the upper triangle's components.
  static constexpr int comp(int a, int b) {
    return a <= b ? a * Dim - a * (a - 1) / 2 + (b - a) : comp(b, a);
  }
  // A_p = I + alpha sum_f a_f a_f^T of particle state q (I for an isotropic request).
  static Mat<Dim> structural_tensor(const LaplacianRequest& r, const Real* q) {
    Mat<Dim> A = Mat<Dim>::Identity();
    if (!r.anisotropic()) return A;
    for (const int at : r.fibers) {
      if (at < 0) continue;
      const Vec<Dim> a = Eigen::Map<const Vec<Dim>>(q + at);
      if (a.squaredNorm() > 0) A += r.alpha * (a * a.transpose());
    }
    return A;
  }

  // The materials' requests (requests_, aniso_); whether any is active.
  bool read_requests(const State<Dim>& s) {
    requests_.resize(s.materials.size());
    bool any = false;
    aniso_ = false;
    for (std::size_t k = 0; k < s.materials.size(); ++k) {
      requests_[k] = s.materials[k]->laplacian_request();
      any = any || requests_[k].active();
      aniso_ = aniso_ || requests_[k].anisotropic();
    }
    return any;
  }

  // Sizes the fields for the grid (all zero when a size changes: the first call,
  // another grid, or the other path's width); false when they were sized already.
  bool size_fields(const GridGeometry<Dim>& geo) {
    const auto n = static_cast<std::size_t>(geo.node_count());
    const int W = width();
    const bool fresh = records_.size() != n * W;
    if (fresh) {
      assign_on_huge_pages(records_, n * W, Real(0));
      assign_on_huge_pages(lap_, n, Real(0));
      diag_.clear();
    }
    if (aniso_ && diag_.size() != n) diag_.assign(n, 0);
    return fresh;
  }

  bool requested(const Particles<Dim>& P, std::size_t p) const {
    return requests_[P.material[p]].active();
  }

  // Node boxes: every node, grown by k nodes per side, and the common part.
  static NodeBox<Dim> everywhere() {
    NodeBox<Dim> b;
    b.lo.fill(std::numeric_limits<int>::min() / 2), b.hi.fill(std::numeric_limits<int>::max() / 2);
    return b;
  }
  static NodeBox<Dim> grown(NodeBox<Dim> b, int k) {
    for (int a = 0; a < Dim; ++a) b.lo[a] -= k, b.hi[a] += k;
    return b;
  }
  static NodeBox<Dim> intersection(NodeBox<Dim> b, const NodeBox<Dim>& c) {
    for (int a = 0; a < Dim; ++a)
      b.lo[a] = std::max(b.lo[a], c.lo[a]), b.hi[a] = std::min(b.hi[a], c.hi[a]);
    return b;
  }
  static constexpr int kSpan = stencil_span<Dim, Kernel>();

  // The nodes that the requesting particles with q_p != 0 (or NaN) reach; empty
  // when there are none. Min and max are exact: the box does not depend on the
  // thread count.
  // It also writes every requested particle's lap_p = +0 (and the diagonal),
  // interpolate_back's answer for a particle that reaches no nonzero lap_i: in
  // the same sweep over q_p, and a field zero everywhere then needs no other
  // (elsewhere interpolate_back writes every particle's lap_p again).
  NodeBox<Dim> source_nodes(State<Dim>& s) const {
    auto& P = s.particles;
    const Real diagonal = 2 * Dim / (s.grid.geo.dx * s.grid.geo.dx);
    // Where every material makes the same request (one material: the pinned
    // block), first a plain sweep over the state records, with no material
    // lookup per particle: while the field is zero everywhere (before the first
    // crack) it is all the operator does, and with the lookups and first nodes
    // it was 3.7 % of the pinned block's step.
    // Where it finds q_p != 0, the first nodes below read q_p alone (the sweep
    // wrote the rest).
    const LaplacianRequest* common = common_request();
    if (common && !any_source_written(P, *common, diagonal)) return NodeBox<Dim>{};
    const auto range = first_node_range<Dim, Kernel>(
        s.grid.geo, static_cast<long>(P.size()),
        [&](long p) {
          if (common) return P.state_of(p)[common->source] != 0;
          if (!requested(P, p)) return false;
          Real* q = P.state_of(p);
          const LaplacianRequest& r = requests_[P.material[p]];
          q[r.target] = 0;
          q[r.target + 1] = diagonal;
          return q[r.source] != 0;
        },
        [&](long p) -> const Vec<Dim>& { return P.x[p]; }, [](long, const AxisInts&) {});
    const AxisInts lo = range.first, hi = range.second;
    NodeBox<Dim> box;
    for (int a = 0; a < Dim; ++a) {
      box.lo[a] = lo[a];
      box.hi[a] = hi[a] == std::numeric_limits<int>::min() ? lo[a] - 1 : hi[a] + kSpan - 1;
    }
    return box;
  }

  // The request of every material, where all make the same one; else null.
  const LaplacianRequest* common_request() const {
    if (requests_.empty()) return nullptr;
    const LaplacianRequest& r = requests_[0];
    for (const LaplacianRequest& other : requests_) {
      if (!other.active() || other.source != r.source || other.target != r.target) return nullptr;
    }
    return &r;
  }
  // source_nodes' writes (lap_p = +0 and the diagonal) for every particle under
  // the common request r; true when some q_p is nonzero (or NaN).
  static bool any_source_written(Particles<Dim>& P, const LaplacianRequest& r, Real diagonal) {
    const long n = static_cast<long>(P.size());
    const long stride = P.state_size;
    Real* const q = P.state.data();
    bool nonzero = false;
#pragma omp parallel for schedule(static) reduction(|| : nonzero) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      Real* const qp = q + p * stride;
      qp[r.target] = 0;
      qp[r.target + 1] = diagonal;
      nonzero = nonzero || qp[r.source] != 0;
    }
    return nonzero;
  }

  // reach_[p]: kTransfer when particle p is requested and its stencil reaches a
  // node of `transfer`, kInterpolate when one of `laplacian` (inside transfer).
  enum Reach : std::uint8_t { kTransfer = 1, kInterpolate = 2 };
  void mark_reach(const State<Dim>& s, const NodeBox<Dim>& transfer,
                  const NodeBox<Dim>& laplacian) {
    const auto& P = s.particles;
    const long n = static_cast<long>(P.size());
    reach_.resize(n);
    const bool all = transfer.lo == everywhere().lo && laplacian.lo == everywhere().lo;
    const FirstNodes<Dim, Kernel> first_nodes(s.grid.geo);
    const auto reaches = [](const AxisInts& f, const NodeBox<Dim>& b) {
      for (int a = 0; a < Dim; ++a) {
        if (f[a] > b.hi[a] || f[a] + kSpan - 1 < b.lo[a]) return false;
      }
      return true;
    };
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      std::uint8_t r = 0;
      if (requested(P, p)) {
        if (all) {
          r = kTransfer | kInterpolate;
        } else {
          const AxisInts f = first_nodes(P.x[p]);
          if (reaches(f, transfer)) r |= kTransfer;
          if (reaches(f, laplacian)) r |= kInterpolate;
        }
      }
      reach_[p] = r;
    }
  }
  int width() const {
    return aniso_ ? kAnisoWidth : kIsoWidth;
  }
  Real m(long i) const {
    return records_[i * width() + kM];
  }
  Real q(long i) const {
    return records_[i * width() + kQ];
  }
  Real A(int c, long i) const {
    return records_[i * width() + kA + c];
  }

  // Zeroes the fields over the box of the previous call, then bins the particles
  // at their current positions into a new box: outside it every field is zero.
  void rebin(const State<Dim>& s) {
    const auto& geo = s.grid.geo;
    const int W = width();
    // A fresh diag_ (the path just turned anisotropic) is zero already.
    const bool had_diag = !diag_.empty();
    if (!size_fields(geo)) {
      box_.for_each_row(geo.strides(), [&](long first, long count) {
        std::fill_n(records_.begin() + first * W, count * W, Real(0));
        std::fill_n(lap_.begin() + first, count, Real(0));
        if (had_diag) std::fill_n(diag_.begin() + first, count, Real(0));
      });
    }
    blocks_.bin(s.particles.x, geo, box_);
  }

  // The particles marked kTransfer; the records divided by the mass over `nodes`.
  void transfer_to_grid(const State<Dim>& s, const NodeBox<Dim>& nodes) {
    const auto& P = s.particles;
    const auto& geo = s.grid.geo;
    Real* const records = records_.data();
    blocks_.for_each_coloured(s, [&](int p) {
      if (!(reach_[p] & kTransfer)) return;
      const LaplacianRequest& r = requests_[P.material[p]];
      const Real mp = P.m[p], mq = mp * P.state_of(p)[r.source];
      const StencilT st(P.x[p], P.F[p], geo);
      if (!aniso_) {  // the isotropic path
        const Real value[kIsoWidth] = {mp, mq};
        st.add_to_records(geo, value, records);
        return;
      }
      const Mat<Dim> mA = mp * structural_tensor(r, P.state_of(p));
      Real value[kAnisoWidth] = {mp, mq};
      for (int a = 0; a < Dim; ++a) {
        for (int b = a; b < Dim; ++b) value[kA + comp(a, b)] = mA(a, b);
      }
      st.add_to_records(geo, value, records);
    });
    const int W = width(), values = aniso_ ? 1 + kComponents : 1;
    nodes.for_each_node(geo.strides(), [&](long i) {
      Real* record = records + i * W;
      if (record[kM] > 0) {
        for (int c = kQ; c < kQ + values; ++c) record[c] /= record[kM];
      }
    });
  }

  // Over `nodes` (inside the box: a node with mass lies inside the particles'
  // stencils, its neighbours inside the box's pad layers).
  void grid_laplacian(const GridGeometry<Dim>& geo, const NodeBox<Dim>& nodes) {
    const Real inv_dx2 = 1 / (geo.dx * geo.dx);
    nodes.for_each_node(geo.strides(), [&](long i) {
      if (!(m(i) > 0)) return;
      const auto idx = geo.multi_index(i);
      const Real q_i = q(i);
      Real sum = 0;
      for (int a = 0; a < Dim; ++a) {
        const long stride = geo.strides()[a];
        // A neighbour off the grid or without mass mirrors the node (zero flux).
        const Real lo = idx[a] > 0 && m(i - stride) > 0 ? q(i - stride) : q_i;
        const Real hi = idx[a] + 1 < geo.nodes(a) && m(i + stride) > 0 ? q(i + stride) : q_i;
        sum += (hi - q_i) + (lo - q_i);
      }
      lap_[i] = sum * inv_dx2;
    });
  }

  // Node i's neighbour along axis a on side dir (+1 or -1), or -1 off the grid.
  static long neighbour(const GridGeometry<Dim>& geo, long i, const std::array<int, Dim>& idx,
                        int a, int dir) {
    const int k = idx[a] + dir;
    return k >= 0 && k < geo.nodes(a) ? i + dir * geo.strides()[a] : -1;
  }
  bool has_mass(long j) const {
    return j >= 0 && m(j) > 0;
  }
  // dx F_ab(j) = A_ab,j (q_{j+e_b} - q_{j-e_b}) / 2 at a node j with mass; a
  // neighbour without mass mirrors q_j.
  Real cross_flux(const GridGeometry<Dim>& geo, long j, const std::array<int, Dim>& idx, int a,
                  int b) const {
    const long hi = neighbour(geo, j, idx, b, 1), lo = neighbour(geo, j, idx, b, -1);
    const Real q_hi = has_mass(hi) ? q(hi) : q(j), q_lo = has_mass(lo) ? q(lo) : q(j);
    return A(comp(a, b), j) * (q_hi - q_lo) / 2;
  }

  // div(A grad q) in flux form (header, step 2), and its diagonal.
  void grid_divergence(const GridGeometry<Dim>& geo) {
    const Real inv_dx2 = 1 / (geo.dx * geo.dx);
    box_.for_each_node(geo.strides(), [&](long i) {
      if (!(m(i) > 0)) return;
      const auto idx = geo.multi_index(i);
      Real sum = 0, diagonal = 0;
      for (int a = 0; a < Dim; ++a) {
        const auto Aaa = [&](long j) { return A(comp(a, a), j); };
        Real F_i[Dim] = {};  // the cross fluxes at i, for the ghost -F_ab(i)
        for (int b = 0; b < Dim; ++b) {
          if (b != a) F_i[b] = cross_flux(geo, i, idx, a, b);
        }
        for (const int dir : {-1, 1}) {
          const long j = neighbour(geo, i, idx, a, dir);
          const bool inside = has_mass(j);
          const Real half = inside ? (Aaa(i) + Aaa(j)) / 2 : Aaa(i);
          diagonal += half;
          if (inside) sum += half * (q(j) - q(i));
          auto idx_j = idx;
          idx_j[a] += dir;
          for (int b = 0; b < Dim; ++b) {
            if (b == a) continue;
            const Real F_j = inside ? cross_flux(geo, j, idx_j, a, b) : -F_i[b];
            sum += dir * F_j / 2;
          }
        }
      }
      lap_[i] = sum * inv_dx2;
      diag_[i] = diagonal * inv_dx2;
    });
  }

  void interpolate_back(State<Dim>& s) {
    auto& P = s.particles;
    const auto& geo = s.grid.geo;
    const Real diagonal = 2 * Dim / (geo.dx * geo.dx);
    const Real* const lap_data = lap_.data();
    const long n = static_cast<long>(P.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      if (!requested(P, p)) continue;
      Real* q = P.state_of(p);
      const int target = requests_[P.material[p]].target;
      if (!(reach_[p] & kInterpolate)) {  // lap_i = +0 over its stencil
        q[target] = 0;
        q[target + 1] = diagonal;
        continue;
      }
      const StencilT st(P.x[p], P.F[p], geo);
      q[target] = st.interpolate(geo, lap_data);
      q[target + 1] = aniso_ ? st.interpolate(geo, diag_.data()) : diagonal;
    }
  }

  std::vector<LaplacianRequest> requests_;
  bool aniso_ = false;               // any request anisotropic in this call
  bool localised_ = true;            // the isotropic path skips the exact zeros (header)
  std::vector<std::uint8_t> reach_;  // Reach per particle
  // Over the whole grid, zero outside box_: the records (width() per node), and lap_i.
  std::vector<Real> records_, lap_;
  std::vector<Real> diag_;  // the anisotropic path's diagonal; empty until first used
  NodeBox<Dim> box_;
  ParticleBlocks<Dim, Kernel> blocks_;
};

}  // namespace mpmtb
