// Vibrating elastic bar in mode n, of length L from x0 (Bardenhagen 2002,
// "Energy conservation error in the material point method for solid
// mechanics", J. Comput. Phys. 180, sec. 4), fixed at x0 and free at x0 + L
// (fixed_ends = 1) or fixed at both ends (fixed_ends = 2, Tielen et al. 2017):
//   beta_n = (2n - 1) pi / (2L) or n pi / L,  omega_n = beta_n c,  c = sqrt(modulus / rho)
//   v(x, t) = v0 sin(beta_n (x - x0)) cos(omega_n t)
//   v_cm(t) = v0 (1 - cos(beta_n L)) / (beta_n L) cos(omega_n t)
//   u(x, t) = (v0 / omega_n) sin(beta_n (x - x0)) sin(omega_n t)
// Error norms (cases/README.md): the field error of the displacement, which
// sees amplitude and phase (a scheme that damps the bar or shifts its period
// both show), max over output times t of
//   field_rel = sqrt(sum_p V0_p |u_p(t) - u(X_p, t)|^2) / sqrt(sum_p V0_p U(X_p)^2),
// U(X) = (v0 / omega_n) sin(beta_n (X - x0)) the amplitude field; the energy
// error, max over output times of |E(t) - E(0)| / E(0), E = kinetic + strain
// (the exact solution keeps E); v_cm and the period as before.
// The modulus is lambda + 2 mu of the material: E for nu = 0, and the right
// modulus for a 1D bar and for a 2D/3D bar between slip walls.
#pragma once

#include <cmath>
#include <memory>

#include "references/reference.hpp"

namespace mpmtb {

template <int Dim>
class VibratingBar final : public Reference<Dim> {
 public:
  // mode (integer >= 1) and v0 from [reference]; L, x0 from the first body (a
  // box); the wave speed from its material.
  VibratingBar(const Scene& scene, Real wave_speed);

  void initialize(State<Dim>& s) override;
  std::vector<std::string> columns() const override {
    return {"vcm", "vcm_exact", "field_err", "energy_err"};
  }
  std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) override;
  nlohmann::json errors() const override;
  nlohmann::json measured() const override;
  // The largest v_cm, field and energy errors, E(0), then the sample times,
  // then v_cm at those times.
  std::vector<Real> saved() const override;
  void restore(const std::vector<Real>& v) override;

  Real beta() const { return beta_; }
  Real omega() const { return omega_; }
  Real vcm_exact(Real t) const;
  // The exact displacement along the bar at reference position X.
  Real displacement_exact(Real X, Real t) const;
  Real vcm_amplitude() const { return v0_ * (1 - std::cos(beta_ * L_)) / (beta_ * L_); }

 private:
  Real v0_ = 0, L_ = 0, x0_ = 0, beta_ = 0, omega_ = 0;
  Real max_vcm_error_ = 0, max_field_error_ = 0, max_energy_error_ = 0;
  Real energy0_ = -1;                         // E(0), set by the first sample
  Real field_norm_ = 0;                       // sqrt(sum_p V0_p U(X_p)^2)
  std::shared_ptr<std::vector<Vec<Dim>>> X_;  // reference position X_p of each particle
  std::vector<Real> t_, vcm_;                 // samples, for the period estimate
};

// Period of a sampled oscillation from its zero crossings (linear interpolation
// between samples): 2 (t_last - t_first) / (crossings - 1). NaN if fewer than 2.
Real period_from_zero_crossings(const std::vector<Real>& t, const std::vector<Real>& y);

}  // namespace mpmtb
