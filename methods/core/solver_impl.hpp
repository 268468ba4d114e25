// The base solver: owns every loop and the parallelism; the Transfer policy
// supplies only the per-particle and per-node math, the Kernel the weights.
// Included only by the transfers' own .cpp files, which instantiate it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "core/nonlocal.hpp"
#include "core/particle_blocks.hpp"
#include "core/policy_hooks.hpp"
#include "core/solver.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "kernels/all.hpp"

namespace mpmtb {

template <int Dim, class Kernel, class Transfer>
class Solver final : public Stepper<Dim> {
  using Policy = typename Transfer::template Policy<Dim, Kernel>;
  using StencilT = Stencil<Dim, Kernel>;
  // The policy's transfers as sums over the stencil (core/tensor_transfer.hpp),
  // or, for a policy that does not declare them, its per-node math.
  static constexpr bool kTensorPath = has_tensor_path<Policy>();
  // Per-particle values the transfer keeps between steps (Particles::transfer_state).
  static constexpr int kTransferState = [] {
    if constexpr (requires { Policy::transfer_state_size; }) {
      return Policy::transfer_state_size;
    } else {
      return 0;
    }
  }();
  // A policy that declares old_velocity_series() has the grid update replace
  // v_old by a polynomial in the particle projection (filter_old_velocity; XPIC).
  static constexpr bool kFiltersOldVelocity = requires(const Policy& q) {
    q.old_velocity_series();
  };
  // A transfer that never reads v_old scatters (m_i, p_i + dt f_i): the force
  // folded into the momentum, half the row per node (NodeSums, kFolded).
  static constexpr bool kFoldForce =
      kTensorPath && !Transfer::needs_old_velocity && !kFiltersOldVelocity;

 public:
  Solver(Parameters& transfer_params) : transfer_params_(transfer_params) {}

  std::string_view transfer_name() const override { return Transfer::name; }
  std::string_view kernel_name() const override { return Kernel::name; }
  bool gradient_based() const override { return transfer_is_gradient_based<Transfer>(); }

  void prepare(const State<Dim>& s) override {
    sums_.resize(s.grid.size());
    if constexpr (kTensorPath) rows_.resize(s.grid.size());
    v_rows_.resize(s.grid.size());
  }

  void particles_to_grid(State<Dim>& s, Real dt) override {
    compute_stresses(s);
    s.particles.use_transfer_state(kTransferState);
    clear_active_box(s.grid);
    blocks_.bin(s);
    const Policy policy(transfer_params_, s.grid.geo.dx);
    blocks_.for_each_coloured(s, [&](int p) { scatter_particle<true>(s, policy, p, dt); });
    if constexpr (kTensorPath) unpack_sums<true, true>(s.grid);
  }

