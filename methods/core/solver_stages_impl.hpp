// Definitions of the transfer-independent stages (core/solver_stages.hpp).
// Included only by core/solver_stages_*d.cpp, which instantiate them for every
// kernel of their dimension.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/deformation.hpp"
#include "core/solver_stages.hpp"
#include "kernels/all.hpp"

namespace mpmtb {

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::compute_stresses(const State<Dim>& s) {
  tauV_.resize(s.particles.size());
  for (std::size_t m = 0; m < s.materials.size(); ++m) {
    s.materials[m]->kirchhoff_times_volume(s.particles, s.material_particles[m], tauV_);
  }
}

// Every nodal field of the `count` nodes from `first` zeroed.
template <int Dim>
void zero_nodes(Grid<Dim>& g, long first, long count) {
  std::fill_n(g.m.begin() + first, count, Real(0));
  std::fill_n(g.p.begin() + first, count, Vec<Dim>::Zero());
  std::fill_n(g.f.begin() + first, count, Vec<Dim>::Zero());
  std::fill_n(g.v.begin() + first, count, Vec<Dim>::Zero());
  std::fill_n(g.v_old.begin() + first, count, Vec<Dim>::Zero());
  std::fill_n(g.pinned.begin() + first, count, std::uint8_t{0});
}

// The scatter's sums are zero outside the calls that fill and drain them, but
// for those that scatter_momentum kept and no scatter_forces drained (musl).
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::clear_active_box(Grid<Dim>& g) {
  sums_.resize(g.size());
  const bool clear_sums = std::exchange(sums_kept_, false);
  for_each_active_row(g, [&](long first, long count) {
    zero_nodes(g, first, count);
    if (clear_sums) sums_.clear(first, count);
  });
}

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::clear_for_unpack(Grid<Dim>& g, const NodeBox<Dim>& before) {
  sums_.resize(g.size());
  const bool clear_sums = std::exchange(sums_kept_, false);
  const auto strides = g.geo.strides();
  before.for_each_row_outside(g.active, strides,
                              [&](long first, long count) { zero_nodes(g, first, count); });
  // Over the old box (outside it every field is zero already).
  const bool clear_f = kFold && std::exchange(f_written_, false);
  const bool clear_pinned = pinned_written_.exchange(false, std::memory_order_relaxed);
  if (!clear_f && !clear_pinned && !clear_sums) return;
  before.for_each_row(strides, [&](long first, long count) {
    if (clear_f) std::fill_n(g.f.begin() + first, count, Vec<Dim>::Zero());
    if (clear_pinned) std::fill_n(g.pinned.begin() + first, count, std::uint8_t{0});
    if (clear_sums) sums_.clear(first, count);
  });
}

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::bin(State<Dim>& s) {
  blocks_.bin(s);
}

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::unpack_and_drain(Grid<Dim>& g) {
  for_each_active_row(g, [&](long first, long count) {
    sums_.template unpack<true, true>(first, count, g.m.data(), g.p.data(), g.f.data());
  });
}

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::unpack_and_keep(Grid<Dim>& g) {
  for_each_active_row(g, [&](long first, long count) {
    sums_.template unpack<true, false>(first, count, g.m.data(), g.p.data(), g.f.data());
  });
}

// Force, on the blocks scatter_momentum binned (the particles have not moved),
// added to the momentum sums that scatter_momentum left (tensor path), or alone
// in the sums (per-node path, whose momentum went straight to the grid).
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::scatter_forces(State<Dim>& s, Real dt) {
  compute_stresses(s);
  blocks_.for_each_coloured(s, [&](int p) { scatter_force(s, p, dt); });
  Grid<Dim>& g = s.grid;
  if (kFold || tensor_path_) {
    unpack_and_drain(g);
  } else if constexpr (!kFold) {
    for_each_active_row(g, [&](long first, long count) {
      sums_.template unpack<false, true>(first, count, g.m.data(), g.p.data(), g.f.data());
    });
  }
  sums_kept_ = false;
}

// f_i += -V0_p tau_p grad w_ip + w_ip m_p b_p: the force of a gradient-based
// transfer (Sulsky et al. 1994), the force part of the split P2G.
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::scatter_force(State<Dim>& s, int p, Real dt) {
  const Particles<Dim>& P = s.particles;
  using Form = ScatterForm<Dim>;
  Form form;
  for (int a = 0; a < Dim; ++a) form.beta[a].template segment<Dim>(Form::f) = -tauV_[p].col(a);
  if (s.body_force) form.alpha.template segment<Dim>(Form::f) = P.m[p] * s.body_force(P, p, s.time);
  add_form<TensorTerms{.gradient = true}>(StencilT(P.x[p], domain_F(P, p), s.grid.geo), s.grid.geo,
                                          form, dt);
}

// v_i = p_i / m_i with walls, pinned nodes and colliders, for the F update.
// Folding the walls' ghosts changes m and p, which the grid update that may
// follow (usf) folds again, so they are kept and restored; no impulse is
// exchanged with the boundaries here, so none is recorded.
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::grid_velocities(State<Dim>& s, Real t) {
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
template <int Dim, class Kernel, bool kFold>
StepReport SolverStages<Dim, Kernel, kFold>::update_deformation(State<Dim>& s, Real dt) {
  Particles<Dim>& P = s.particles;
  const Grid<Dim>& g = s.grid;
  pack_velocities(v_rows_, g, g.v.data(), nullptr);
  const long n = static_cast<long>(P.size());
  if constexpr (kernel_deformed_domain<Kernel>) F_start_.resize(n);
  Real J_min = std::numeric_limits<Real>::infinity(), J_max = -J_min;
  long non_finite = n;
#pragma omp parallel for schedule(static) reduction(min                  \
                                                    : J_min, non_finite) \
    reduction(max                                                        \
              : J_max) if (n >= kParallelMinimum)
  for (long p = 0; p < n; ++p) {
    const StencilT st(P.x[p], P.F[p], g.geo);
    if constexpr (kernel_deformed_domain<Kernel>) F_start_[p] = P.F[p];
    const Mat<Dim> G =
        Sums::template gather<TensorTerms{.gradient = true}>(st, g.geo, v_rows_.data()).G;
    deformation_update<Dim>(P.F[p], G, dt);
    const Real J = P.F[p].determinant();
    J_min = std::min(J_min, J);
    J_max = std::max(J_max, J);
    if (!std::isfinite(J)) non_finite = std::min(non_finite, p);
  }
  F_start_kept_ = kernel_deformed_domain<Kernel>;
  return {J_min, J_max, 0, non_finite == n ? -1 : non_finite, -1};
}

// v_old <- sum_j c_j Q^j v_old, c the policy's old_velocity_series(), with
// Q = S+ S the particle projection of a nodal field: interpolate it to the
// particles (S, u_p = sum_i w_ip u_i), scatter it back mass-weighted
// (S+, u_i = sum_p w_ip m_p u_p / sum_p w_ip m_p). Both go through the fast
// path's tensor-product sums, as a PIC form (node by node, the scatter took 40 %
// of XPIC(5)'s step). The scatter runs over P2G's blocks and colours (the
// particles have not moved since), so the result does not depend on the thread
// count. Particles and nodes as in this step's P2G.
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::filter_old_velocity(State<Dim>& s,
                                                           const std::vector<Real>& c) {
  Grid<Dim>& g = s.grid;
  const Particles<Dim>& P = s.particles;
  const long n = static_cast<long>(P.size());
  if (c.size() > 1) {
    q_field_.resize(g.size()), q_sum_.resize(g.size()), q_mass_.resize(g.size());
    q_sums_.resize(g.size());
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
                           StencilT(P.x[p], this->domain_F(P, p), g.geo), g.geo, v_rows_.data())
                           .v;
    }
    // (sum_i w_ip m_p, sum_i w_ip m_p u_p) as P2G's fast path sums a PIC form,
    // into rows of (m, m u) (folded sums without a force).
    blocks_.for_each_coloured(s, [&](int p) {
      using Form = ScatterForm<Dim>;
      Form form;
      form.alpha[Form::m] = P.m[p];
      form.alpha.template segment<Dim>(Form::p) = P.m[p] * q_particle_[p];
      TensorTransfer<Dim, Kernel>::template scatter_folded<TensorTerms{}>(
          StencilT(P.x[p], this->domain_F(P, p), g.geo), g.geo, form, 0, q_sums_.data());
    });
    for_each_active_row(g, [&](long first, long count) {
      q_sums_.template unpack<true, true>(first, count, q_mass_.data(), q_sum_.data(), nullptr);
    });
    // A pass of its own: fused into the unpack's row loop it measured 0.96x.
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

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::nonlocal_update(State<Dim>& s) {
  nonlocal_.apply(s);
}

template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::prepare_stages(const State<Dim>& s) {
  blocks_.size_for(s.particles.size());
  nonlocal_.prepare(s);
}

// Never called: a qualified (non-virtual) call of each stage instantiates it
// here, and, not inlined, its code is emitted for the solvers of every transfer
// to link against.
template <int Dim, class Kernel, bool kFold>
void SolverStages<Dim, Kernel, kFold>::instantiate(SolverStages& self, State<Dim>& s) {
  using S = SolverStages;
  self.S::scatter_forces(s, 0);
  self.S::grid_velocities(s, 0);
  self.S::update_deformation(s, 0);
  self.S::nonlocal_update(s);
  self.S::prepare_stages(s);
  self.S::compute_stresses(s);
  self.S::clear_active_box(s.grid);
  self.S::clear_for_unpack(s.grid, s.grid.active);
  self.S::bin(s);
  self.S::unpack_and_drain(s.grid);
  self.S::unpack_and_keep(s.grid);
  self.S::filter_old_velocity(s, {});
}

// Every kernel's stages in dimension Dim, with both layouts of the sums.
template <int Dim>
void instantiate_solver_stages() {
  AllKernels::for_each([]<class K>() {
    [[maybe_unused]] volatile auto folded = &SolverStages<Dim, K, true>::instantiate;
    [[maybe_unused]] volatile auto unfolded = &SolverStages<Dim, K, false>::instantiate;
  });
}

}  // namespace mpmtb
