// The base solver: owns every loop and the parallelism; the Transfer policy
// supplies only the per-particle and per-node math, the Kernel the weights.
// Included only by the transfers' own .cpp files, which instantiate it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

#include "core/combinations.hpp"
#include "core/particle_check.hpp"
#include "core/policy_hooks.hpp"
#include "core/solver.hpp"
#include "core/solver_stages.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "core/thread_split.hpp"
#include "kernels/all.hpp"

namespace mpmtb {

// A transfer that never reads v_old scatters (m_i, p_i + dt f_i): the force
// folded into the momentum, half the row per node (NodeSums, kFolded).
template <int Dim, class Kernel, class Transfer>
constexpr bool folds_force() {
  using Policy = typename Transfer::template Policy<Dim, Kernel>;
  constexpr bool filters_old_velocity = requires(const Policy& q) {
    q.old_velocity_series();
  };
  return has_tensor_path<Policy>() && !Transfer::needs_old_velocity && !filters_old_velocity;
}

// The transfer-independent stages come from the base (core/solver_stages.hpp),
// compiled once per dimension and kernel.
template <int Dim, class Kernel, class Transfer>
class Solver final : public SolverStages<Dim, Kernel, folds_force<Dim, Kernel, Transfer>()> {
  using Policy = typename Transfer::template Policy<Dim, Kernel>;
  using StencilT = Stencil<Dim, Kernel>;
  static constexpr bool kFoldForce = folds_force<Dim, Kernel, Transfer>();
  using Base = SolverStages<Dim, Kernel, kFoldForce>;
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
  // A tensor-path policy that finishes G2P from the stencil sums in registers.
  static constexpr bool kFinishRows = kTensorPath && has_finish_rows<Policy>();
  // G2P's stencil rows go to the policy's Gather (TensorTerms::nodal: PolyPIC).
  static constexpr bool kNodalGather = [] {
    if constexpr (kTensorPath) {
      return Policy::gather_terms.nodal;
    } else {
      return false;
    }
  }();
  static constexpr bool kFiltersOldVelocity = requires(const Policy& q) {
    q.old_velocity_series();
  };
  using Base::bin;
  using Base::blocks_;
  using Base::clear_active_box;
  using Base::clear_for_unpack;
  using Base::filter_old_velocity;
  using Base::for_each_active_node;
  using Base::for_each_active_row;
  using Base::kStressRun;
  using Base::pack_velocities;
  using Base::sums_;
  using Base::sums_kept_;
  using Base::unpack_and_drain;
  using Base::unpack_and_keep;
  using Base::v_rows_;
  // The policy keeps values per particle from P2G to G2P (core/policy_hooks.hpp).
  static constexpr bool kKeeps = keeps_from_p2g<Policy>;
  // Particles whose stencils G2P computes together (for_each_in_run).
  static constexpr int kRun = 8;
  // P2G takes the policy's FoldedForm (core/tensor_transfer.hpp) where the sums
  // are folded and the kernel's transfer has it (CPDI's has not).
  static constexpr bool kFoldedForm =
      kTensorPath && kFoldForce && takes_folded_form<Dim, Kernel, Policy>;

 public:
  Solver(Parameters& transfer_params) : Base(kTensorPath), transfer_params_(transfer_params) {}

  std::string_view transfer_name() const override { return Transfer::name; }
  std::string_view kernel_name() const override { return Kernel::name; }
  bool gradient_based() const override { return transfer_is_gradient_based<Transfer>(); }

  void prepare(State<Dim>& s) override {
    s.particles.use_transfer_state(kTransferState);
    sums_.resize(s.grid.size());
    if constexpr (kTensorPath) rows_.resize(s.grid.size());
    if constexpr (kKeeps) kept_.resize(s.particles.size());
    v_rows_.resize(s.grid.size());
    this->prepare_stages(s);
  }

