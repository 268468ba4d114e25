// The constitutive-model interface. A model is chosen per material at run time
// and called once per material per stage (a batch over its particles), or once
// per run of P2G's scatter (kirchhoff_times_volume_of), never inside the
// particle-node loops. Concrete models derive from ModelBase, which
// writes the batch loops once over the model's per-particle formulas.
#pragma once

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/batch_exp.hpp"
#include "core/batch_log.hpp"
#include "core/lanes.hpp"
#include "core/particles.hpp"
#include "core/thread_split.hpp"
#include "core/types.hpp"

namespace mpmtb {

// What a nonlocal model asks of the step (core/nonlocal.hpp): the grid
// Laplacian of its state variable q[source], written to q[target] together
// with the grid operator's diagonal magnitude (2 Dim / dx^2 for lap q) in
// q[target + 1], after G2P and before return_map.
// Anisotropic (alpha > 0 and fibers[0] >= 0): div(A grad q) instead of lap q,
// with the per-particle symmetric tensor A_p = I + alpha sum_f a_f a_f^T built
// from the unit directions a_f stored at q[fibers[f]] .. q[fibers[f] + Dim - 1]
// (a family with a zero vector, or index -1, is left out).
struct LaplacianRequest {
  static constexpr int kMaxFibers = 2;
  int source = -1, target = -1;
  Real alpha = 0;
  std::array<int, kMaxFibers> fibers{-1, -1};
  bool active() const { return source >= 0; }
  bool anisotropic() const { return active() && alpha > 0 && fibers[0] >= 0; }
};

template <int Dim>
class ConstitutiveModel {
 public:
  virtual ~ConstitutiveModel() = default;

  virtual std::string_view name() const = 0;
  virtual Real density() const = 0;
  // P-wave speed sqrt((lambda + 2 mu) / rho): sets the CFL time step.
  virtual Real wave_speed() const = 0;
  // Internal variables per particle (plastic J, damage, ...); 0 for pure elasticity.
  virtual int state_size() const { return 0; }
  virtual void initial_state(Real* /*q*/) const {}
  // Names of the internal variables, in order (for output).
  virtual std::vector<std::string> state_names() const { return {}; }
  // Material directions, for anisotropic models: how many fibre families the
  // model takes (0: none; a model that takes any needs at least one, a body's
  // `fiber`), and set_fibers writes them (nonzero, in the reference
  // configuration) into a particle's state after initial_state.
  virtual int fiber_families() const { return 0; }
  virtual void set_fibers(Real* /*q*/, std::span<const Vec<Dim>> /*a0*/) const {}
  // Nonlocal models only (see LaplacianRequest); local models ask for nothing.
  virtual LaplacianRequest laplacian_request() const { return {}; }
  // The largest wave speed over the particles `ids` in their current state
  // (hardening raises it), for the adaptive time step; the model's wave_speed()
  // unless the stiffness depends on the state.
  virtual Real max_wave_speed(const Particles<Dim>& /*particles*/,
                              std::span<const int> /*ids*/) const {
    return wave_speed();
  }

  // Per-particle formulas, for tests and diagnostics.
  virtual Real energy_density(const Mat<Dim>& F, const Real* q) const = 0;   // psi(F)
  virtual Mat<Dim> first_piola(const Mat<Dim>& F, const Real* q) const = 0;  // P = dpsi/dF
  // dP = (dP/dF) : dF, the first elasticity tensor applied to dF, at the state q
  // held fixed (the implicit integrators' Hessian, methods/integrators/). Exact
  // for the elastic models; plasticity and damage give their elastic part at
  // the current state (the return map runs after the implicit solve).
  virtual Mat<Dim> first_piola_differential(const Mat<Dim>& F, const Mat<Dim>& dF,
                                            const Real* q) const = 0;
  // Volume ratio of the total deformation: det F, or J_E J_P when F_p holds
  // only the elastic part (plasticity). Used for the reported volume and J range.
  virtual Real total_J(const Mat<Dim>& F, const Real* /*q*/) const { return F.determinant(); }

