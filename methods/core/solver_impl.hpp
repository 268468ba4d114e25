// The base solver: owns every loop and the parallelism; the Transfer policy
// supplies only the per-particle and per-node math, the Kernel the weights.
// Included only by the transfers' own .cpp files, which instantiate it.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/nonlocal.hpp"
#include "core/solver.hpp"
#include "core/stencil.hpp"
#include "kernels/all.hpp"

namespace mpmtb {

template <int Dim, class Kernel, class Transfer>
class Solver final : public Stepper<Dim> {
  using Policy = typename Transfer::template Policy<Dim, Kernel>;
  using StencilT = Stencil<Dim, Kernel>;

 public:
  Solver(Parameters& transfer_params) : transfer_params_(transfer_params) {}

  std::string_view transfer_name() const override { return Transfer::name; }
  std::string_view kernel_name() const override { return Kernel::name; }

  void particles_to_grid(State<Dim>& s, Real dt) override {
    (void)dt;  // forces are kept apart from momentum; the grid update integrates them
    compute_stresses(s);
    clear_grid(s.grid);
    bin_particles_into_slabs(s);
    const Policy policy(transfer_params_, s.grid.geo.dx);
    // Slabs of Kernel::support cells along x: the stencils of slabs two apart never
    // overlap, so even slabs scatter in parallel, then odd ones. No locks, and the
    // summation order (and so the result) does not depend on the thread count.
    const bool parallel = static_cast<long>(s.particles.size()) >= kParallelMinimum;
    for (int phase = 0; phase < 2; ++phase) {
      const int n_slabs = static_cast<int>(slab_start_.size()) - 1;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
      for (int slab = phase; slab < n_slabs; slab += 2) {
        for (int k = slab_start_[slab]; k < slab_start_[slab + 1]; ++k) {
          scatter_particle(s, policy, slab_order_[k]);
        }
      }
    }
  }

  void update_grid(State<Dim>& s, Real dt) override {
    Grid<Dim>& g = s.grid;
    const long n = static_cast<long>(g.size());
    const Vec<Dim> gravity = s.gravity;
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long i = 0; i < n; ++i) g.f[i] += g.m[i] * gravity;
    s.walls.fold(g);
    Real rx = 0, ry = 0, rz = 0;  // reaction of the pinned nodes
#pragma omp parallel for schedule(static) reduction(+ : rx, ry, rz) if (n >= kParallelMinimum)
    for (long i = 0; i < n; ++i) {
      if (g.m[i] > 0) {
        const Real inv_m = 1 / g.m[i];
        const Vec<Dim> v_old = g.p[i] * inv_m;
        if constexpr (Transfer::needs_old_velocity) g.v_old[i] = v_old;
        // Symplectic Euler: v_i^{n+1} = v_i^n + dt f_i / m_i (f_i includes m_i g).
        g.v[i] = v_old + dt * inv_m * g.f[i];
        if (g.pinned[i]) {
          const Vec3 reaction = to3<Dim>(-g.m[i] * g.v[i]);
          rx += reaction[0], ry += reaction[1], rz += reaction[2];
          g.v[i].setZero();
        }
      } else {
        g.v_old[i].setZero();
        g.v[i].setZero();
      }
    }
    s.pin_impulse += Vec3(rx, ry, rz);
    s.walls.apply(g);
    if (!s.colliders.empty())
      s.colliders.apply(g, s.time + dt, s.collider_impulse, s.collider_work);
  }