  void particles_to_grid(State<Dim>& s, Real dt) override {
    this->forget_start_F();
    s.particles.use_transfer_state(kTransferState);
    if constexpr (kTensorPath) {
      const NodeBox<Dim> before = s.grid.active;
      bin(s);
      clear_for_unpack(s.grid, before);
    } else {
      clear_active_box(s.grid);
      bin(s);
    }
    keep_from_scatter(s);
    const Policy policy(transfer_params_, s.grid.geo.dx);
    // The body force decided once: a possible call inside the particle's
    // scatter kept its form on the stack (perf: store-forwarding stalls).
    // The stresses a run of particles at a time, in the scatter's order, just
    // before it scatters them (the yardsticks' fused stress), into a buffer the
    // scatter reads from the first-level cache: a pass of their own wrote V0 tau
    // to a particle array, which the scatter read back. (3D block, 1 thread:
    // 1.03x, 15 interleaved rounds; 1.055x with neo-Hookean's stress in lanes.)
    const auto scatter_runs = [&]<bool kBodyForce>() {
      const Particles<Dim>& P = s.particles;
      blocks_.for_each_coloured_run(
          s, kStressRun, [&](const int* ids, int count, const int* next, int next_count) {
            Mat<Dim> tauV[kStressRun];
            s.kirchhoff_times_volume_of(std::span<const int>(ids, count), tauV);
            for (int k = 0; k < count; ++k) {
              if (k + 1 < count) {
                prefetch_particle_state(P, ids[k + 1]);
              } else if (next_count > 0) {
                prefetch_particle_state(P, next[0]);
              }
              // The next run's F_p, which its stresses read first (perf: their
              // loads missed the cache, in the blocks' order).
              if (k < next_count) prefetch_lines(&P.F[next[k]], sizeof(Mat<Dim>));
              scatter_particle<kBodyForce>(s, policy, ids[k], tauV[k], dt);
            }
          });
    };
    if (s.body_force) {
      scatter_runs.template operator()<true>();
    } else {
      scatter_runs.template operator()<false>();
    }
    if constexpr (kTensorPath) unpack_and_drain(s.grid);
  }