  // Batches over the particles `ids` of this material.
  // tauV[p] = V0_p * tau(F_p), tau = P F^T the Kirchhoff stress.
  virtual void kirchhoff_times_volume(const Particles<Dim>& particles, std::span<const int> ids,
                                      std::vector<Mat<Dim>>& tauV) const = 0;
  // The same for a few particles, serially: out[k] = V0_p tau_p for p = ids[k]
  // (P2G computes its particles' stresses a batch at a time, in the scatter's
  // order, just before it scatters them: core/solver_impl.hpp).
  virtual void kirchhoff_times_volume_of(const Particles<Dim>& particles, std::span<const int> ids,
                                         Mat<Dim>* out) const = 0;
  // sum_p V0_p psi(F_p), summed in particle order (deterministic).
  virtual Real strain_energy(const Particles<Dim>& particles, std::span<const int> ids) const = 0;
  // Plastic or damage return map after F_p is updated; no-op for elasticity.
  virtual void return_map(Particles<Dim>& particles, std::span<const int> ids, Real dt) const = 0;
  // Energy the return maps have dissipated so far, sum_p V0_p d_p, so that
  // kinetic + strain + gravity + dissipated is the conserved budget.
  virtual Real dissipated_energy(const Particles<Dim>& particles,
                                 std::span<const int> ids) const = 0;
};

// Writes the batch loops once. Derived provides psi(F, q), P(F, q), tau(F, q),
// and, for plasticity or damage, project(F, q, dt): the return map of one
// particle, which may change F (to its elastic part) and q, and
// dissipated(q): the energy per unit initial volume it has dissipated.
template <int Dim, class Derived>
class ModelBase : public ConstitutiveModel<Dim> {
 public:
  Real energy_density(const Mat<Dim>& F, const Real* q) const override { return self().psi(F, q); }
  Mat<Dim> first_piola(const Mat<Dim>& F, const Real* q) const override { return self().P(F, q); }
  // The model's own dP(F, dF, q) where it has one (every built-in model);
  // otherwise the central difference of P along dF (step 1e-6 relative),
  // second-order accurate: enough for Newton's direction, which the line search
  // on the energy safeguards, for a new model whose derivative is not written out.
  Mat<Dim> first_piola_differential(const Mat<Dim>& F, const Mat<Dim>& dF,
                                    const Real* q) const override {
    if constexpr (requires { self().dP(F, dF, q); }) {
      return self().dP(F, dF, q);
    } else {
      const Real norm = dF.norm();
      if (norm == 0) return Mat<Dim>::Zero();
      const Real h = Real(1e-6) * std::max(Real(1), F.norm()) / norm;
      return (self().P(F + h * dF, q) - self().P(F - h * dF, q)) / (2 * h);
    }
  }
  void kirchhoff_times_volume(const Particles<Dim>& particles, std::span<const int> ids,
                              std::vector<Mat<Dim>>& tauV) const override {
    for_each_batch(static_cast<long>(ids.size()), [&](long first, int count) {
      stress_batch(particles, &ids[first], count,
                   [&](int k) MPMTB_INLINE_LAMBDA -> Mat<Dim>& { return tauV[ids[first + k]]; });
    });
  }
  void kirchhoff_times_volume_of(const Particles<Dim>& particles, std::span<const int> ids,
                                 Mat<Dim>* out) const override {
    const int n = static_cast<int>(ids.size());
    for (int first = 0; first < n; first += kLogBatch) {
      stress_batch(particles, &ids[first], std::min(kLogBatch, n - first),
                   [&](int k) MPMTB_INLINE_LAMBDA -> Mat<Dim>& { return out[first + k]; });
    }
  }
  void return_map(Particles<Dim>& particles, std::span<const int> ids, Real dt) const override {
    // A projection that takes exp(kPowerOfLog ln J) too (Damage in 3D: J^(2/3))
    // gets it from the batch's exponentials (core/batch_exp.hpp), as ln J from
    // its logarithms.
    constexpr bool kPower = requires(Mat<Dim> & F, Real * q) {
      self().project_given_log_and_power(F, 0, 1, q, dt);
    };
    if constexpr (kPower ||
                  requires(Mat<Dim> & F, Real * q) { self().project_given_log(F, 0, q, dt); }) {
      const auto project = [&](int p, Real logJ, Real power) {
        if constexpr (kPower) {
          self().project_given_log_and_power(particles.F[p], logJ, power, particles.state_of(p),
                                             dt);
        } else {
          self().project_given_log(particles.F[p], logJ, particles.state_of(p), dt);
        }
      };
      // A model that can tell from F, J and its state that its return map leaves
      // a particle as it is (Damage::unsettled: the undamaged stress below the
      // threshold, a vector register of particles at a time) spares that
      // particle's logarithm and call.
      if constexpr (requires(const int* batch, Real* J, int* kept) {
                      self().unsettled(particles, batch, 0, dt, J, kept);
                    }) {
        for_each_with_log<kPower>(particles, ids, project,
                                  [&](const int* batch, int count, Real* J, int* kept) {
                                    return self().unsettled(particles, batch, count, dt, J, kept);
                                  });
      } else {
        for_each_with_log<kPower>(particles, ids, project);
      }
    } else if constexpr (requires(Mat<Dim> & F, Real * q) { self().project(F, q, dt); }) {
      const long n = static_cast<long>(ids.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
      for (long i = 0; i < n; ++i) {
        const int p = ids[i];
        self().project(particles.F[p], particles.state_of(p), dt);
      }
    }
  }
  Real dissipated_energy(const Particles<Dim>& particles, std::span<const int> ids) const override {
    Real sum = 0;
    if constexpr (requires(const Real* q) { self().dissipated(q); }) {
      for (const int p : ids) sum += particles.V0[p] * self().dissipated(particles.state_of(p));
    }
    return sum;
  }
  Real strain_energy(const Particles<Dim>& particles, std::span<const int> ids) const override {
    Real sum = 0;
    for (const int p : ids)
      sum += particles.V0[p] * self().psi(particles.F[p], particles.state_of(p));
    return sum;
  }

 private:
  // Particles per batch of logarithms (core/batch_log.hpp).
  static constexpr int kLogBatch = 64;
  // Batches a thread takes at a time in for_each_chunk_balanced (256 particles:
  // 64 chunks per thread for the 32,768 particles of the 3D block at 2 threads).
  static constexpr long kLogChunk = 4;
  // f(p, ln det F_p, power) for every particle p of ids but those a skip screens
  // out (skip(ids, count, J, kept) writes det F and the ids of the particles kept
  // of a batch, and returns their count), in parallel over batches of
  // kLogBatch: each batch's logarithms first, in vector registers
  // (core/batch_log.hpp), with kPower power = exp(Derived::kPowerOfLog ln det
  // F_p) likewise (core/batch_exp.hpp), else 1; then f for its particles. For
  // the return maps that need ln J (project_given_log[_and_power]); the stress
  // batches take with_log directly. (batch_log's lanes are independent: a
  // value's logarithm does not depend on the batch it is in, so neither does a
  // stress, which P2G computes in runs of its scatter's order:
  // kirchhoff_times_volume_of.)
  struct NoSkip {};
  template <bool kPower = false, class F, class Skip = NoSkip>
  static void for_each_with_log(const Particles<Dim>& particles, std::span<const int> ids, F&& f,
                                Skip&& skip = {}) {
    for_each_batch(static_cast<long>(ids.size()), [&](long first, int count) {
      with_log<kPower>(
          particles, &ids[first], count,
          [&](int, int p, Real logJ, Real power) MPMTB_INLINE_LAMBDA { f(p, logJ, power); }, skip);
    });
  }
  // f(first, count) for each batch of kLogBatch of n particles, in parallel.
  template <class F>
  static void for_each_batch(long n, F&& f) {
    const long batches = (n + kLogBatch - 1) / kLogBatch;
    for_each_chunk_balanced(batches, kLogChunk, n >= kParallelMinimum, [&](long from, long to) {
      for (long b = from; b < to; ++b) {
        f(b * kLogBatch, static_cast<int>(std::min<long>(kLogBatch, n - b * kLogBatch)));
      }
    });
  }
  // One batch of for_each_with_log, serial: f(k, p, ln det F_p[, power]) for the
  // particles p = ids[k], k < count <= kLogBatch (k counts the particles kept;
  // power: exp(Derived::kPowerOfLog ln det F_p) with kPower, else 1).
  template <bool kPower = false, class F, class Skip = NoSkip>
  MPMTB_INLINE static void with_log(const Particles<Dim>& particles, const int* ids, int count,
                                    F&& f, Skip&& skip = {}) {
    constexpr bool skips = !std::is_same_v<std::decay_t<Skip>, NoSkip>;
    // J zeroed: GCC cannot tell that the first `count` values, the only ones
    // batch_log reads, are written (-Wmaybe-uninitialized); 8 stores a batch.
    Real J[kLogBatch] = {}, logJ[kLogBatch];
    int kept[kLogBatch];
    if constexpr (skips) {
      count = skip(ids, count, J, kept);  // det F and the ids kept
    } else {
      for (int k = 0; k < count; ++k) J[k] = particles.F[ids[k]].determinant();
    }
    batch_log(J, logJ, count);
    if constexpr (kPower) {
      Real power[kLogBatch];
      powers_of_log(logJ, power, count);
      for (int k = 0; k < count; ++k) f(k, skips ? kept[k] : ids[k], logJ[k], power[k]);
    } else {
      for (int k = 0; k < count; ++k) f(k, skips ? kept[k] : ids[k], logJ[k], Real(1));
    }
  }
  // power[k] = exp(Derived::kPowerOfLog logJ[k]) for k < n <= kLogBatch
  // (core/batch_exp.hpp: lane by lane, so a value does not depend on its batch).
  MPMTB_INLINE static void powers_of_log(const Real* logJ, Real* power, int n) {
    Real exponent[kLogBatch] = {};  // zeroed as J in with_log
    for (int k = 0; k < n; ++k) exponent[k] = Derived::kPowerOfLog * logJ[k];
    batch_exp(exponent, power, n);
  }
  // out(k) = V0_p tau_p for the particles p = ids[k] of one batch (count <=
  // kLogBatch), with the batch's logarithms where the formula takes them; a
  // vector register of particles at a time where Derived writes its formula
  // over lanes (tau_times_volume_lanes, core/lanes.hpp). (Neo-Hookean in the
  // 3D block, 1 thread, perf: the stresses 9.7 % of the step particle by
  // particle, 7.1 % in lanes, plus the logarithms.)
  template <class Out>
  MPMTB_INLINE void stress_batch(const Particles<Dim>& particles, const int* ids, int count,
                                 Out&& out) const {
    if constexpr (stress_in_lanes()) {
      constexpr int kGroups = kLogBatch / kLanes;
      static_assert(kGroups * kLanes == kLogBatch, "whole registers");
      Lanes F[kGroups][Dim][Dim];
      alignas(sizeof(Lanes)) Real J[kLogBatch] = {}, logJ[kLogBatch];  // zeroed as in with_log
      const int groups = (count + kLanes - 1) / kLanes;
      const auto lanes_of = [&](int g) { return std::min(kLanes, count - g * kLanes); };
      for (int g = 0; g < groups; ++g) {
        load_lanes<Dim>(particles.F, ids + g * kLanes, lanes_of(g), F[g]);
        const Lanes det = determinant_of<Dim>(F[g]);
        std::memcpy(&J[g * kLanes], &det, sizeof det);  // the identity's 1 beyond count
      }
      batch_log(J, logJ, groups * kLanes);
      alignas(sizeof(Lanes)) Real power[kLogBatch] = {};
      if constexpr (stress_takes_power()) powers_of_log(logJ, power, groups * kLanes);
      const auto pack = [](const Real* at) MPMTB_INLINE_LAMBDA {
        Lanes v;
        std::memcpy(&v, at, sizeof v);
        return v;
      };
      for (int g = 0; g < groups; ++g) {
        const int* const group = ids + g * kLanes;
        Lanes tauV[Dim][Dim];
        const Lanes V0 = lanes_from(lanes_of(g), Real(0), [&](int l) MPMTB_INLINE_LAMBDA {
          return particles.V0[group[l]];
        });
        const Lanes J_g = pack(&J[g * kLanes]), logJ_g = pack(&logJ[g * kLanes]);
        Lanes power_g = Lanes{} + Real(1);
        if constexpr (stress_takes_power()) power_g = pack(&power[g * kLanes]);
        self().tau_times_volume_lanes(particles, group, lanes_of(g), F[g], J_g, logJ_g, power_g, V0,
                                      tauV);
        store_lanes<Dim>(tauV, lanes_of(g), [&](int l) MPMTB_INLINE_LAMBDA -> Mat<Dim>& {
          return out(g * kLanes + l);
        });
      }
    } else if constexpr (stress_takes_log()) {
      with_log<stress_takes_power()>(particles, ids, count,
                                     [&](int k, int p, Real logJ, Real power) MPMTB_INLINE_LAMBDA {
                                       tau_times_volume(particles, p, logJ, power, out(k));
                                     });
    } else {
      for (int k = 0; k < count; ++k) tau_times_volume(particles, ids[k], Real(0), Real(1), out(k));
    }
  }
  // Derived's formula over lanes: tau_times_volume_lanes(particles, ids, lanes,
  // F, J, ln J, power, V0, out) for the particles ids[0] .. ids[lanes - 1] (the
  // others' lanes hold the identity), power = exp(kPowerOfLog ln J) where the
  // model has that formula (stress_takes_power), else 1.
  static constexpr bool stress_in_lanes() {
    return requires(const Derived& d, const Particles<Dim>& P, const int* ids,
                    const Lanes(&F)[Dim][Dim], Lanes v, Lanes(&out)[Dim][Dim]) {
      d.tau_times_volume_lanes(P, ids, 1, F, v, v, v, v, out);
    };
  }
  // Which stress formula Derived has, the first of: V0 tau from ln J and
  // exp(kPowerOfLog ln J); V0 tau from ln J; tau from ln J; tau from F alone.
  static constexpr bool stress_takes_power() {
    return requires(const Derived& d, const Mat<Dim>& F, const Real* q, Mat<Dim>& out) {
      d.tau_times_volume_given_log_and_power(F, 0, 1, q, 1, out);
    };
  }
  static constexpr bool stress_takes_log() {
    return stress_takes_power() ||
           requires(const Derived& d, const Mat<Dim>& F, const Real* q, Mat<Dim>& out) {
      d.tau_times_volume_given_log(F, 0, q, 1, out);
    }
    || requires(const Derived& d, const Mat<Dim>& F, const Real* q) {
      d.tau_given_log(F, 0, q);
    };
  }
  // out = V0_p tau_p by that formula (logJ = ln det F_p and power its multiple's
  // exponential where the formula takes them).
  MPMTB_INLINE void tau_times_volume(const Particles<Dim>& particles, int p, Real logJ,
                                     [[maybe_unused]] Real power, Mat<Dim>& out) const {
    const Mat<Dim>& F = particles.F[p];
    const Real* q = particles.state_of(p);
    if constexpr (stress_takes_power()) {
      self().tau_times_volume_given_log_and_power(F, logJ, power, q, particles.V0[p], out);
    } else if constexpr (requires { self().tau_times_volume_given_log(F, logJ, q, 1, out); }) {
      self().tau_times_volume_given_log(F, logJ, q, particles.V0[p], out);
    } else if constexpr (stress_takes_log()) {
      out = particles.V0[p] * self().tau_given_log(F, logJ, q);
    } else {
      out = particles.V0[p] * self().tau(F, q);
    }
  }

  const Derived& self() const {
    return static_cast<const Derived&>(*this);
  }
};

}  // namespace mpmtb
