// The stages of a step that do not depend on the transfer scheme, compiled once
// per dimension, kernel and layout of the P2G sums (core/solver_stages_*d.cpp)
// instead of once per transfer: the gradient-based force scatter and F update
// of the split orders (usf, musl), the grid velocities that update F, XPIC's
// filter of v_old, the stresses, the scatter's bookkeeping (binning, clearing
// and unpacking the sums) and the nonlocal Laplacian. Each transfer's Solver (core/solver_impl.hpp)
// derives from this class and adds its own P2G, grid update and G2P. Only the
// declarations are here, so that a transfer's file does not compile these
// stages again (core/solver_stages_impl.hpp holds the definitions).
#pragma once

#include <atomic>
#include <utility>
#include <vector>

#include "core/nonlocal.hpp"
#include "core/particle_blocks.hpp"
#include "core/stepper.hpp"
#include "core/tensor_transfer.hpp"

namespace mpmtb {

// kFold: the P2G sums hold (m_i, p_i + dt f_i), the force folded into the
// momentum (NodeSums, TensorTransfer::scatter_folded).
template <int Dim, class Kernel, bool kFold>
class SolverStages : public Stepper<Dim> {
 public:
  // tensor_path: the transfer's momentum goes through the P2G sums (its policy
  // declares the tensor-product form, core/tensor_transfer.hpp), so that the
  // force part of the split P2G adds to the momentum sums scatter_momentum left.
  explicit SolverStages(bool tensor_path) : tensor_path_(tensor_path) {}

  // The stages are never inlined: their code is emitted once, in the file that
  // instantiates them (instantiate()), whatever the optimiser decides there.
  // They run once per step, so the call costs nothing.
  [[gnu::noinline]] void scatter_forces(State<Dim>& s, Real dt) override;
  [[gnu::noinline]] void grid_velocities(State<Dim>& s, Real t) override;
  [[gnu::noinline]] StepReport update_deformation(State<Dim>& s, Real dt) override;
  [[gnu::noinline]] void nonlocal_update(State<Dim>& s) override;
  // The one-time allocations of these stages (Stepper::prepare): P2G's blocks
  // and the nonlocal Laplacian's fields.
  [[gnu::noinline]] void prepare_stages(const State<Dim>& s);

  // Instantiates every stage for this combination (core/solver_stages_*d.cpp).
  static void instantiate(SolverStages& self, State<Dim>& s);

 protected:
  using StencilT = Stencil<Dim, Kernel>;
  using Sums = TensorTransfer<Dim, Kernel>;

  // V0_p tau_p of every particle, from the materials, into tauV_.
  [[gnu::noinline]] void compute_stresses(const State<Dim>& s);
  // The particles P2G's scatter takes at a time (ParticleBlocks::for_each_coloured_run)
  // after their stresses (State::kirchhoff_times_volume_of): one batch of the
  // models' logarithms (ModelBase).
  static constexpr int kStressRun = 64;
  // Zeroes every nodal field over the active box of the previous step: the grid
  // is zero everywhere before the scatter, at a cost that follows the particles.
  [[gnu::noinline]] void clear_active_box(Grid<Dim>& g);
  // The same before a scatter whose sums the unpack writes to m_i and p_i (and
  // f_i, unfolded) over the new active box, which the grid update then sweeps
  // whole, writing v_i (and v_i_old for the transfers that read it): called
  // after bin() with the box of the previous step, it zeroes every field only
  // where the new box leaves the old one, and within it only what a stage wrote
  // that this step does not write again: f_i where the grid update added gravity
  // to it (folded sums: f_written_) and the pinned flags (pinned_written_).
  // v_i_old stays zero for the transfers that never read it: no explicit stage
  // writes it for them (the implicit integrator, which does, scatters through
  // scatter_momentum, which clears the whole box).
  // (Clearing every field of the box was 1.9 % of the 3D block's step at 1
  // thread; the fields rewritten then cost more to write, their cache lines no
  // longer brought in by the clear: 0.5-1 % net, measured by perf.)
  [[gnu::noinline]] void clear_for_unpack(Grid<Dim>& g, const NodeBox<Dim>& before);
  // The active box and P2G's blocks for the particles' positions.
  [[gnu::noinline]] void bin(State<Dim>& s);
  // m_i, p_i, f_i <- the scatter's sums over the active box (NodeSums::unpack),
  // the sums then zeroed (drained) or kept for scatter_forces.
  [[gnu::noinline]] void unpack_and_drain(Grid<Dim>& g);
  [[gnu::noinline]] void unpack_and_keep(Grid<Dim>& g);
  // v_old <- sum_j c_j Q^j v_old over the active box, Q the particle projection
  // (XPIC: the policy's old_velocity_series(); after P2G, before the particles move).
  [[gnu::noinline]] void filter_old_velocity(State<Dim>& s, const std::vector<Real>& c);

