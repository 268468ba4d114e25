// Manufactured solutions for convergence studies (shared/REFERENCE.md).
//
// The exact motion is axis-aligned on the unit box [0, 1]^d:
//   u_i(X, t) = A_i sin(pi X_i) sin(omega t + phi_i)
// so F = I + grad_X u is diagonal, F_ii = 1 + A_i pi cos(pi X_i) sin(omega t + phi_i).
// For the neo-Hookean solid (P_ii = mu (F_ii - 1/F_ii) + lambda ln J / F_ii) the
// body force per unit mass that makes it an exact solution of
// rho0 d2u/dt2 = Div P + rho0 b is (derived; Wallstedt & Guilkey 2008,
// "An evaluation of explicit time integration schemes for use with the
// generalized interpolation material point method", J. Comput. Phys. 227, sec. 4.1):
//   d P_ii / d X_i = -pi^2 u_i [mu + (mu + lambda (1 - ln J)) / F_ii^2]
//   b_i = pi^2 u_i [mu / rho0 - omega^2 / pi^2 - (lambda (ln J - 1) - mu) / (rho0 F_ii^2)].
// `mms-bar`: d = 1, A = G, phi = 0, omega = c pi with c = sqrt(E / rho) the
// bar's wave speed (the 1D bar of REFERENCE.md: b = 0 in the linear limit).
// `mms-axis`: A_i = A, phi_i = 0, 2 pi/3, 4 pi/3, omega = c pi with c a time
// scale (100), in 2D or 3D (2D uses the first two components).
#pragma once

#include <array>
#include <memory>

#include "references/reference.hpp"

namespace mpmtb {

// The exact field and its body force. Time frequency omega; wavenumber pi (unit box).
template <int Dim>
struct AxisAlignedSolution {
  std::array<Real, 3> amplitude{};  // A_i
  std::array<Real, 3> phase{};      // phi_i
  Real omega = 0;                   // angular frequency in time
  Real mu = 0, lambda = 0, rho0 = 1;

  Vec<Dim> displacement(const Vec<Dim>& X, Real t) const;
  Vec<Dim> velocity(const Vec<Dim>& X, Real t) const;
  Vec<Dim> acceleration(const Vec<Dim>& X, Real t) const;
  Mat<Dim> deformation_gradient(const Vec<Dim>& X, Real t) const;
  Mat<Dim> deformation_rate(const Vec<Dim>& X, Real t) const;  // dF/dt
  // Body force per unit mass b(X, t) for the neo-Hookean solid.
  Vec<Dim> body_force(const Vec<Dim>& X, Real t) const;
  // Neo-Hookean strain energy density psi(F(X, t)) per reference volume.
  Real strain_energy_density(const Vec<Dim>& X, Real t) const;
};

template <int Dim>
class ManufacturedReference final : public Reference<Dim> {
 public:
  // kind: "mms-bar" or "mms-axis"; reads [reference] parameters and the first
  // material (neo-Hookean required); the first body must be the unit box.
  ManufacturedReference(const Scene& scene, const std::string& kind);

  void initialize(State<Dim>& s) override;
  std::vector<std::string> columns() const override {
    return {"disp_l2", "disp_linf", "energy_err"};
  }
  std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) override;
  nlohmann::json errors() const override;
  nlohmann::json measured() const override;
  std::vector<Real> saved() const override {
    return {max_l2_, max_linf_, max_energy_error_, max_energy_};
  }
  void restore(const std::vector<Real>& v) override;

  const AxisAlignedSolution<Dim>& solution() const { return exact_; }

 private:
  // The first step the run driver will take (to start the velocity half a step back).
  Real first_step(const State<Dim>& s) const;

  AxisAlignedSolution<Dim> exact_;
  std::shared_ptr<std::vector<Vec<Dim>>> X_;  // reference position X_p of each particle
  bool half_step_start_ = true;
  Real cfl_ = 0, dt_ = 0, t_end_ = 0;  // the scene's time stepping
  Real max_l2_ = 0, max_linf_ = 0;
  // max over output times of |E_h - E(t)| and of E(t), E = kinetic + strain.
  Real max_energy_error_ = 0, max_energy_ = 0;
};

}  // namespace mpmtb