  StepReport grid_to_particles(State<Dim>& s, Real dt) override {
    Particles<Dim>& P = s.particles;
    const Grid<Dim>& g = s.grid;
    const Policy policy(transfer_params_, g.geo.dx);
    const long n = static_cast<long>(P.size());
    Real J_min = std::numeric_limits<Real>::infinity(), J_max = -J_min, v_max = 0;
    long non_finite = n, outside = n;
#pragma omp parallel for schedule(static) reduction(min                           \
                                                    : J_min, non_finite, outside) \
    reduction(max                                                                 \
              : J_max, v_max) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      const StencilT st(P.x[p], g.geo);
      typename Policy::Gather gather;
      st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        policy.gather(gather, w, grad, d, g.v[node], g.v_old[node]);
      });
      policy.finish(gather, P, static_cast<int>(p), dt);
      // Failure detection, fused into this loop so that it costs nothing extra.
      const Real J = P.F[p].determinant();
      J_min = std::min(J_min, J);
      J_max = std::max(J_max, J);
      const Real speed = P.v[p].norm();
      v_max = std::max(v_max, speed);
      if (!std::isfinite(J) || !std::isfinite(speed) || !P.x[p].allFinite()) {
        non_finite = std::min(non_finite, p);
      } else if (!g.geo.contains(P.x[p])) {
        outside = std::min(outside, p);
      }
    }
    return {J_min, J_max, v_max, non_finite == n ? -1 : non_finite, outside == n ? -1 : outside};
  }

  void nonlocal_update(State<Dim>& s) override {
    nonlocal_.apply(s);
  }

  Vec3 affine_angular_momentum(const State<Dim>& s) const override {
    Vec3 L = Vec3::Zero();
    if constexpr (Transfer::affine_momentum && Dim >= 2) {
      const Particles<Dim>& P = s.particles;
      for (std::size_t p = 0; p < P.size(); ++p) {
        // B_p = C_p D_p; L_a = m_p eps_abc B_cb (REFERENCE.md; Jiang et al. 2015).
        const Vec<Dim> D = StencilT(P.x[p], s.grid.geo).inertia_diagonal();
        const Mat<Dim> B = P.C[p] * D.asDiagonal();
        if constexpr (Dim == 2) {
          L[2] += P.m[p] * (B(1, 0) - B(0, 1));
        } else {
          L[0] += P.m[p] * (B(2, 1) - B(1, 2));
          L[1] += P.m[p] * (B(0, 2) - B(2, 0));
          L[2] += P.m[p] * (B(1, 0) - B(0, 1));
        }
      }
    }
    return L;
  }

 private:
  void compute_stresses(const State<Dim>& s) {
    tauV_.resize(s.particles.size());
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
      s.materials[m]->kirchhoff_times_volume(s.particles, s.material_particles[m], tauV_);
    }
  }

  static void clear_grid(Grid<Dim>& g) {
    const long n = static_cast<long>(g.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long i = 0; i < n; ++i) {
      g.m[i] = 0;
      g.p[i].setZero();
      g.f[i].setZero();
      g.pinned[i] = 0;
    }
  }

  // Stable counting sort of particle ids by slab along x.
  void bin_particles_into_slabs(const State<Dim>& s) {
    const auto& geo = s.grid.geo;
    constexpr int width = Kernel::support;
    const int n_slabs = (geo.cells[0] + 2 * GridGeometry<Dim>::pad) / width + 1;
    const auto& x = s.particles.x;
    slab_of_.resize(x.size());
    slab_start_.assign(n_slabs + 1, 0);
    for (std::size_t p = 0; p < x.size(); ++p) {
      const Real cell = std::floor((x[p][0] - geo.lo[0]) / geo.dx) + GridGeometry<Dim>::pad;
      const int slab = std::clamp(static_cast<int>(cell) / width, 0, n_slabs - 1);
      slab_of_[p] = slab;
      ++slab_start_[slab + 1];
    }
    for (int k = 0; k < n_slabs; ++k) slab_start_[k + 1] += slab_start_[k];
    slab_order_.resize(x.size());
    std::vector<int> fill(slab_start_.begin(), slab_start_.end() - 1);
    for (std::size_t p = 0; p < x.size(); ++p)
      slab_order_[fill[slab_of_[p]]++] = static_cast<int>(p);
  }

  void scatter_particle(State<Dim>& s, const Policy& policy, int p) {
    const Particles<Dim>& P = s.particles;
    Grid<Dim>& g = s.grid;
    const StencilT st(P.x[p], g.geo);
    const auto src = policy.prepare(P, p, tauV_[p]);
    const bool pinned = P.pinned[p];
    const bool has_body_force = static_cast<bool>(s.body_force);
    const Vec<Dim> mb =
        has_body_force ? Vec<Dim>(P.m[p] * s.body_force(P, p, s.time)) : Vec<Dim>::Zero();
    st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
      policy.scatter(src, w, grad, d, g.m[node], g.p[node], g.f[node]);
      if (has_body_force) g.f[node] += w * mb;
      if (pinned && w > 0) g.pinned[node] = 1;
    });
  }

  Parameters transfer_params_;
  std::vector<Mat<Dim>> tauV_;  // V0_p tau_p, from the materials
  std::vector<int> slab_of_, slab_start_, slab_order_;
  NonlocalLaplacian<Dim, Kernel> nonlocal_;
};

template <int Dim, class Kernel, class Transfer>
std::unique_ptr<Stepper<Dim>> make_solver(Parameters& transfer_params) {
  // Validate the transfer's parameters once, up front.
  {
    Parameters probe = transfer_params;
    typename Transfer::template Policy<Dim, Kernel> check(probe, 1);
    probe.reject_unknown();
  }
  return std::make_unique<Solver<Dim, Kernel, Transfer>>(transfer_params);
}

template <class Transfer>
void SolverInstances<Transfer>::instantiate() {
  AllKernels::for_each([]<class K>() {
    if constexpr (Transfer::template supports<K>) {
      [[maybe_unused]] volatile auto f1 = &make_solver<1, K, Transfer>;
      [[maybe_unused]] volatile auto f2 = &make_solver<2, K, Transfer>;
      [[maybe_unused]] volatile auto f3 = &make_solver<3, K, Transfer>;
    }
  });
}

}  // namespace mpmtb