  // The form into the P2G sums, folded with dt or not (kFold).
  template <TensorTerms T>
  void add_form(const StencilT& st, const GridGeometry<Dim>& geo, const ScatterForm<Dim>& form,
                Real dt) {
    if constexpr (kFold) {
      Sums::template scatter_folded<T>(st, geo, form, dt, sums_.data());
    } else {
      Sums::template scatter<T>(st, geo, form, sums_.data());
    }
  }
  // The same from a policy's FoldedForm (folded sums only).
  template <TensorTerms T>
  void add_folded_form(const StencilT& st, const GridGeometry<Dim>& geo,
                       const FoldedForm<Dim>& form, Real dt) requires(kFold&& Dim >= 2) {
    Sums::template scatter_folded_form<T>(st, geo, form, dt, sums_.data());
  }

  // The gathers' input: v and v_old (if the rows hold it) packed over the active
  // box (VelocityRows), which holds every stencil of the particles that scattered.
  template <class Rows>
  static void pack_velocities(Rows& rows_out, const Grid<Dim>& g, const Vec<Dim>* v,
                              const Vec<Dim>* v_old) {
    rows_out.resize(g.size());
    for_each_active_row(g, [&](long first, long count) { rows_out.pack(first, count, v, v_old); });
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

  // The F that shapes the particle domains (kernel_deformed_domain: cpGIMP, CPDI)
  // within a step: F_p at the step's start, also once update_deformation has moved
  // F on (usf), so that the force scatter and G2P use the momentum scatter's
  // stencils. Other kernels ignore it.
  const Mat<Dim>& domain_F(const Particles<Dim>& P, long p) const {
    if constexpr (kernel_deformed_domain<Kernel>) {
      if (F_start_kept_) return F_start_[p];
    }
    return P.F[p];
  }
  // A new step's P2G: the domains follow the particles' current F again.
  void forget_start_F() { F_start_kept_ = false; }

  std::vector<Mat<Dim>> tauV_;  // V0_p tau_p, from the materials
  NodeSums<Dim, kFold> sums_;   // the fast path's P2G accumulator
  bool sums_kept_ = false;      // sums_ holds scatter_momentum's sums (see clear_active_box)
  bool f_written_ = false;      // folded sums: the grid update wrote f_i (clear_for_unpack)
  std::atomic<bool> pinned_written_{false};  // the scatter flagged pinned nodes (the same)
  VelocityRows<Dim, false> v_rows_;          // v alone: the F update, XPIC's filter
  ParticleBlocks<Dim, Kernel> blocks_;       // P2G's colouring (core/particle_blocks.hpp)

 private:
  // f_i += -V0_p tau_p grad w_ip + w_ip m_p b_p for particle p.
  void scatter_force(State<Dim>& s, int p, Real dt);

  bool tensor_path_;
  std::vector<Mat<Dim>> F_start_;  // domain_F: F_p before update_deformation
  bool F_start_kept_ = false;
  std::vector<Real> m_kept_;  // grid_velocities: m and p before the walls fold them
  std::vector<Vec<Dim>> p_kept_;
  NonlocalLaplacian<Dim, Kernel> nonlocal_;
  // Scratch of filter_old_velocity: nodal field, sums and masses; particle values.
  std::vector<Vec<Dim>> q_field_, q_sum_, q_particle_;
  std::vector<Real> q_mass_;
  NodeSums<Dim, true> q_sums_;  // the scatter's (m, m u) rows, zero between scatters
};

}  // namespace mpmtb
