// Time integrators of the step (`[method] integrator`, `--integrator`):
//   explicit        symplectic Euler, the stages of core/stepper.hpp (default);
//   backward-euler  implicit, first order, unconditionally stable, dissipative;
//   newmark         implicit trapezoidal rule (Newmark beta = 1/4, gamma = 1/2),
//                   second order, energy conserving for linear elasticity.
// The implicit ones solve for the grid velocities after P2G by minimising the
// incremental potential of Gast, Schroeder, Stomakhin, Jiang & Teran 2015
// ("Optimization integrator for large time steps", IEEE TVCG 21(10)) with
// Newton's method (methods/integrators/implicit_impl.hpp). Only the interface
// is here: core/stepper.hpp includes it.
// The implicit integrators (integrators/implicit_impl.hpp):
//   Newmark (beta = 1/4, gamma = 1/2) energy: for a quadratic psi, Psi(F^n+1) - Psi(F^n) = (P^n +
//   P^n+1)/2 :
//     (F^n+1 - F^n) = -dt/2 (v^n + v^n+1) . (f^n + f^n+1)/2, while the kinetic
//     energy changes by m (v^n+1 - v^n) . (v^n+1 + v^n)/2 = the same with the
//     opposite sign: the grid energy is kept exactly (to the solver's
//     tolerance). For one mode x'' = -omega^2 x the step's amplification is
//     A = (1 - (omega dt/2)^2 + i omega dt) / (1 + (omega dt/2)^2) with
//     |A|^2 = ((1 - z^2)^2 + 4 z^2) / (1 + z^2)^2 = 1, z = omega dt / 2:
//     no growth or decay at any dt, a phase error of O((omega dt)^3) per step.
//     (Backward Euler: A = 1 / (1 - i omega dt), |A| = 1 / sqrt(1 + (omega dt)^2).)
// Newton's method on E: the Hessian-vector product
//   H d = m d + h^2 sum_p V0_p (dP/dF : dF_p) F_p^nT grad w_ip,
//   dF_p = sum_i d_i grad w_ip^T F_p^n,
// with each particle's dP/dF (a Dim^2 x Dim^2 block, built from the model's
// first_piola_differential) projected to positive semi-definite by clamping
// its negative eigenvalues (Teran, Sifakis, Irving & Fedkiw 2005, "Robust
// quasistatic finite elements and flesh simulation", sec. 5, per particle
// instead of per element), so that every direction descends. The linear
// systems are solved matrix-free by our own Jacobi-preconditioned conjugate
// gradients (integrators/conjugate_gradient.hpp): the operator acts on the grid's Vec<Dim> arrays
// over the active nodes with the constraints folded in, which Eigen's CG would need a wrapper type
// and a flattening copy for, for no gain. An inexact Newton forcing term (|r| <= min(cg_tol,
// |g|/|g_0|) |g|) and a backtracking (Armijo) line search on E. Converged when |g| <= newton_tol
// |g_0|, g_0 the gradient at the step's start (v = v~), or below a round-off floor.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"

namespace mpmtb {

template <int Dim>
struct State;
template <int Dim>
class Stepper;
struct StepReport;

enum class Integrator { explicit_euler, backward_euler, newmark };
inline constexpr std::array<std::string_view, 3> kIntegratorNames = {"explicit", "backward-euler",
                                                                     "newmark"};
inline std::string_view integrator_name(Integrator i) {
  return kIntegratorNames[static_cast<int>(i)];
}
// Parses a name; throws InputError naming method.integrator and the allowed names.
Integrator parse_integrator(std::string_view name);

// The Newton solve's controls; tolerances are relative to the residual (the
// norm of the energy's gradient) at the start of the step.
struct ImplicitOptions {
  Real newton_tol = 1e-8;  // |g| <= newton_tol |g_0|
  int newton_max = 50;     // iterations before the step is declared failed
  Real cg_tol = 0.1;       // forcing term cap: |r| <= min(cg_tol, |g| / |g_0|) |g|
  int cg_max = 2000;       // CG iterations per Newton iteration
};

// What the last implicit step did.
struct ImplicitStats {
  int newton = 0;         // Newton iterations
  long cg = 0;            // CG iterations, summed over the Newton iterations
  Real residual = 0;      // final |g| / |g_0| (0 when g_0 is already below the floor)
  bool converged = true;  // |g| reached the tolerance within newton_max
  // Grid energy of the step, after minus before (kinetic sum m_i |v_i|^2 / 2 of
  // P2G's and the solved velocities, plus the strain energy at F^n and F^n+1);
  // zero to the solver tolerance for Newmark with a quadratic energy.
  Real grid_energy_change = 0;
  Real grid_energy = 0;  // the energy before, the scale of the change
};

// The implicit step of one dimension and kernel (integrators/implicit_*d.cpp).
template <int Dim>
class ImplicitSolve {
 public:
  virtual ~ImplicitSolve() = default;
  // One step of size dt through the stepper's split stages; fills `report`.
  virtual void step(Stepper<Dim>& stepper, State<Dim>& s, Real dt, StepReport& report) = 0;
  const ImplicitStats& stats() const { return stats_; }

  // The objective of a step, for tests: setup runs P2G and builds E for the
  // step dt without solving; vectors are indexed by grid node (only the
  // active nodes are read), components a constraint prescribes are ignored.
  virtual void setup(Stepper<Dim>& stepper, State<Dim>& s, Real dt) = 0;
  virtual Real energy(const std::vector<Vec<Dim>>& u) = 0;
  virtual void gradient(const std::vector<Vec<Dim>>& u, std::vector<Vec<Dim>>& g) = 0;
  // H d at u; `project`: the particles' dP/dF blocks projected to PSD.
  virtual void hessian_times(const std::vector<Vec<Dim>>& u, const std::vector<Vec<Dim>>& d,
                             std::vector<Vec<Dim>>& out, bool project) = 0;
  virtual const std::vector<Vec<Dim>>& start() const = 0;  // v~, masked
  virtual const std::vector<long>& active_nodes() const = 0;

 protected:
  ImplicitStats stats_;
};

// The solve for the stepper's kernel (by name); throws InputError for an
// unknown kernel (never, for a kernel the registry made).
template <int Dim>
std::unique_ptr<ImplicitSolve<Dim>> make_implicit_solve(std::string_view kernel,
                                                        Integrator integrator,
                                                        const ImplicitOptions& options);

}  // namespace mpmtb
