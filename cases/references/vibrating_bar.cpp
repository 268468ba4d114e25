#include "references/vibrating_bar.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.hpp"
#include "scene.hpp"

namespace mpmtb {

template <int Dim>
VibratingBar<Dim>::VibratingBar(const Scene& scene, Real wave_speed) {
  Parameters params = scene.reference_params;
  const Range whole_mode{[](Real v) { return v >= 1 && v <= 1000 && v == std::floor(v); },
                         "an integer in [1, 1000]"};
  const int mode = static_cast<int>(params.optional("mode", 1, whole_mode));
  const int fixed_ends = static_cast<int>(params.optional(
      "fixed_ends", 1, {[](Real v) { return v == 1 || v == 2; }, "1 (fixed-free) or 2"}));
  v0_ = params.required("v0", Range::any());
  params.reject_unknown();
  const BodySpec& bar = scene.bodies.front();
  if (bar.shape != "box")
    throw InputError("reference: the vibrating bar needs bodies[0] to be a box");
  x0_ = bar.min[0];
  L_ = bar.max[0] - bar.min[0];
  beta_ =
      fixed_ends == 1 ? (2 * mode - 1) * std::numbers::pi / (2 * L_) : mode * std::numbers::pi / L_;
  if (vcm_amplitude() == 0) {
    throw InputError("reference.mode: an even mode of the fixed-fixed bar has v_cm = 0; use odd");
  }
  omega_ = beta_ * wave_speed;
}

template <int Dim>
void VibratingBar<Dim>::initialize(State<Dim>& s) {
  auto& P = s.particles;
  // The bar starts undeformed: X_p is the seeded position. Also on resume, where
  // the checkpoint then overwrites the particles.
  X_ = std::make_shared<std::vector<Vec<Dim>>>(P.x);
  Real norm2 = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.v[p] = Vec<Dim>::Zero();
    P.v[p][0] = v0_ * std::sin(beta_ * (P.x[p][0] - x0_));
    const Real U = v0_ / omega_ * std::sin(beta_ * (P.x[p][0] - x0_));
    norm2 += P.V0[p] * U * U;
  }
  field_norm_ = std::sqrt(norm2);
}

template <int Dim>
Real VibratingBar<Dim>::displacement_exact(Real X, Real t) const {
  return v0_ / omega_ * std::sin(beta_ * (X - x0_)) * std::sin(omega_ * t);
}

template <int Dim>
Real VibratingBar<Dim>::vcm_exact(Real t) const {
  return vcm_amplitude() * std::cos(omega_ * t);
}

template <int Dim>
std::vector<Real> VibratingBar<Dim>::sample(const State<Dim>& s, const Diagnostics& d) {
  const Real vcm = d.center_of_mass_velocity[0];
  const Real exact = vcm_exact(s.time);
  max_vcm_error_ = std::max(max_vcm_error_, std::abs(vcm - exact));
  t_.push_back(s.time);
  vcm_.push_back(vcm);
  // The displacement, not the velocity: symplectic Euler's positions sit at the
  // output times, its velocities half a step behind (an O(dt) offset that a
  // velocity norm would add to every scheme alike).
  const auto& P = s.particles;
  const auto& X = *X_;
  Real sum = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    Vec<Dim> e = P.x[p] - X[p];
    e[0] -= displacement_exact(X[p][0], s.time);
    sum += P.V0[p] * e.squaredNorm();
  }
  const Real field = field_norm_ > 0 ? std::sqrt(sum) / field_norm_ : 0;
  const Real energy = d.kinetic + d.strain;
  if (energy0_ < 0) energy0_ = energy;
  const Real energy_error = energy0_ > 0 ? std::abs(energy - energy0_) / energy0_ : 0;
  max_field_error_ = std::max(max_field_error_, field);
  max_energy_error_ = std::max(max_energy_error_, energy_error);
  return {vcm, exact, field, energy_error};
}

template <int Dim>
nlohmann::json VibratingBar<Dim>::errors() const {
  const Real period = period_from_zero_crossings(t_, vcm_);
  const Real exact_period = 2 * std::numbers::pi / omega_;
  nlohmann::json e;
  e["vcm_rel"] = max_vcm_error_ / vcm_amplitude();
  e["field_rel"] = max_field_error_;
  e["energy_rel"] = max_energy_error_;
  // null when fewer than two zero crossings were sampled
  e["period_rel"] = std::isfinite(period)
                        ? nlohmann::json(std::abs(period - exact_period) / exact_period)
                        : nlohmann::json(nullptr);
  return e;
}

template <int Dim>
nlohmann::json VibratingBar<Dim>::measured() const {
  const Real period = period_from_zero_crossings(t_, vcm_);
  return {{"period", std::isfinite(period) ? nlohmann::json(period) : nlohmann::json(nullptr)},
          {"period_exact", 2 * std::numbers::pi / omega_},
          {"vcm_amplitude_exact", vcm_amplitude()}};
}

Real period_from_zero_crossings(const std::vector<Real>& t, const std::vector<Real>& y) {
  std::vector<Real> crossings;
  for (std::size_t i = 1; i < y.size(); ++i) {
    if ((y[i - 1] < 0) != (y[i] < 0) && y[i] != y[i - 1]) {
      crossings.push_back(t[i - 1] + (t[i] - t[i - 1]) * y[i - 1] / (y[i - 1] - y[i]));
    }
  }
  if (crossings.size() < 2) return std::numeric_limits<Real>::quiet_NaN();
  return 2 * (crossings.back() - crossings.front()) / static_cast<Real>(crossings.size() - 1);
}

template <int Dim>
std::vector<Real> VibratingBar<Dim>::saved() const {
  std::vector<Real> v = {max_vcm_error_, max_field_error_, max_energy_error_, energy0_};
  v.insert(v.end(), t_.begin(), t_.end());
  v.insert(v.end(), vcm_.begin(), vcm_.end());
  return v;
}

template <int Dim>
void VibratingBar<Dim>::restore(const std::vector<Real>& v) {
  if (v.size() < 4 || v.size() % 2 != 0) {
    throw InputError(fmt::format(
        "checkpoint: the vibrating-bar reference keeps 4 + 2 n values, found {}", v.size()));
  }
  const auto n = static_cast<long>((v.size() - 4) / 2);
  max_vcm_error_ = v[0];
  max_field_error_ = v[1];
  max_energy_error_ = v[2];
  energy0_ = v[3];
  t_.assign(v.begin() + 4, v.begin() + 4 + n);
  vcm_.assign(v.begin() + 4 + n, v.end());
}

template class VibratingBar<1>;
template class VibratingBar<2>;
template class VibratingBar<3>;

}  // namespace mpmtb
