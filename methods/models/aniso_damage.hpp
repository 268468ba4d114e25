// Anisotropic damage on neo-Hookean elasticity with fibre reinforcement, after
//   Wolper, Chen, Li, Fang, Qu, Lu, Cheng, Jiang 2020, "AnisoMPM: Animating
//     Anisotropic Damage Mechanics", ACM TOG 39(4): the stress-based damage
//     evolution of models/damage.hpp, with the driving stress weighted by a
//     structural tensor built from the material's fibre directions, and an
//     anisotropic (fibre-reinforced) elastic energy degraded with the damage.
//   Teichtmeister, Kienle, Aldakheel, Keip 2017, "Phase field modeling of
//     fracture in anisotropic brittle solids", Int. J. Non-Linear Mech. 97:
//     the anisotropic crack density gamma = (d^2 + l0^2 grad d . A_l grad d) / (2 l0).
//   Equation numbers are not given: they were not checked against the papers.
// Regularisation (the length scale l0 with a grain): the damage evolution
// takes div(A_l grad d) in place of lap d (core/nonlocal.hpp), with
//   A_l = I + alpha sum_f a_f a_f^T.
// Why this sign (worked on paper): across a straight damage band of unit
// normal n, d = d(s), s = x . n, so grad d . A_l grad d = m d'^2 with
// m = n . A_l n; the optimal profile is d = exp(-|s| / (l0 sqrt m)), of width
// l0 sqrt m, and the regularised surface energy per unit area is
// int gamma ds = sqrt(m): the crack prefers the normal that minimises n . A_l n.
// With A_l = I + alpha a a^T, n . A_l n = 1 + alpha (n . a)^2 is least (1) for
// n normal to the fibre, i.e. for a crack running ALONG the fibre; damage
// diffuses 1 + alpha times as fast along a as across it, so a crack tip's
// process zone reaches ahead along the grain. The driver's form
// I + alpha (I - a a^T) below would, in the regularisation, make n . A n =
// 1 + alpha (1 - (n . a)^2) least for n ALONG the fibre, a crack ACROSS it:
// the wrong way. Teichtmeister et al. write A = I + alpha (I - m m^T) with m the
// normal of the preferred cleavage plane; with m normal to the fibre in 2D
// that is I + alpha a a^T, the form here (in 3D, I + alpha a a^T favours every
// plane containing the fibre and lets the load choose among them).
// The same reasoning checks the driver: sigma~ = A sigma A with
// A = I + alpha (I - a a^T) scales the normal stress b . sigma b on planes of
// normal b perpendicular to the fibre by (1 + alpha)^2, and leaves that on the
// plane normal to the fibre alone: tension opening a crack ALONG the fibres
// drives damage hardest. Both tensors favour the same cracks.
// Fibres: one or two families of unit directions a0_f per particle, given in
// the reference configuration (a body's `fiber`, `fiber2`). The current
// direction is the pushed-forward fibre renormalised, a_f = F a0_f / |F a0_f|:
// the same as advecting a_f by each step's increment of F and renormalising,
// because F itself is the product of those increments. The model keeps a0_f
// and writes a_f into its state in the return map (for output); it needs no
// hook in the step.
// Structural tensor (AnisoMPM; the Raina & Miehe 2016 form for one family,
// summed over the families for two):
//   A = I + alpha sum_f (I - a_f a_f^T),
// so that A a = a for a single family and A b = (1 + alpha) b for b normal to
// it: tension across the fibres drives damage (1 + alpha)^2 times as hard as
// the same tension along them (the material splits along its grain).
// (AnisoMPM's own driver, as its public implementation computes it: phi =
// (A sigma+ : sigma+ A) / sigma_crit^2 with A = I + alpha a a^T, alpha in
// [-1, inf), and the isotropic lap d; for alpha near -1 it is, like this one
// for large alpha, the normal stress on the planes that contain the fibres.
// Alone it turns a crack only part of the way to the fibres: cases/README.md.)
// Driver: sigma~ = A sigma A (sigma the undamaged Cauchy stress, fibre part
// included), phi = (largest principal value of sigma~) / sigma_crit,
// D~ = zeta <phi - 1>, and the rate law and the linearly implicit update of
// models/damage.hpp, with div(A_l grad d) for lap d and its grid diagonal for
// 2 Dim / dx^2 (alpha = 0: lap d itself, the isotropic path of the step).
// Energy: psi = g(d) psi_m+ + g_f(d) psi_f + psi_m-, with psi_m+/- the
// neo-Hookean tension/compression split of models/damage.hpp, g(d) its
// degradation, g_f(d) = (1 - d)^2 (1 - fiber_k) + fiber_k that of the fibres
// (fiber_k = k: fibres and matrix break together; fiber_k = 1: the damage
// cracks the matrix only and the fibres stay whole), and the fibre energy
//   psi_f = sum_f fiber_E / 2 <lambda_f - 1>_+^2,  lambda_f = |F a0_f|,
// the fibre stretch. Fibres carry tension only (a buckled fibre stores no
// energy), so psi_f is wholly tensile; it is C^1 at lambda_f = 1. Stress of
// one family (Kirchhoff tau = P F^T):
//   P_f = fiber_E <lambda_f - 1>_+ / lambda_f (F a0_f) a0_f^T,
//   tau_f = fiber_E <lambda_f - 1>_+ lambda_f a_f a_f^T.
// Dissipated at fixed F: (g(d_old) - g(d_new)) psi_m+ + (g_f(d_old) -
// g_f(d_new)) psi_f, so kinetic + strain + gravity + dissipated is kept.
// alpha = 0 and fiber_E = 0 is the `damage` model exactly: every formula takes
// the `damage` model's path, bit for bit (tests/unit/aniso_damage_test.cpp).
// Objective: psi depends on F through F^T F and a0 only; under F -> R F,
// a -> R a, A -> R A R^T and sigma~ -> R sigma~ R^T keep their eigenvalues.
// Parameters: those of `damage`, plus alpha >= 0 (0: isotropic driver),
// alpha_l >= 0 (alpha; the grain of the length scale, 0: the isotropic lap d),
// fiber_E >= 0 (0; a modulus: the fibres' stiffness in tension) and fiber_k in
// [0, 1] (1e-6). The P-wave speed along the fibres,
// sqrt((lambda + 2 mu + fiber_E) / rho), sets the CFL.
// State per particle: the four of `damage`, then a0 and a of each family
// (a second family absent: a0 = 0).
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "models/damage.hpp"