  void update_grid(State<Dim>& s, Real dt) override {
    Grid<Dim>& g = s.grid;
    const long rows = g.active_rows();
    const bool parallel = g.active_nodes() >= kParallelMinimum;
    const Vec<Dim> gravity = s.gravity;
    for_each_active_node(g, [&](long i) { g.f[i] += g.m[i] * gravity; });
    s.walls.fold(g);
    Real rx = 0, ry = 0, rz = 0;  // reaction of the pinned nodes
#pragma omp parallel for schedule(static) reduction(+ : rx, ry, rz) if (parallel)
    for (long r = 0; r < rows; ++r) {
      const auto [first, count] = g.active_row(r);
      for (long i = first; i < first + count; ++i) {
        if (g.m[i] > 0) {
          const Real inv_m = 1 / g.m[i];
          const Vec<Dim> v_old = g.p[i] * inv_m;
          if constexpr (Transfer::needs_old_velocity) g.v_old[i] = v_old;
          // Symplectic Euler: v_i^{n+1} = v_i^n + dt f_i / m_i (f_i includes m_i g).
          // With folded sums (kFoldForce) p_i already holds dt times the internal
          // and body forces, and f_i is gravity alone; v_old is then not kept.
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
    }
    s.pin_impulse += Vec3(rx, ry, rz);
    if constexpr (kFiltersOldVelocity) filter_old_velocity(s);
    s.walls.apply(g);
    if (!s.colliders.empty())
      s.colliders.apply(g, s.time + dt, s.collider_impulse, s.collider_work);
  }

  StepReport grid_to_particles(State<Dim>& s, Real dt) override {
    return gather_particles<true>(s, dt);
  }
  StepReport move_particles(State<Dim>& s, Real dt) override {
    return gather_particles<false>(s, dt);
  }

  // G2P; kDeform = false keeps F (the motion part of usf and musl).
  template <bool kDeform>
  StepReport gather_particles(State<Dim>& s, Real dt) {
    Particles<Dim>& P = s.particles;
    const Grid<Dim>& g = s.grid;
    const Policy policy(transfer_params_, g.geo.dx);
    P.use_transfer_state(kTransferState);
    if constexpr (kTensorPath) pack_velocities(rows_, g, g.v.data(), g.v_old.data());
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
      if constexpr (kTensorPath) {
        gather = tensor_gather(policy, st, g.geo, rows_.data());  // core/policy_hooks.hpp
      } else {
        gather = begin_gather(policy, st);  // core/policy_hooks.hpp
        st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
          policy.gather(gather, w, grad, d, g.v[node], g.v_old[node]);
        });
      }
      if constexpr (kDeform) {
        policy.finish(gather, P, static_cast<int>(p), dt);
      } else {
        const Mat<Dim> F = P.F[p];
        policy.finish(gather, P, static_cast<int>(p), dt);
        P.F[p] = F;
      }
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

  // The split stages of the other update orders (core/stepper.hpp).
  // P2G momentum part: the transfer's own P2G with zero stress and no body force.
  void scatter_momentum(State<Dim>& s) override {
    tauV_.assign(s.particles.size(), Mat<Dim>::Zero());
    s.particles.use_transfer_state(kTransferState);
    clear_active_box(s.grid);
    blocks_.bin(s);
    const Policy policy(transfer_params_, s.grid.geo.dx);
    blocks_.for_each_coloured(s, [&](int p) { scatter_particle<false>(s, policy, p, 0); });
    if constexpr (kTensorPath) {
      unpack_sums<true, false>(s.grid);  // kept for scatter_forces (usf); musl has none
      sums_kept_ = true;
    }
  }
  // Force, on the blocks scatter_momentum binned (the particles have not moved),
  // added to the momentum sums that scatter_momentum left.
  void scatter_forces(State<Dim>& s, Real dt) override {
    compute_stresses(s);
    blocks_.for_each_coloured(s, [&](int p) { scatter_force(s, p, dt); });
    unpack_sums<kTensorPath, true>(s.grid);
    sums_kept_ = false;
  }

  // v_i = p_i / m_i with walls, pinned nodes and colliders, for the F update.
  // Folding the walls' ghosts changes m and p, which the grid update that may
  // follow (usf) folds again, so they are kept and restored; no impulse is
  // exchanged with the boundaries here, so none is recorded.
  void grid_velocities(State<Dim>& s, Real t) override {
    Grid<Dim>& g = s.grid;
    m_kept_.resize(g.m.size());
    p_kept_.resize(g.p.size());
    for_each_active_row(g, [&](long first, long count) {
      std::copy_n(g.m.begin() + first, count, m_kept_.begin() + first);
      std::copy_n(g.p.begin() + first, count, p_kept_.begin() + first);
    });
    s.walls.fold(g);
    for_each_active_node(g, [&](long i) {
      if (g.m[i] > 0 && !g.pinned[i]) {
        g.v[i] = g.p[i] / g.m[i];
      } else {
        g.v[i].setZero();
      }
    });
    s.walls.apply(g);
    if (!s.colliders.empty()) {
      Vec3 impulse = Vec3::Zero();
      Real work = 0;
      s.colliders.apply(g, t, impulse, work);
    }
    for_each_active_row(g, [&](long first, long count) {
      std::copy_n(m_kept_.begin() + first, count, g.m.begin() + first);
      std::copy_n(p_kept_.begin() + first, count, g.p.begin() + first);
    });
  }

  // F_p <- (I + dt sum_i v_i grad w_ip^T) F_p, the F update of every
  // gradient-based transfer (Sulsky et al. 1994), from the grid's v.
  StepReport update_deformation(State<Dim>& s, Real dt) override {
    Particles<Dim>& P = s.particles;
    const Grid<Dim>& g = s.grid;
    pack_velocities(v_rows_, g, g.v.data(), nullptr);
    const long n = static_cast<long>(P.size());
    Real J_min = std::numeric_limits<Real>::infinity(), J_max = -J_min;
    long non_finite = n;
#pragma omp parallel for schedule(static) reduction(min                  \
                                                    : J_min, non_finite) \
    reduction(max                                                        \
              : J_max) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      const StencilT st(P.x[p], g.geo);
      const Mat<Dim> G =
          TensorTransfer<Dim, Kernel>::template gather<TensorTerms{.gradient = true}>(
              st, g.geo, v_rows_.data())
              .G;
      P.F[p] = (Mat<Dim>::Identity() + dt * G) * P.F[p];
      const Real J = P.F[p].determinant();
      J_min = std::min(J_min, J);
      J_max = std::max(J_max, J);
      if (!std::isfinite(J)) non_finite = std::min(non_finite, p);
    }
    return {J_min, J_max, 0, non_finite == n ? -1 : non_finite, -1};
  }

