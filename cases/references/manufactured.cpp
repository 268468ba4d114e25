#include "references/manufactured.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "models/lame.hpp"
#include "scene.hpp"

namespace mpmtb {

namespace {
constexpr Real pi = std::numbers::pi;
}

template <int Dim>
Vec<Dim> AxisAlignedSolution<Dim>::displacement(const Vec<Dim>& X, Real t) const {
  Vec<Dim> u;
  for (int i = 0; i < Dim; ++i)
    u[i] = amplitude[i] * std::sin(pi * X[i]) * std::sin(omega * t + phase[i]);
  return u;
}

template <int Dim>
Vec<Dim> AxisAlignedSolution<Dim>::velocity(const Vec<Dim>& X, Real t) const {
  Vec<Dim> v;
  for (int i = 0; i < Dim; ++i)
    v[i] = amplitude[i] * omega * std::sin(pi * X[i]) * std::cos(omega * t + phase[i]);
  return v;
}

template <int Dim>
Vec<Dim> AxisAlignedSolution<Dim>::acceleration(const Vec<Dim>& X, Real t) const {
  return -omega * omega * displacement(X, t);
}

template <int Dim>
Mat<Dim> AxisAlignedSolution<Dim>::deformation_gradient(const Vec<Dim>& X, Real t) const {
  Mat<Dim> F = Mat<Dim>::Identity();
  for (int i = 0; i < Dim; ++i)
    F(i, i) += amplitude[i] * pi * std::cos(pi * X[i]) * std::sin(omega * t + phase[i]);
  return F;
}

template <int Dim>
Mat<Dim> AxisAlignedSolution<Dim>::deformation_rate(const Vec<Dim>& X, Real t) const {
  Mat<Dim> dF = Mat<Dim>::Zero();
  for (int i = 0; i < Dim; ++i)
    dF(i, i) = amplitude[i] * pi * omega * std::cos(pi * X[i]) * std::cos(omega * t + phase[i]);
  return dF;
}

template <int Dim>
Vec<Dim> AxisAlignedSolution<Dim>::body_force(const Vec<Dim>& X, Real t) const {
  // b_i = pi^2 u_i [mu/rho0 - omega^2/pi^2 - (lambda (ln J - 1) - mu) / (rho0 F_ii^2)]
  // (header; Wallstedt & Guilkey 2008, sec. 4.1, with c = omega / pi).
  const Vec<Dim> u = displacement(X, t);
  const Mat<Dim> F = deformation_gradient(X, t);
  Real logJ = 0;
  for (int i = 0; i < Dim; ++i) logJ += std::log(F(i, i));
  Vec<Dim> b;
  for (int i = 0; i < Dim; ++i) {
    b[i] = pi * pi * u[i] *
           (mu / rho0 - omega * omega / (pi * pi) -
            (lambda * (logJ - 1) - mu) / (rho0 * F(i, i) * F(i, i)));
  }
  return b;
}

template <int Dim>
Real AxisAlignedSolution<Dim>::strain_energy_density(const Vec<Dim>& X, Real t) const {
  // psi = mu/2 (tr(F^T F) - d) - mu ln J + lambda/2 (ln J)^2 (shared/REFERENCE.md), F diagonal.
  const Mat<Dim> F = deformation_gradient(X, t);
  Real trace = 0, logJ = 0;
  for (int i = 0; i < Dim; ++i) {
    trace += F(i, i) * F(i, i);
    logJ += std::log(F(i, i));
  }
  return mu / 2 * (trace - Dim) - mu * logJ + lambda / 2 * logJ * logJ;
}

template <int Dim>
ManufacturedReference<Dim>::ManufacturedReference(const Scene& scene, const std::string& kind) {
  if (scene.bodies.size() != 1 || scene.bodies.front().shape != "box") {
    throw InputError(fmt::format("reference ({}): needs exactly one body, a box", kind));
  }
  const BodySpec& body = scene.bodies.front();
  for (int a = 0; a < Dim; ++a) {
    if (body.min[a] != 0 || body.max[a] != 1) {
      throw InputError(fmt::format(
          "reference ({}): bodies[0] must be the unit box [0, 1] along each axis used", kind));
    }
  }
  const MaterialSpec& m = scene.materials[body.material];
  if (m.model != "neo-hookean") {
    throw InputError(fmt::format(
        "reference ({}): the body force is derived for neo-hookean; materials.{}.model is '{}'",
        kind, m.name, m.model));
  }
  Parameters material = m.params;
  const ElasticConstants elastic = ElasticConstants::read(material);
  exact_.mu = elastic.mu;
  exact_.lambda = elastic.lambda;
  exact_.rho0 = elastic.density;

  Parameters params = scene.reference_params;
  const bool bar = kind == "mms-bar";
  // F_ii > 0 everywhere needs A pi < 1.
  const Real amplitude = params.optional("amplitude", bar ? 1e-4 : 0.05, Range::open(0, 1 / pi));
  // Time scale c, omega = c pi: the bar's wave speed for mms-bar, 100 for mms-axis.
  const Real c = params.optional("c", bar ? elastic.wave_speed() : 100, Range::positive());
  half_step_start_ = params.optional("half_step_start", 1,
                                     {[](Real v) { return v == 0 || v == 1; }, "0 or 1"}) != 0;
  params.reject_unknown();
  exact_.omega = c * pi;
  for (int i = 0; i < 3; ++i) {
    exact_.amplitude[i] = bar ? (i == 0 ? amplitude : 0) : amplitude;
    exact_.phase[i] = bar ? 0 : 2 * pi * i / 3;
  }
  cfl_ = scene.cfl.value_or(0);
  dt_ = scene.dt.value_or(0);
  t_end_ = scene.t_end;
}

template <int Dim>
Real ManufacturedReference<Dim>::first_step(const State<Dim>& s) const {
  if (dt_ > 0) return std::min(dt_, t_end_);
  Real v_max = 0;
  for (const auto& v : s.particles.v) v_max = std::max(v_max, v.norm());
  return std::min(cfl_ * s.grid.geo.dx / (s.max_wave_speed() + v_max), t_end_);
}

template <int Dim>
void ManufacturedReference<Dim>::initialize(State<Dim>& s) {
  auto& P = s.particles;
  X_ = std::make_shared<std::vector<Vec<Dim>>>(P.x);
  const auto& X = *X_;
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.x[p] = X[p] + exact_.displacement(X[p], 0);
    P.F[p] = exact_.deformation_gradient(X[p], 0);
  }
  // Symplectic Euler is the leapfrog scheme with velocities at half steps: v^0
  // stands for v(-dt/2). Starting from v(0) instead is an O(dt) error in the
  // velocity wherever the initial acceleration is non-zero (the phased case),
  // which would cap the observed order at 1. The first dt depends on max |v|,
  // so the start is iterated (it settles to round-off in a few passes).
  auto set_velocity = [&](Real t) {
    for (std::size_t p = 0; p < P.size(); ++p) {
      P.v[p] = exact_.velocity(X[p], t);
      const Mat<Dim> F = exact_.deformation_gradient(X[p], t);
      // C_p: the spatial velocity gradient dF/dt F^-1 (used by APIC / MLS-MPM).
      P.C[p] = exact_.deformation_rate(X[p], t) * F.inverse();
    }
  };
  set_velocity(0);
  if (half_step_start_) {
    for (int pass = 0; pass < 4; ++pass) set_velocity(-first_step(s) / 2);
  }
  s.body_force = [X = X_, exact = exact_](const Particles<Dim>&, int p, Real t) {
    return exact.body_force((*X)[p], t);
  };
}

