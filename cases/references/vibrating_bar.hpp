// Vibrating elastic bar in mode n, of length L from x0 (Bardenhagen 2002,
// "Energy conservation error in the material point method for solid
// mechanics", J. Comput. Phys. 180, sec. 4), fixed at x0 and free at x0 + L
// (fixed_ends = 1) or fixed at both ends (fixed_ends = 2, Tielen et al. 2017):
//   beta_n = (2n - 1) pi / (2L) or n pi / L,  omega_n = beta_n c,  c = sqrt(modulus / rho)
//   v(x, t) = v0 sin(beta_n (x - x0)) cos(omega_n t)
//   v_cm(t) = v0 (1 - cos(beta_n L)) / (beta_n L) cos(omega_n t)
// The modulus is lambda + 2 mu of the material: E for nu = 0, and the right
// modulus for a 1D bar and for a 2D/3D bar between slip walls.
#pragma once

#include <cmath>

#include "references/reference.hpp"

namespace mpmtb {

template <int Dim>
class VibratingBar final : public Reference<Dim> {
 public:
  // mode (integer >= 1) and v0 from [reference]; L, x0 from the first body (a
  // box); the wave speed from its material.
  VibratingBar(const Scene& scene, Real wave_speed);

  void initialize(State<Dim>& s) override;
  std::vector<std::string> columns() const override { return {"vcm", "vcm_exact"}; }
  std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) override;
  nlohmann::json errors() const override;
  nlohmann::json measured() const override;
  // The largest error, then the sample times, then v_cm at those times.
  std::vector<Real> saved() const override;
  void restore(const std::vector<Real>& v) override;

  Real beta() const { return beta_; }
  Real omega() const { return omega_; }
  Real vcm_exact(Real t) const;
  Real vcm_amplitude() const { return v0_ * (1 - std::cos(beta_ * L_)) / (beta_ * L_); }

 private:
  Real v0_ = 0, L_ = 0, x0_ = 0, beta_ = 0, omega_ = 0;
  Real max_vcm_error_ = 0;
  std::vector<Real> t_, vcm_;  // samples, for the period estimate
};

// Period of a sampled oscillation from its zero crossings (linear interpolation
// between samples): 2 (t_last - t_first) / (crossings - 1). NaN if fewer than 2.
Real period_from_zero_crossings(const std::vector<Real>& t, const std::vector<Real>& y);

}  // namespace mpmtb
