// Sand: Drucker-Prager elastoplasticity of Klar, Gast, Pradhana, Fu,
// Schroeder, Jiang & Teran 2016, "Drucker-Prager elastoplasticity for sand
// animation", ACM Trans. Graph. 35(4) 103 (SIGGRAPH), sec. 6-7 and
// Algorithm 2; also Jiang et al. 2016, "The material point method for
// simulating continuum materials", SIGGRAPH course, sec. 7.
// F = F_E F_P; the particle's F is the elastic part F_E, and the plastic part
// enters only through J_P = det F_P (so that total_J = J_E J_P).
//
// Elasticity: St. Venant-Kirchhoff in the Hencky (logarithmic) strain
// (Klar et al. 2016, sec. 6.1). With F = U Sigma V^T and eps = ln Sigma
// (a vector of principal strains):
//   psi = mu tr(eps^2) + lambda/2 (tr eps)^2
//   P   = U (2 mu Sigma^-1 eps + lambda tr(eps) Sigma^-1) V^T
//   tau = U (2 mu eps + lambda tr(eps) I) U^T
// It needs det F > 0 (ln of a negative singular value): the model is not
// invertible, and the step loop reports J <= 0 as unstable.
//
// Return map (Klar et al. 2016, sec. 7.3, Algorithm 2), in d = Dim dimensions,
// on the trial eps with its deviatoric part eps_hat = eps - tr(eps)/d I:
//   case II  (tr eps >= 0, expansion): project to the tip of the cone, eps = 0
//            (Sigma = I); sand has no tensile strength;
//   otherwise delta_gamma = |eps_hat| + (d lambda + 2 mu)/(2 mu) tr(eps) alpha,
//   case I   (delta_gamma <= 0): inside the cone, elastic, F untouched;
//   case III (delta_gamma > 0): eps <- eps - delta_gamma eps_hat / |eps_hat|,
//            which keeps tr eps (no plastic volume change on the cone) and lands
//            on |eps_hat| = -(d lambda + 2 mu)/(2 mu) tr(eps) alpha.
// alpha = sqrt(2/3) 2 sin(phi_F) / (3 - sin(phi_F)) (eq. 27), with the friction
// angle phi_F(q) = friction_angle + (h1 q - h3) exp(-h2 q) degrees (eq. 28;
// the paper writes h0 for friction_angle), q the hardening state:
// q += delta_gamma (case III) or |eps| (case II). Defaults h1 = h3 = 0 give a
// constant friction angle of 30 degrees; the paper's hardening is
// friction_angle = 35, h1 = 9, h2 = 0.2, h3 = 10 (phi_F from 25 to 35 degrees).
// The paper's E = 3.537e5 Pa, nu = 0.3, density 2200 kg/m^3.
//
// Energy budget. The return map changes neither positions nor velocities; it
// replaces psi(eps^trial) by psi(eps^new), and the difference is added to
// `dissipated` (state q[2]). psi = mu |eps_hat|^2 + (mu/d + lambda/2) (tr eps)^2
// does not depend on the hardening state, and both projections lower it
// (case II to zero; case III shrinks |eps_hat| at fixed trace), so the
// dissipated energy only grows. J_P <- J_P exp(tr eps^trial - tr eps^new)
// keeps J = J_E J_P what G2P produced (only case II changes it).
//
// Time step: the Hencky stiffness grows in compression. Along a principal
// axis dP_i/dsigma_i = (lambda + 2 mu - tau_i) / sigma_i^2, so
// max_wave_speed() takes c = sqrt(max_i dP_i/dsigma_i / rho) over the
// particles, and never less than the rest value wave_speed().
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "models/lame.hpp"
#include "models/model.hpp"
#include "models/polar.hpp"

namespace mpmtb {

template <int Dim>
class Sand final : public ModelBase<Dim, Sand<Dim>> {
 public:
  static constexpr std::string_view model_name = "sand";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{klar2016,
  author = {Klar, Gergely and Gast, Theodore and Pradhana, Andre and Fu, Chuyuan and Schroeder, Craig and Jiang, Chenfanfu and Teran, Joseph},
  title = {Drucker-Prager elastoplasticity for sand animation},
  journal = {ACM Transactions on Graphics},
  volume = {35},
  number = {4},
  articleno = {103},
  year = {2016},
  doi = {10.1145/2897824.2925906}
})bib";
  enum StateIndex { kJP = 0, kHardening = 1, kDissipated = 2 };