namespace mpmtb {

template <int Dim>
class AnisoDamage final : public ModelBase<Dim, AnisoDamage<Dim>> {
  using Matrix = Damage<Dim>;  // the isotropic matrix and its damage law

 public:
  static constexpr std::string_view model_name = "aniso-damage";
  static constexpr std::string_view bibtex = R"bib(@article{wolper2020,
  author = {Wolper, Joshuah and Chen, Yunuo and Li, Minchen and Fang, Yu and Qu, Ziyin and Lu, Jiecong and Cheng, Meggie and Jiang, Chenfanfu},
  title = {{AnisoMPM}: animating anisotropic damage mechanics},
  journal = {ACM Transactions on Graphics},
  volume = {39},
  number = {4},
  year = {2020}
}
@article{raina2016,
  author = {Raina, Arun and Miehe, Christian},
  title = {A phase-field model for fracture in biological tissues},
  journal = {Biomechanics and Modeling in Mechanobiology},
  volume = {15},
  number = {3},
  pages = {479--496},
  year = {2016}
})bib";
  static constexpr int kFamilies = 2;
  static_assert(kFamilies <= LaplacianRequest::kMaxFibers, "the step reads at most kMaxFibers");
  enum StateIndex { kDamage = 0, kDissipated = 1, kLapDamage = 2, kLapDiagonal = 3, kFibers = 4 };
  // Where family f's reference (a0) and current (a) directions sit in the state.
  static constexpr int ref_at(int f) { return kFibers + 2 * Dim * f; }
  static constexpr int cur_at(int f) { return kFibers + 2 * Dim * f + Dim; }

  explicit AnisoDamage(Parameters& params)
      : m_(params),
        alpha_(params.optional("alpha", 0, Range::non_negative())),
        fiber_E_(params.optional("fiber_E", 0, Range::non_negative())),
        fiber_k_(params.optional("fiber_k", 1e-6, Range::closed(0, 1))),
        alpha_l_(params.optional("alpha_l", alpha_, Range::non_negative())) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return m_.density(); }
  Real wave_speed() const override {
    const ElasticConstants& c = m_.elastic();
    return std::sqrt((c.lambda + 2 * c.mu + fiber_E_) / c.density);
  }
  int state_size() const override { return kFibers + 2 * Dim * kFamilies; }
  void initial_state(Real* q) const override {
    m_.initial_state(q);
    // Until set_fibers: one family along the first axis, no second family.
    for (int i = kFibers; i < state_size(); ++i) q[i] = 0;
    q[ref_at(0)] = q[cur_at(0)] = 1;
  }
  std::vector<std::string> state_names() const override {
    std::vector<std::string> names = m_.state_names();
    const char* axis[] = {"x", "y", "z"};
    for (const char* family : {"fiber", "fiber2"}) {
      for (int a = 0; a < Dim; ++a) names.push_back(std::string(family) + "_ref_" + axis[a]);
      for (int a = 0; a < Dim; ++a) names.push_back(std::string(family) + "_" + axis[a]);
    }
    return names;
  }
  // div(A_l grad d), A_l = I + alpha_l sum_f a_f a_f^T of the current fibres;
  // alpha_l = 0 asks for the `damage` model's isotropic lap d.
  LaplacianRequest laplacian_request() const override {
    LaplacianRequest r = m_.laplacian_request();
    if (!r.active() || alpha_l_ == 0) return r;
    r.alpha = alpha_l_;
    for (int f = 0; f < kFamilies; ++f) r.fibers[f] = cur_at(f);
    return r;
  }
  int fiber_families() const override { return kFamilies; }
  // a0: one or two nonzero directions (normalised here).
  void set_fibers(Real* q, std::span<const Vec<Dim>> a0) const override {
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> a = f < static_cast<int>(a0.size()) ? a0[f].normalized() : Vec<Dim>::Zero();
      for (int i = 0; i < Dim; ++i) q[ref_at(f) + i] = q[cur_at(f) + i] = a[i];
    }
  }

  Real alpha() const { return alpha_; }
  // g_f(d) = (1 - d)^2 (1 - fiber_k) + fiber_k: fiber_k = 1 keeps the fibres intact.
  Real fiber_degradation(Real d) const { return (1 - d) * (1 - d) * (1 - fiber_k_) + fiber_k_; }
  Real fiber_E() const { return fiber_E_; }
  const Matrix& matrix() const { return m_; }

  // The reference and current direction of family f (zero if absent).
  static Vec<Dim> reference_fiber(const Real* q, int f) {
    return Eigen::Map<const Vec<Dim>>(q + ref_at(f));
  }
  static Vec<Dim> current_fiber(const Real* q, int f) {
    return Eigen::Map<const Vec<Dim>>(q + cur_at(f));
  }

  Real psi(const Mat<Dim>& F, const Real* q) const {
    if (fiber_E_ == 0) return m_.psi(F, q);
    const typename Matrix::Split e = m_.split(F);
    const Real d = damage(q);
    return m_.degradation(d) * e.plus + fiber_degradation(d) * fiber_energy(F, q) + e.minus;
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real* q) const {
    if (fiber_E_ == 0) return m_.P(F, q);
    return m_.P(F, q) + fiber_degradation(damage(q)) * fiber_piola(F, q);
  }
  // dP = (dP/dF) : dF at fixed d (the implicit integrators' Hessian): the
  // matrix's (models/damage.hpp) plus the degraded fibres'. With u = F a0,
  // du = dF a0 and d lambda = u . du / lambda, for a stretched fibre
  //   dP_f = fiber_E [(u . du) / lambda^3 u + (1 - 1 / lambda) du] a0^T.
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real* q) const {
    if (fiber_E_ == 0) return m_.dP(F, dF, q);
    Mat<Dim> dP_f = Mat<Dim>::Zero();
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> a0 = reference_fiber(q, f), u = F * a0, du = dF * a0;
      const Real stretch = u.norm();
      if (a0.squaredNorm() == 0 || !(stretch > 1)) continue;
      dP_f += fiber_E_ * (u.dot(du) / (stretch * stretch * stretch) * u + (1 - 1 / stretch) * du) *
              a0.transpose();
    }
    return m_.dP(F, dF, q) + fiber_degradation(damage(q)) * dP_f;
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const {
    return tau_given_log(F, std::log(F.determinant()), q);
  }
  // tau with ln J given, as damage's (ModelBase takes a batch's logarithms at once).
  Mat<Dim> tau_given_log(const Mat<Dim>& F, Real logJ, const Real* q) const {
    if (fiber_E_ == 0) return m_.tau_given_log(F, logJ, q);
    return m_.tau_given_log(F, logJ, q) + fiber_degradation(damage(q)) * fiber_kirchhoff(F, q);
  }

  // The structural tensor A = I + alpha sum_f (I - a_f a_f^T) of the current fibres.
  Mat<Dim> structural_tensor(const Real* q) const {
    Mat<Dim> A = Mat<Dim>::Identity();
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> a = current_fiber(q, f);
      if (a.squaredNorm() > 0) A += alpha_ * (Mat<Dim>::Identity() - a * a.transpose());
    }
    return A;
  }
  // sigma~ = A sigma A, sigma the undamaged Cauchy stress (fibres included).
  Mat<Dim> driving_stress(const Mat<Dim>& F, const Real* q) const {
    return driving_stress(F, std::log(F.determinant()), q);
  }
  Mat<Dim> driving_stress(const Mat<Dim>& F, Real logJ, const Real* q) const {
    Mat<Dim> sigma = m_.undamaged_cauchy(F, logJ);
    if (fiber_E_ > 0) sigma += fiber_kirchhoff(F, q) / F.determinant();
    const Mat<Dim> A = structural_tensor(q);
    return A * sigma * A;
  }
  Real max_driving_stress(const Mat<Dim>& F, const Real* q) const {
    return Matrix::max_symmetric_eigenvalue(driving_stress(F, q));
  }

  // Writes the current fibres a_f = F a0_f / |F a0_f|, then updates the damage at
  // fixed F as models/damage.hpp does, driven by sigma~ instead of sigma.
  void project(Mat<Dim>& F, Real* q, Real dt) const {
    project_given_log(F, std::log(F.determinant()), q, dt);
  }
  // The same with ln J given (ModelBase::return_map takes a batch's logarithms).
  void project_given_log(Mat<Dim>& F, Real logJ, Real* q, Real dt) const {
    advect_fibers(F, q);
    if (alpha_ == 0 && fiber_E_ == 0) return m_.project_given_log(F, logJ, q, dt);  // `damage`
    const Real d_old = q[kDamage];
    if (d_old >= 1) return;
    const Real d_new = m_.advanced_damage(d_old, stress_excess(F, logJ, q), q, dt);
    if (!(d_new > d_old)) return;
    q[kDissipated] += (m_.degradation(d_old) - m_.degradation(d_new)) * m_.split(F).plus +
                      (fiber_degradation(d_old) - fiber_degradation(d_new)) * fiber_energy(F, q);
    q[kDamage] = d_new;
  }
  // The same with s = J^(2/3) given (3D; ModelBase::return_map takes a batch's
  // exponentials): at alpha = 0 without fibres `damage`'s own, bit for bit; with
  // them the path above (s is not read).
  static constexpr Real kPowerOfLog = Matrix::kPowerOfLog;
  void project_given_log_and_power(Mat<Dim>& F, Real logJ, Real s, Real* q, Real dt) const
      requires(Dim == 3) {
    if (alpha_ != 0 || fiber_E_ != 0) return project_given_log(F, logJ, q, dt);
    advect_fibers(F, q);
    m_.project_given_log_and_power(F, logJ, s, q, dt);
  }
  Real dissipated(const Real* q) const { return q[kDissipated]; }

  // Undegraded fibre energy, first Piola and Kirchhoff stress (sum over families).
  Real fiber_energy(const Mat<Dim>& F, const Real* q) const {
    Real e = 0;
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> a0 = reference_fiber(q, f);
      if (a0.squaredNorm() == 0) continue;
      const Real over = std::max(Real(0), (F * a0).norm() - 1);
      e += Real(0.5) * fiber_E_ * over * over;
    }
    return e;
  }
  Mat<Dim> fiber_piola(const Mat<Dim>& F, const Real* q) const {
    Mat<Dim> P = Mat<Dim>::Zero();
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> a0 = reference_fiber(q, f), Fa = F * a0;
      const Real stretch = Fa.norm();
      if (a0.squaredNorm() == 0 || !(stretch > 1)) continue;
      P += fiber_E_ * (stretch - 1) / stretch * Fa * a0.transpose();
    }
    return P;
  }
  Mat<Dim> fiber_kirchhoff(const Mat<Dim>& F, const Real* q) const {
    return fiber_piola(F, q) * F.transpose();
  }

 private:
  static Real damage(const Real* q) { return q ? q[kDamage] : Real(0); }
  static void advect_fibers(const Mat<Dim>& F, Real* q) {
    for (int f = 0; f < kFamilies; ++f) {
      const Vec<Dim> Fa = F * reference_fiber(q, f);
      const Real n = Fa.norm();
      if (!(n > 0)) continue;  // absent family (or a degenerate F: keep the last)
      Eigen::Map<Vec<Dim>>(q + cur_at(f)) = Fa / n;
    }
  }
  // largest eig(sigma~) - sigma_crit, with the Gershgorin shortcut of models/damage.hpp.
  Real stress_excess(const Mat<Dim>& F, Real logJ, const Real* q) const {
    return Matrix::eigenvalue_excess(driving_stress(F, logJ, q), m_.sigma_crit());
  }

  Matrix m_;
  Real alpha_, fiber_E_, fiber_k_, alpha_l_;
};

}  // namespace mpmtb