  void update_grid(State<Dim>& s, Real dt) override {
    Grid<Dim>& g = s.grid;
    const long rows = g.active_rows();
    const bool parallel = g.active_nodes() >= kParallelMinimum;
    const Vec<Dim> gravity = s.gravity;
    // Skipped without gravity: adding m_i 0 changes no value (only -0 to +0).
    // Where the walls cannot fold (no ghost layer meets the box) the body force
    // is added in the update's own loop, the same operations node by node,
    // instead of in a pass of its own over m_i and f_i before the fold.
    const bool has_gravity = gravity != Vec<Dim>::Zero();
    const bool folds = s.walls.may_fold(g);
    const bool gravity_in_update = has_gravity && !folds;
    if (has_gravity && folds) {
      for_each_active_node(g, [&](long i) { g.f[i] += g.m[i] * gravity; });
      this->f_written_ = true;
    }
    if (folds) s.walls.fold(g);
    Real rx = 0, ry = 0, rz = 0;  // reaction of the pinned nodes
#pragma omp parallel for schedule(static) reduction(+ : rx, ry, rz) if (parallel)
    for (long r = 0; r < rows; ++r) {
      const auto [first, count] = g.active_row(r);
      for (long i = first; i < first + count; ++i) {
        // With folded sums (kFoldForce) p_i already holds dt times the internal
        // and body forces, and f_i, zero before, is gravity alone: formed here,
        // not loaded from a field no other stage of the step reads (perf: that
        // load missed the cache, most of the pinned block's grid update), and
        // not stored (nothing reads it before the next step clears it). Where
        // the walls fold, f_i was loaded and folded before this loop.
        Vec<Dim> f_i;
        if (kFoldForce && !folds) {
          f_i = gravity_in_update ? Vec<Dim>(g.m[i] * gravity) : Vec<Dim>::Zero();
        } else {
          if (gravity_in_update) g.f[i] += g.m[i] * gravity;
          f_i = g.f[i];
        }
        if (g.m[i] > 0) {
          const Real inv_m = 1 / g.m[i];
          const Vec<Dim> v_old = g.p[i] * inv_m;
          if constexpr (Transfer::needs_old_velocity) g.v_old[i] = v_old;
          // Symplectic Euler: v_i^{n+1} = v_i^n + dt f_i / m_i (f_i includes m_i g);
          // v_old is not kept for folded sums.
          g.v[i] = v_old + dt * inv_m * f_i;
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
    if constexpr (kFiltersOldVelocity)
      filter_old_velocity(s, Policy(transfer_params_, g.geo.dx).old_velocity_series());
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
    // What the policy kept from this step's scatter, if one ran since the last G2P.
    const bool kept = std::exchange(kept_fresh_, false) && kept_.size() == P.size();
    Real J_min = std::numeric_limits<Real>::infinity(), J_max = -J_min, v2_max = 0;
    long non_finite = n, outside = n;
    const Vec<Dim> lo = g.geo.lo, hi = g.geo.hi();  // the closed box of GridGeometry::contains
    // Failure detection (core/particle_check.hpp): det F, the squared speed (one
    // square root per step, below) and the box test, over each chunk of particles
    // once it is gathered (its values still in the core's first-level cache).
    // Contiguous shares of the particles, sized by the threads' speeds in the
    // last G2P (core/thread_split.hpp).
    gather_split_.open();
    // Each thread's share, for the team the region is planned to have (a team
    // of another size, in a nested region, takes even shares without stealing).
    const int planned = n >= kParallelMinimum ? omp_get_max_threads() : 1;
    gather_shares_.open(planned);
    for (int t = 0; t < planned; ++t) {
      const auto [from, to] = gather_split_.range(t, planned, n);
      gather_shares_.set(t, from, to);
    }
    int threads_used = 1;
#pragma omp parallel reduction(min                           \
                               : J_min, non_finite, outside) \
    reduction(max                                            \
              : J_max, v2_max) if (n >= kParallelMinimum)
    {
      const int threads = omp_get_num_threads(), t = omp_get_thread_num();
      if (t == 0) threads_used = threads;
      const double start = omp_get_wtime();
      long first = 0, last = 0, gathered = 0;
      bool taken_alone = false;
      const auto take = [&] {
        if (threads == planned) return gather_shares_.next(t, threads, kChunk, first, last);
        first = n * t / threads, last = n * (t + 1) / threads;
        return !std::exchange(taken_alone, true) && first < last;
      };
      ParticleCheck<Dim> checked(lo, hi, n);
      while (take()) {
        gathered += last - first;
        for (long p0 = first; p0 < last; p0 += kRun) {
          for_each_in_run(
              P, g.geo, p0, std::min<long>(kRun, last - p0),
              [&](long p, const StencilT& st) MPMTB_INLINE_LAMBDA {
                if (p + 1 < last) prefetch_particle_state(P, p + 1);
                // kDeform = false: the finish may update F, the motion part keeps it.
                const auto finish = [&](auto&& finish_particle) MPMTB_INLINE_LAMBDA {
                  if constexpr (kDeform) {
                    finish_particle();
                  } else {
                    const Mat<Dim> F = P.F[p];
                    finish_particle();
                    P.F[p] = F;
                  }
                };
                if constexpr (kFinishRows) {
                  const auto sums =
                      TensorTransfer<Dim, Kernel>::template gather_rows<Policy::gather_terms>(
                          st, g.geo, rows_.data());
                  finish([&]() MPMTB_INLINE_LAMBDA {
                    policy.finish_rows(sums, st, P, static_cast<int>(p), dt);
                  });
                } else {
                  // Initialised in place (core/policy_hooks.hpp): an assignment would copy the
                  // policy's Gather, which for PolyPIC holds a stencil's worth of rows.
                  // (PolyPIC's, TensorTerms::nodal, is filled in place: tensor_gather_into.)
                  typename Policy::Gather gather = [&]() MPMTB_INLINE_LAMBDA {
                    if constexpr (kTensorPath && !kNodalGather) {
                      return tensor_gather(policy, st, g.geo, rows_.data());
                    } else if constexpr (kKeeps) {
                      return policy.begin_gather(st, P.x[p], kept ? &kept_[p] : nullptr);
                    } else {
                      return begin_gather(policy, st);
                    }
                  }();
                  if constexpr (kNodalGather)
                    tensor_gather_into(policy, st, g.geo, rows_.data(), gather);
                  if constexpr (!kTensorPath) {
                    st.for_each_node(
                        g.geo, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
                          policy.gather(gather, w, grad, d, g.v[node], g.v_old[node]);
                        });
                  }
                  finish([&]() MPMTB_INLINE_LAMBDA {
                    policy.finish(gather, P, static_cast<int>(p), dt);
                  });
                }
              });
        }
        checked.add(P, first, last - first);
      }
      J_min = std::min(J_min, checked.J_min()), J_max = std::max(J_max, checked.J_max());
      v2_max = std::max(v2_max, checked.v2_max());
      non_finite = std::min(non_finite, checked.first_non_finite());
      outside = std::min(outside, checked.first_outside());
      gather_split_.record(t, gathered, omp_get_wtime() - start);
    }
    gather_split_.close(threads_used);
    return {J_min, J_max, std::sqrt(v2_max), non_finite == n ? -1 : non_finite,
            outside == n ? -1 : outside};
  }

  Vec3 affine_angular_momentum(const State<Dim>& s) const override {
    Vec3 L = Vec3::Zero();
    if constexpr (Transfer::affine_momentum && Dim >= 2) {
      const Particles<Dim>& P = s.particles;
      for (std::size_t p = 0; p < P.size(); ++p) {
        // B_p = C_p D_p; L_a = m_p eps_abc B_cb (REFERENCE.md; Jiang et al. 2015).
        const Vec<Dim> D = StencilT(P.x[p], P.F[p], s.grid.geo).inertia_diagonal();
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
    this->forget_start_F();
    s.particles.use_transfer_state(kTransferState);
    clear_active_box(s.grid);
    bin(s);
    keep_from_scatter(s);
    const Policy policy(transfer_params_, s.grid.geo.dx);
    const Mat<Dim> no_stress = Mat<Dim>::Zero();
    blocks_.for_each_coloured(s,
                              [&](int p) { scatter_particle<false>(s, policy, p, no_stress, 0); });
    if constexpr (kTensorPath) {
      unpack_and_keep(s.grid);  // kept for scatter_forces (usf); musl has none
      sums_kept_ = true;
    }
  }

 private:
  // The scatter that follows writes the policy's kept values of every particle,
  // or reads them from a pass of their own before it, kKeptTogether particles
  // at a time, where the policy has one (keep_modes: PolyPIC's modes with 4
  // nodes per axis).
  void keep_from_scatter(const State<Dim>& s) {
    if constexpr (kKeeps) {
      const Particles<Dim>& P = s.particles;
      const long n = static_cast<long>(P.size());
      kept_.resize(n);
      kept_fresh_ = true;
      const Policy policy(transfer_params_, s.grid.geo.dx);
      if constexpr (requires(const StencilT* const(&st)[Policy::kKeptTogether],
                             const Vec<Dim>* const(&x)[Policy::kKeptTogether],
                             KeptOf<Policy>* const(&k)[Policy::kKeptTogether]) {
                      policy.keep_modes(st, x, k);
                    }) {
        constexpr int G = Policy::kKeptTogether;
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
        for (long a = 0; a < n; a += G) {
          // Particles a .. a + G - 1, the last one repeated past the end.
          const auto at = [&](int g) MPMTB_INLINE_LAMBDA { return std::min(a + g, n - 1); };
          [&]<int... g>(std::integer_sequence<int, g...>) MPMTB_INLINE_LAMBDA {
            const StencilT st[G] = {StencilT(P.x[at(g)], this->domain_F(P, at(g)), s.grid.geo)...};
            const StencilT* const stencils[G] = {&st[g]...};
            const Vec<Dim>* const x[G] = {&P.x[at(g)]...};
            KeptOf<Policy>* const kept[G] = {&kept_[at(g)]...};
            policy.keep_modes(stencils, x, kept);
          }
          (std::make_integer_sequence<int, G>{});
        }
      }
    }
  }

  // A particle's long records fetched one particle ahead, in P2G and G2P:
  // PolyPIC's higher modes (180 values in 3D with the cubic B-spline) and the
  // modes kept by the pass before P2G. P2G takes the particles in the blocks'
  // order, not in memory's, which the hardware's prefetcher does not follow; in
  // G2P, in memory's order, it does not keep up with records this long either.
  // Records of a few lines are left to the hardware. 3D PolyPIC at 1 thread (5-7
  // rounds): cubic 1.10x from P2G's, 1.10x more from G2P's; quadratic 1.02x
  // from each. Always inlined: out of line, GCC took the function, having only
  // prefetches, for one without effects and dropped it.
  static constexpr int kFetchAheadBytes = 256;
  MPMTB_INLINE void prefetch_particle_state(const Particles<Dim>& P, long p) const {
    constexpr int state_bytes = kTransferState * int(sizeof(Real));
    if constexpr (state_bytes >= kFetchAheadBytes)
      prefetch_lines(P.transfer_state_of(p), state_bytes);
    if constexpr (kKeeps && sizeof(KeptOf<Policy>) >= kFetchAheadBytes)
      prefetch_lines(&kept_[p], int(sizeof(KeptOf<Policy>)));
  }
  // The cache lines of `bytes` bytes from `first`.
  MPMTB_INLINE static void prefetch_lines(const void* first, int bytes) {
    const char* at = static_cast<const char*>(first);
    const auto line = [](const char* c) { return reinterpret_cast<std::uintptr_t>(c) / 64; };
    for (const char* c = at; line(c) <= line(at + bytes - 1); c += 64) __builtin_prefetch(c);
  }
  // f(p, stencil of p) for p = first, ..., first + count - 1 (count <= kRun),
  // with the stencils computed first, back to back: a stencil is a long chain
  // of dependent operations from x_p to the first row's address, which the
  // transfer of the particle before (several hundred instructions) kept the
  // core from starting ahead of time. (P2G's scatter, its stencils taken in
  // runs of a block the same way, measured no faster: 1.02x, within noise.)
  template <class F>
  MPMTB_INLINE void for_each_in_run(const Particles<Dim>& P, const GridGeometry<Dim>& geo,
                                    long first, long count, F&& f) const {
    static_assert(std::is_trivially_destructible_v<StencilT>, "the run never destroys them");
    alignas(StencilT) unsigned char bytes[kRun * sizeof(StencilT)];
    StencilT* const run = reinterpret_cast<StencilT*>(bytes);
    for (long i = 0; i < count; ++i)
      new (&run[i]) StencilT(P.x[first + i], this->domain_F(P, first + i), geo);
    for (long i = 0; i < count; ++i) f(first + i, *std::launder(&run[i]));
  }
  // tauV: V0_p tau_p (zero for the momentum part). kBodyForce = false: no body
  // force (the scene has none, or the momentum part only). dt: the step that
  // folded sums integrate the force over (kFoldForce).
  template <bool kBodyForce>
  void scatter_particle(State<Dim>& s, const Policy& policy, int p, const Mat<Dim>& tauV, Real dt) {
    const Particles<Dim>& P = s.particles;
    Grid<Dim>& g = s.grid;
    const StencilT st(P.x[p], P.F[p], g.geo);
    // core/policy_hooks.hpp. The two cases spelled out: as one call (the record
    // `kKeeps ? &kept_[p] : nullptr`), 2D PolyPIC's cubic scatter compiled
    // otherwise and ran 0.94x-0.98x (18 rounds at 1 thread).
    const auto src = [&]() MPMTB_INLINE_LAMBDA {
      if constexpr (kKeeps) {
        return prepare_source(policy, P, p, tauV, st, &kept_[p]);
      } else {
        return prepare_source(policy, P, p, tauV, st);
      }
    }();
    Real* m = g.m.data();
    Vec<Dim>* mom = g.p.data();
    Vec<Dim>* f = g.f.data();
    if constexpr (kFoldedForm) {
      FoldedForm<Dim> form;
      policy.folded_form(src, form);
      if (kBodyForce && s.body_force) {
        const Vec<Dim> mb = P.m[p] * s.body_force(P, p, s.time);
        for (int a = 0; a < Dim; ++a) form.alpha_f[1 + a] += mb[a];
      }
      this->template add_folded_form<Policy::scatter_terms>(st, g.geo, form, dt);
    } else if constexpr (kTensorPath) {
      ScatterForm<Dim> form;
      policy.scatter_form(src, form);
      if (kBodyForce && s.body_force) {
        form.alpha.template segment<Dim>(ScatterForm<Dim>::f) +=
            P.m[p] * s.body_force(P, p, s.time);
      }
      this->template add_form<Policy::scatter_terms>(st, g.geo, form, dt);
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
      this->pinned_written_.store(true, std::memory_order_relaxed);
    }
  }

  Parameters transfer_params_;
  // The fast path's G2P input: v (and v_old if the policy reads it) for the
  // transfer's gather (v alone for the F update and XPIC's filter: v_rows_).
  static constexpr bool kGatherOld = [] {
    if constexpr (kTensorPath) {
      return Policy::gather_terms.old;
    } else {
      return false;
    }
  }();
  VelocityRows<Dim, kGatherOld> rows_;
  ThreadSplit gather_split_;      // G2P's shares of the particles per thread
  StealingShares gather_shares_;  // taken in chunks of kChunk, the last ones stolen
  // G2P's chunks: whole runs, few enough that taking one costs nothing.
  static constexpr long kChunk = 16 * kRun;
  // The policy's values kept from the last scatter for G2P, and whether they
  // are that scatter's (no G2P since).
  std::vector<KeptOf<Policy>> kept_;
  bool kept_fresh_ = false;
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
    if constexpr (kCompiled<Transfer, K>) {
      [[maybe_unused]] volatile auto f1 = &make_solver<1, K, Transfer>;
      [[maybe_unused]] volatile auto f2 = &make_solver<2, K, Transfer>;
      [[maybe_unused]] volatile auto f3 = &make_solver<3, K, Transfer>;
    }
  });
}

}  // namespace mpmtb