  explicit Sand(Parameters& params)
      : c_(ElasticConstants::read(params)),
        friction_angle_(params.optional("friction_angle", 30, Range::open(0, 90))),
        h1_(params.optional("h1", 0, Range::non_negative())),
        h2_(params.optional("h2", 0.2, Range::positive())),
        h3_(params.optional("h3", 0, Range::half_open(0, friction_angle_))) {
    // phi_F(q) <= friction_angle + max_q h1 q exp(-h2 q) = friction_angle + h1 / (e h2).
    if (friction_angle_ + h1_ / (std::numbers::e_v<Real> * h2_) >= 90) {
      throw InputError(fmt::format(
          "{}.h1 = {}: the hardened friction angle friction_angle + h1 / (e h2) = {} must stay "
          "below 90 degrees",
          params.context(), h1_, friction_angle_ + h1_ / (std::numbers::e_v<Real> * h2_)));
    }
  }

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }
  int state_size() const override { return 3; }
  void initial_state(Real* q) const override {
    q[kJP] = 1;
    q[kHardening] = 0;
    q[kDissipated] = 0;
  }
  std::vector<std::string> state_names() const override {
    return {"J_P", "hardening_q", "dissipated"};
  }
  Real total_J(const Mat<Dim>& F, const Real* q) const override { return F.determinant() * q[kJP]; }
  Real max_wave_speed(const Particles<Dim>& particles, std::span<const int> ids) const override {
    const long n = static_cast<long>(ids.size());
    Real stiffness = c_.lambda + 2 * c_.mu;  // the rest value
#pragma omp parallel for schedule(static) reduction(max : stiffness) if (n >= kParallelMinimum)
    for (long i = 0; i < n; ++i) {
      const Vec<Dim> sigma = signed_svd<Dim>(particles.F[ids[i]]).sigma;
      const Vec<Dim> tau = kirchhoff_principal(log_strain(sigma));
      for (int a = 0; a < Dim; ++a) {
        stiffness = std::max(stiffness, (c_.lambda + 2 * c_.mu - tau[a]) / (sigma[a] * sigma[a]));
      }
    }
    return std::sqrt(stiffness / c_.density);
  }

  Real mu() const {
    return c_.mu;
  }
  Real lambda() const {
    return c_.lambda;
  }
  // Friction angle phi_F(q) in degrees and the cone's slope alpha (eq. 27-28).
  Real friction_angle(const Real* q) const {
    const Real hq = q[kHardening];
    return friction_angle_ + (h1_ * hq - h3_) * std::exp(-h2_ * hq);
  }
  Real alpha(const Real* q) const {
    const Real s = std::sin(friction_angle(q) * std::numbers::pi_v<Real> / 180);
    return std::sqrt(Real(2) / 3) * 2 * s / (3 - s);
  }

  // Energy density of the principal Hencky strains eps.
  Real psi_of_strain(const Vec<Dim>& eps) const {
    const Real tr = eps.sum();
    return c_.mu * eps.squaredNorm() + Real(0.5) * c_.lambda * tr * tr;
  }
  Real psi(const Mat<Dim>& F, const Real*) const {
    return psi_of_strain(log_strain(signed_svd<Dim>(F).sigma));
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real*) const {
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    const Vec<Dim> tau = kirchhoff_principal(log_strain(svd.sigma));
    return svd.U * tau.cwiseQuotient(svd.sigma).asDiagonal() * svd.V.transpose();
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real*) const {
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    return svd.U * kirchhoff_principal(log_strain(svd.sigma)).asDiagonal() * svd.U.transpose();
  }
  // dP = (dP/dF) : dF of the elastic part (the implicit integrators' Hessian; the
  // return map runs after the solve). P = U diag(p) V^T with p_i = tau_i / sigma_i
  // is isotropic, so in the principal frames, G = U^T dF V and dP = U H V^T
  // (Irving, Teran & Fedkiw 2004, "Invertible finite elements for robust
  // simulation of large deformation", the diagonalised elasticity tensor):
  //   H_ii = sum_j dp_i/dsigma_j G_jj,  dp_i/dsigma_j = (2 mu delta_ij + lambda)
  //          / (sigma_i sigma_j) - delta_ij tau_i / sigma_i^2,
  //   (H_ij, H_ji) = 1/2 [(a + b) (G_ij, G_ji) + (a - b) (G_ji, G_ij)], i != j,
  //   a = (p_i - p_j) / (sigma_i - sigma_j), b = (p_i + p_j) / (sigma_i + sigma_j),
  // a written without the cancellation at sigma_i = sigma_j:
  //   a = 2 mu (ln sigma_i - ln sigma_j) / ((sigma_i - sigma_j) sigma_i) - tau_j / (sigma_i
  //   sigma_j),
  // with (ln sigma_i - ln sigma_j) / (sigma_i - sigma_j) = log1p(x) / (x sigma_j),
  // x = (sigma_i - sigma_j) / sigma_j (1 / sigma_j at x = 0).
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real*) const {
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    const Vec<Dim>& s = svd.sigma;
    const Vec<Dim> tau = kirchhoff_principal(log_strain(s));
    const Mat<Dim> G = svd.U.transpose() * dF * svd.V;
    Mat<Dim> H;
    for (int i = 0; i < Dim; ++i) {
      Real h = -tau[i] / (s[i] * s[i]) * G(i, i);
      for (int j = 0; j < Dim; ++j) {
        h += ((i == j ? 2 * c_.mu : Real(0)) + c_.lambda) / (s[i] * s[j]) * G(j, j);
      }
      H(i, i) = h;
      for (int j = i + 1; j < Dim; ++j) {
        const Real x = (s[i] - s[j]) / s[j];
        const Real log_quotient = x == 0 ? 1 / s[j] : std::log1p(x) / (x * s[j]);
        const Real a = 2 * c_.mu * log_quotient / s[i] - tau[j] / (s[i] * s[j]);
        const Real b = (tau[i] / s[i] + tau[j] / s[j]) / (s[i] + s[j]);
        H(i, j) = Real(0.5) * ((a + b) * G(i, j) + (a - b) * G(j, i));
        H(j, i) = Real(0.5) * ((a - b) * G(i, j) + (a + b) * G(j, i));
      }
    }
    return svd.U * H * svd.V.transpose();
  }

  // The return map of one particle (Algorithm 2): F is the trial elastic part
  // on entry and the projected one on exit. Trial states inside the cone, and
  // the rest state, are left untouched (bit for bit).
  void project(Mat<Dim>& F, Real* q, Real /*dt*/) const {
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    const Vec<Dim> eps = log_strain(svd.sigma);
    const Real tr = eps.sum();
    Vec<Dim> eps_new;
    Real delta_q;
    if (tr >= 0) {  // case II: expansion, to the tip
      if ((eps.array() == 0).all()) return;
      eps_new.setZero();
      delta_q = eps.norm();
    } else {
      const Vec<Dim> eps_hat = eps.array() - tr / Dim;
      const Real eps_hat_norm = eps_hat.norm();
      const Real delta_gamma =
          eps_hat_norm + (Dim * c_.lambda + 2 * c_.mu) / (2 * c_.mu) * tr * alpha(q);
      if (delta_gamma <= 0) return;                            // case I: inside the cone
      eps_new = eps - (delta_gamma / eps_hat_norm) * eps_hat;  // case III: onto the cone
      delta_q = delta_gamma;
    }
    F = svd.U * eps_new.array().exp().matrix().asDiagonal() * svd.V.transpose();
    if (tr >= 0) q[kJP] *= std::exp(tr);  // case III keeps tr eps: J_P exactly unchanged
    q[kHardening] += delta_q;
    q[kDissipated] += psi_of_strain(eps) - psi_of_strain(eps_new);
  }
  Real dissipated(const Real* q) const {
    return q[kDissipated];
  }

 private:
  static Vec<Dim> log_strain(const Vec<Dim>& sigma) {
    return sigma.array().log().matrix();
  }
  // Principal Kirchhoff stresses tau_i = 2 mu eps_i + lambda tr(eps).
  Vec<Dim> kirchhoff_principal(const Vec<Dim>& eps) const {
    return (2 * c_.mu * eps.array() + c_.lambda * eps.sum()).matrix();
  }

  ElasticConstants c_;
  Real friction_angle_, h1_, h2_, h3_;
};

}  // namespace mpmtb