template <int Dim>
std::vector<Real> ManufacturedReference<Dim>::sample(const State<Dim>& s, const Diagnostics& d) {
  const auto& P = s.particles;
  const auto& X = *X_;
  Real sum = 0, linf = 0, energy = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Real e = (P.x[p] - X[p] - exact_.displacement(X[p], s.time)).norm();
    sum += P.V0[p] * e * e;
    linf = std::max(linf, e);
    energy += P.m[p] * exact_.velocity(X[p], s.time).squaredNorm() / 2 +
              P.V0[p] * exact_.strain_energy_density(X[p], s.time);
  }
  const Real l2 = std::sqrt(sum);
  max_l2_ = std::max(max_l2_, l2);
  max_linf_ = std::max(max_linf_, linf);
  const Real energy_error = std::abs(d.kinetic + d.strain - energy);
  max_energy_error_ = std::max(max_energy_error_, energy_error);
  max_energy_ = std::max(max_energy_, energy);
  return {l2, linf, max_energy_ > 0 ? energy_error / max_energy_ : 0};
}

template <int Dim>
nlohmann::json ManufacturedReference<Dim>::errors() const {
  // disp_l2 = max over output times of sqrt(sum_p V0_p |u_p - u(X_p, t)|^2), not
  // normalised (the body is the unit box, so it is also the volume-weighted RMS);
  // disp_linf = max over output times and particles of |u_p - u(X_p, t)|.
  // energy_rel = max over output times of |E_h(t) - E(t)| / max over output times
  // of E(t), E = kinetic + strain energy, the exact one by particle quadrature at
  // X_p. The exact energy is not constant (the body force works on the body), and
  // the computed velocity lags half a step (leapfrog), so this error is first
  // order in dt: a check of the energy, not a convergence metric.
  return {{"disp_l2", max_l2_},
          {"disp_linf", max_linf_},
          {"energy_rel", max_energy_ > 0 ? max_energy_error_ / max_energy_ : 0}};
}

template <int Dim>
nlohmann::json ManufacturedReference<Dim>::measured() const {
  return {{"amplitude", exact_.amplitude[0]},
          {"omega", exact_.omega},
          {"half_step_start", half_step_start_}};
}

template struct AxisAlignedSolution<1>;
template struct AxisAlignedSolution<2>;
template struct AxisAlignedSolution<3>;
template <int Dim>
void ManufacturedReference<Dim>::restore(const std::vector<Real>& v) {
  if (v.size() != 4) {
    throw InputError(fmt::format(
        "checkpoint: the manufactured-solution reference keeps {} values, found {}", 4, v.size()));
  }
  max_l2_ = v[0], max_linf_ = v[1], max_energy_error_ = v[2], max_energy_ = v[3];
}

template class ManufacturedReference<1>;
template class ManufacturedReference<2>;
template class ManufacturedReference<3>;

}  // namespace mpmtb