 private:
  void compute_stresses(const State<Dim>& s) {
    tauV_.resize(s.particles.size());
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
      s.materials[m]->kirchhoff_times_volume(s.particles, s.material_particles[m], tauV_);
    }
  }

  // Zeroes every nodal field over the active box of the previous step: the grid
  // is zero everywhere before the scatter, at a cost that follows the particles.
  // The scatter's sums are zero outside the calls that fill and drain them, but
  // for those that scatter_momentum kept and no scatter_forces drained (musl).
  void clear_active_box(Grid<Dim>& g) {
    sums_.resize(g.size());
    const bool clear_sums = std::exchange(sums_kept_, false);
    for_each_active_row(g, [&](long first, long count) {
      std::fill_n(g.m.begin() + first, count, Real(0));
      std::fill_n(g.p.begin() + first, count, Vec<Dim>::Zero());
      std::fill_n(g.f.begin() + first, count, Vec<Dim>::Zero());
      std::fill_n(g.v.begin() + first, count, Vec<Dim>::Zero());
      std::fill_n(g.v_old.begin() + first, count, Vec<Dim>::Zero());
      std::fill_n(g.pinned.begin() + first, count, std::uint8_t{0});
      if (clear_sums) sums_.clear(first, count);
    });
  }

  // m_i, p_i, f_i <- the scatter's sums over the active box (NodeSums::unpack).
  template <bool kMomentum, bool kDrain>
  void unpack_sums(Grid<Dim>& g) {
    for_each_active_row(g, [&](long first, long count) {
      sums_.template unpack<kMomentum, kDrain>(first, count, g.m.data(), g.p.data(), g.f.data());
    });
  }

  // The gathers' input: v and v_old (if the rows hold it) packed over the active
  // box (VelocityRows), which holds every stencil of the particles that scattered.
  template <class Rows>
  void pack_velocities(Rows& rows_out, const Grid<Dim>& g, const Vec<Dim>* v,
                       const Vec<Dim>* v_old) {
    rows_out.resize(g.size());
    for_each_active_row(g, [&](long first, long count) { rows_out.pack(first, count, v, v_old); });
  }

  // kBodyForce = false: the momentum part only (tauV_ is zero then). dt: the
  // step that folded sums integrate the force over (kFoldForce).
  template <bool kBodyForce>
  void scatter_particle(State<Dim>& s, const Policy& policy, int p, Real dt) {
    const Particles<Dim>& P = s.particles;
    Grid<Dim>& g = s.grid;
    const StencilT st(P.x[p], g.geo);
    const auto src = prepare_source(policy, P, p, tauV_[p], st);  // core/policy_hooks.hpp
    Real* m = g.m.data();
    Vec<Dim>* mom = g.p.data();
    Vec<Dim>* f = g.f.data();
    if constexpr (kTensorPath) {
      ScatterForm<Dim> form;
      policy.scatter_form(src, form);
      if (kBodyForce && s.body_force) {
        form.alpha.template segment<Dim>(ScatterForm<Dim>::f) +=
            P.m[p] * s.body_force(P, p, s.time);
      }
      add_form(st, g.geo, form, dt);
    } else if (!kBodyForce || !s.body_force) {
      st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        policy.scatter(src, w, grad, d, m[node], mom[node], f[node]);
      });
    } else {
      const Vec<Dim> mb = P.m[p] * s.body_force(P, p, s.time);
      st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        policy.scatter(src, w, grad, d, m[node], mom[node], f[node]);
        f[node] += w * mb;
      });
    }
    if (P.pinned[p]) {
      st.for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
        if (w > 0) g.pinned[node] = 1;
      });
    }
  }

  // f_i += -V0_p tau_p grad w_ip + w_ip m_p b_p: the force of a gradient-based
  // transfer (Sulsky et al. 1994), the force part of the split P2G.
  void scatter_force(State<Dim>& s, int p, Real dt) {
    const Particles<Dim>& P = s.particles;
    Grid<Dim>& g = s.grid;
    using Form = ScatterForm<Dim>;
    Form form;
    for (int a = 0; a < Dim; ++a) form.beta[a].template segment<Dim>(Form::f) = -tauV_[p].col(a);
    if (s.body_force)
      form.alpha.template segment<Dim>(Form::f) = P.m[p] * s.body_force(P, p, s.time);
    add_form<TensorTerms{.gradient = true}>(StencilT(P.x[p], g.geo), g.geo, form, dt);
  }

  // The form into the P2G sums, folded with dt or not (kFoldForce).
  template <TensorTerms T = Policy::scatter_terms>
  void add_form(const StencilT& st, const GridGeometry<Dim>& geo, const ScatterForm<Dim>& form,
                Real dt) {
    using Sums = TensorTransfer<Dim, Kernel>;
    if constexpr (kFoldForce) {
      Sums::template scatter_folded<T>(st, geo, form, dt, sums_.data());
    } else {
      Sums::template scatter<T>(st, geo, form, sums_.data());
    }
  }

  // v_old <- sum_j c_j Q^j v_old, c = the policy's old_velocity_series(), with
  // Q = S+ S the particle projection of a nodal field: interpolate it to the
  // particles (S, u_p = sum_i w_ip u_i), scatter it back mass-weighted
  // (S+, u_i = sum_p w_ip m_p u_p / sum_p w_ip m_p). The scatter runs over P2G's
  // blocks and colours (the particles have not moved since), so the result does
  // not depend on the thread count. Particles and nodes as in this step's P2G.
  void filter_old_velocity(State<Dim>& s) {
    Grid<Dim>& g = s.grid;
    const Particles<Dim>& P = s.particles;
    const std::vector<Real> c = Policy(transfer_params_, g.geo.dx).old_velocity_series();
    const long n = static_cast<long>(P.size());
    if (c.size() > 1) {
      q_field_.resize(g.size()), q_sum_.resize(g.size()), q_mass_.resize(g.size());
      q_particle_.resize(n);
    }
    for_each_active_node(g, [&](long i) {
      if (c.size() > 1) q_field_[i] = g.v_old[i];
      g.v_old[i] *= c[0];
    });
    for (std::size_t j = 1; j < c.size(); ++j) {
      pack_velocities(v_rows_, g, q_field_.data(), nullptr);
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
      for (long p = 0; p < n; ++p) {
        q_particle_[p] = TensorTransfer<Dim, Kernel>::template gather<TensorTerms{}>(
                             StencilT(P.x[p], g.geo), g.geo, v_rows_.data())
                             .v;
      }
      const bool with_mass = j == 1;  // the nodal masses of S+ do not change within the step
      for_each_active_node(g, [&](long i) {
        q_sum_[i].setZero();
        if (with_mass) q_mass_[i] = 0;
      });
      blocks_.for_each_coloured(s, [&](int p) {
        StencilT(P.x[p], g.geo)
            .for_each_node(g.geo, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
              const Real wm = w * P.m[p];
              q_sum_[node] += wm * q_particle_[p];
              if (with_mass) q_mass_[node] += wm;
            });
      });
      for_each_active_node(g, [&](long i) {
        if (q_mass_[i] > 0) {
          q_field_[i] = q_sum_[i] / q_mass_[i];
        } else {
          q_field_[i].setZero();
        }
        g.v_old[i] += c[j] * q_field_[i];
      });
    }
  }

  // f(first, count) for every row of the active box (runs of consecutive nodes
  // along the last axis), in parallel.
  template <class F>
  static void for_each_active_row(const Grid<Dim>& g, F&& f) {
    g.active.for_each_row(g.geo.strides(), f);
  }
  // f(node) for every node of the active box, in parallel over its rows.
  template <class F>
  static void for_each_active_node(const Grid<Dim>& g, F&& f) {
    g.active.for_each_node(g.geo.strides(), f);
  }

  Parameters transfer_params_;
  std::vector<Real> m_kept_;  // grid_velocities: m and p before the walls fold them
  std::vector<Vec<Dim>> p_kept_;
  std::vector<Mat<Dim>> tauV_;      // V0_p tau_p, from the materials
  NodeSums<Dim, kFoldForce> sums_;  // the fast path's P2G accumulator
  bool sums_kept_ = false;          // sums_ holds scatter_momentum's sums (see clear_active_box)
  // The fast path's G2P input: v (and v_old if the policy reads it) for the
  // transfer's gather, v alone for the gradient-based F update and XPIC's filter.
  static constexpr bool kGatherOld = [] {
    if constexpr (kTensorPath) {
      return Policy::gather_terms.old;
    } else {
      return false;
    }
  }();
  VelocityRows<Dim, kGatherOld> rows_;
  VelocityRows<Dim, false> v_rows_;
  ParticleBlocks<Dim, Kernel> blocks_;  // P2G's colouring (core/particle_blocks.hpp)
  // Scratch of filter_old_velocity: nodal field, sums and masses; particle values.
  std::vector<Vec<Dim>> q_field_, q_sum_, q_particle_;
  std::vector<Real> q_mass_;
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
