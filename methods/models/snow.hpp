// Snow: elastoplasticity of Stomakhin, Schroeder, Chai, Teran & Selle 2013,
// "A material point method for snow simulation", ACM Trans. Graph. 32(4)
// (SIGGRAPH), sec. 5-6. F = F_E F_P; the particle's F is the elastic part F_E
// and the plastic part enters only through J_P = det F_P.
//   psi(F_E, J_P) = mu |F_E - R_E|^2 + lambda/2 (J_E - 1)^2   (fixed-corotated,
//                   fixed_corotated.hpp, of the elastic part)
//   mu = mu0 exp(xi (1 - J_P)), lambda = lambda0 exp(xi (1 - J_P))   (hardening)
// Return map (project): F_E^trial = U Sigma V^T (signed SVD, polar.hpp);
// Sigma is clamped to [1 - theta_c, 1 + theta_s]; F_E = U Sigma_c V^T and
// J_P <- J_P det(Sigma) / det(Sigma_c), so that J = J_E J_P, the determinant of
// the total deformation, is what G2P produced. Defaults theta_c = 2.5e-2,
// theta_s = 7.5e-3, xi = 10 are the paper's reference snow.
//
// Energy budget. The return map changes neither positions nor velocities;
// it replaces the stored energy psi(F_E^trial; J_P^old) by
// psi(F_E; J_P^new). The difference is the energy the plastic flow removed, and
// it is added to `dissipated` (state q[1]) with its sign, so that
// kinetic + strain + gravity + dissipated is conserved through every return
// map exactly (up to round-off), as ConstitutiveModel::dissipated_energy
// promises. Under monotone stretching or compression the increment is
// positive: every singular value moves towards 1 from one side. The clamp is
// not derived from a dissipation potential, though, and the hardening raises
// the stiffness when J_P drops, so the clamp can also raise psi: in mixed
// states (one direction yields in stretch while the volume is compressed, as
// for a few steps at the onset of yield in simple shear) and after a sudden
// large compression (hardening outgrows the released energy). Such a step
// injects energy; it shows as a decrease of `dissipated` rather than as an
// unexplained drift of the total. Clipping the increment at zero would keep
// `dissipated` monotone but break the budget. tests/unit/snow_test.cpp shows
// both cases.
//
// An inverted trial F (det < 0) would give J_P < 0; the step loop reports
// J <= 0 after G2P as unstable before that matters.
// wave_speed() is that of the unhardened material (mu0, lambda0). The adaptive
// time step uses max_wave_speed(): both moduli scale by the hardening
// h = exp(xi (1 - J_P)), so c = c0 sqrt(h), largest where J_P is smallest
// (one pass over the particles for min J_P; exp is monotone).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "models/fixed_corotated.hpp"
#include "models/lame.hpp"
#include "models/model.hpp"
#include "models/polar.hpp"

namespace mpmtb {

template <int Dim>
class Snow final : public ModelBase<Dim, Snow<Dim>> {
 public:
  static constexpr std::string_view model_name = "snow";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{stomakhin2013,
  author = {Stomakhin, Alexey and Schroeder, Craig and Chai, Lawrence and Teran, Joseph and Selle, Andrew},
  title = {A material point method for snow simulation},
  journal = {ACM Transactions on Graphics},
  volume = {32},
  number = {4},
  articleno = {102},
  year = {2013},
  doi = {10.1145/2461912.2461948}
})bib";
  enum StateIndex { kJP = 0, kDissipated = 1 };

  explicit Snow(Parameters& params)
      : c_(ElasticConstants::read(params)),
        theta_c_(params.optional("theta_c", 2.5e-2, Range::open(0, 1))),
        theta_s_(params.optional("theta_s", 7.5e-3, Range::positive())),
        xi_(params.optional("xi", 10, Range::non_negative())) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }
  int state_size() const override { return 2; }
  void initial_state(Real* q) const override {
    q[kJP] = 1;
    q[kDissipated] = 0;
  }
  std::vector<std::string> state_names() const override { return {"J_P", "dissipated"}; }
  Real max_wave_speed(const Particles<Dim>& particles, std::span<const int> ids) const override {
    if (ids.empty()) return wave_speed();
    Real J_P_min = std::numeric_limits<Real>::infinity();
    for (const int p : ids) J_P_min = std::min(J_P_min, particles.state_of(p)[kJP]);
    return wave_speed() * std::sqrt(hardening(J_P_min));
  }
  // F_p is F_E: the total volume ratio is J = J_E J_P.
  Real total_J(const Mat<Dim>& F, const Real* q) const override { return F.determinant() * q[0]; }

  Real theta_c() const { return theta_c_; }
  Real theta_s() const { return theta_s_; }
  // Hardened Lame parameters for the state q.
  Real mu(const Real* q) const { return c_.mu * hardening(q[kJP]); }
  Real lambda(const Real* q) const { return c_.lambda * hardening(q[kJP]); }

  Real psi(const Mat<Dim>& F, const Real* q) const {
    return hardening(q[kJP]) * fixed_corotated_psi<Dim>(F, c_.mu, c_.lambda);
  }
  Real psi_of_sigma(const Vec<Dim>& sigma, const Real* q) const {
    return hardening(q[kJP]) * fixed_corotated_psi_of_sigma<Dim>(sigma, c_.mu, c_.lambda);
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real* q) const {
    return hardening(q[kJP]) * fixed_corotated_P<Dim>(F, c_.mu, c_.lambda);
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const {
    return hardening(q[kJP]) * fixed_corotated_tau<Dim>(F, c_.mu, c_.lambda);
  }
  // The elastic part at the current J_P (semi-implicit, Stomakhin et al. 2013,
  // sec. 5 and 9: the return map follows the solve).
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real* q) const {
    return hardening(q[kJP]) * fixed_corotated_dP<Dim>(F, dF, c_.mu, c_.lambda);
  }

  // The return map of one particle: F is the trial elastic part on entry and
  // the clamped elastic part on exit. A trial state inside the elastic region
  // is left untouched (bit for bit).
  void project(Mat<Dim>& F, Real* q, Real /*dt*/) const {
    const Real lo = 1 - theta_c_, hi = 1 + theta_s_;
    const auto elastic = [&](const Vec<Dim>& sigma) {
      return (sigma.array() >= lo).all() && (sigma.array() <= hi).all();
    };
    // In 2D the singular values alone decide (most particles stay elastic); in
    // 1D and 3D they come from the full SVD anyway.
    if constexpr (Dim == 2) {
      if (elastic(signed_singular_values<Dim>(F))) return;
    }
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    if (Dim != 2 && elastic(svd.sigma)) return;
    // The energies before and after from the singular values (psi's second
    // form, fixed_corotated.hpp): no polar decomposition of either F.
    const Real psi_trial = psi_of_sigma(svd.sigma, q);
    const Vec<Dim> clamped = svd.sigma.cwiseMax(lo).cwiseMin(hi);
    F = svd.U * clamped.asDiagonal() * svd.V.transpose();
    q[kJP] *= svd.sigma.prod() / clamped.prod();
    q[kDissipated] += psi_trial - psi_of_sigma(clamped, q);
  }
  Real dissipated(const Real* q) const { return q[kDissipated]; }

 private:
  Real hardening(Real J_P) const { return std::exp(xi_ * (1 - J_P)); }

  ElasticConstants c_;
  Real theta_c_, theta_s_, xi_;
};

}  // namespace mpmtb
