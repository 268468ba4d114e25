// Isotropic continuum damage on compressible neo-Hookean elasticity, after
//   Wolper, Fang, Li, Lu, Gao, Jiang 2019, "CD-MPM: Continuum Damage Material
//     Point Methods for Dynamic Fracture Animation", ACM TOG 38(4): degradation
//     g = (1 - k) c^2 + k of the tensile energy only, c = 1 - d;
//   Wolper, Chen, Li, Fang, Jiang 2020, "AnisoMPM: Animating Anisotropic
//     Damage Mechanics", ACM TOG 39(4): the stress-driven damage evolution
//       eta dd/dt = <(1 - d) D~ - (d - l0^2 lap d)>,  D~ = zeta <phi - 1>,
//     here isotropic (no structural tensor) with phi = sigma_max / sigma_crit.
//   Equation numbers are not given: they were not checked against the papers.
// Length scale: the l0^2 lap d term needs the grid. The model asks for it
// (laplacian_request) and the step writes lap d, computed on the grid by
// core/nonlocal.hpp, into the state before return_map. l0 = 0 is the local
// model exactly (no Laplacian is asked for, and project takes the local path).
//
// Energy: psi(F, d) = g(d) psi+(F) + psi-(F), g(d) = (1 - d)^2 (1 - k) + k.
// Split (Amor, Marigo & Maurini 2009, volumetric-deviatoric, adapted to
// neo-Hookean). With J = det F, s = J^(2/dim), the neo-Hookean energy
//   psi = mu/2 (tr F^T F - dim) - mu ln J + lambda/2 (ln J)^2
// is split exactly as psi = psi_dev + psi_vol with
//   psi_vol(J) = psi(J^(1/dim) I) = mu dim/2 (s - 1) - mu ln J + lambda/2 (ln J)^2,
//   psi_dev(F) = psi - psi_vol   = mu/2 (tr F^T F - dim s).
// psi_vol is the energy of the pure dilation with the same J; psi_dev >= 0 by
// AM-GM on the eigenvalues of F^T F (tr C >= dim det(C)^(1/dim)), = 0 iff F is
// a rotation times a dilation; psi_dev = 0 identically in 1D. Then
//   J >= 1: psi+ = psi_dev + psi_vol,  psi- = 0;
//   J <  1: psi+ = psi_dev,            psi- = psi_vol.
// psi+ + psi- = psi exactly, psi+ >= 0 always (for x = ln J > 0,
// psi_vol >= (lambda/2 + mu/dim) x^2 = K/2 x^2 with bulk modulus K > 0), and
// psi- = psi_vol >= 0 whenever lambda >= 0 (nu >= 0); for nu < 0 it is >= 0
// near J = 1 but the neo-Hookean energy itself turns negative under extreme
// compression. psi_vol(1) = psi_vol'(1) = 0, so the switch at J = 1 is C^1.
// A fully damaged particle (g = k) under J < 1 keeps the whole volumetric
// stress (all of it in 1D and under pure dilation) but no tensile stress.
// Stresses (d held fixed; F^-T the inverse transpose):
//   P_dev = mu (F - s F^-T),                   tau_dev = mu (F F^T - s I),
//   P_vol = (mu (s - 1) + lambda ln J) F^-T,   tau_vol = (mu (s - 1) + lambda ln J) I.
//
// Damage driver (project, after F is updated): sigma_max = the largest
// principal value of the UNDAMAGED Cauchy stress tau(F, d = 0) / J,
// phi = sigma_max / sigma_crit, D~ = zeta <phi - 1>,
//   d <- min(1, d + h <(1 - d) D~ - (d - l0^2 lap d)>),  h = dt/eta,
// so d never decreases and stays in [0, 1]. With l0 = 0 (or a uniform d) it
// grows only once phi > 1; with l0 > 0 damage also spreads from damaged
// neighbours (lap d > 0) over a distance of order l0: in a region with D~ = 0
// the steady profile solves d = l0^2 d'', d ~ exp(-|x| / l0).
// The explicit diffusion h l0^2 lap d would be unstable for h l0^2 4 Dim/dx^2
// > 2, i.e. l0 above about one cell with the default eta; the Laplacian's
// diagonal a = l0^2 2 Dim / dx^2 (from the step) is therefore taken
// implicitly, d_new - d = h (R - a (d_new - d)) with R the explicit rate, i.e.
// h -> h / (1 + h a): first order in dt like the explicit update, the same
// steady state, and the grid modes stay bounded for any l0 with h <= 2.
// The elastic energy released at fixed F, (g(d_old) - g(d_new)) psi+(F), is added
// to the dissipated energy, keeping kinetic + strain + gravity + dissipated.
// Parameters: E, nu, density; sigma_crit > 0 (required); zeta > 0 (1);
// eta > 0 (1e-3, a time scale: smaller = faster); k in [0, 1) (1e-6);
// l0 >= 0 (0.02, a length: 1.3 cells of the pinned block, dx = 1/64; it
// should span 1 to 2 cells of the grid it runs on; 0 = local).
// State per particle: {damage d, dissipated energy per unit initial volume,
// lap d and the diagonal 2 Dim / dx^2, both written by the step}.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "models/lame.hpp"
#include "models/model.hpp"

namespace mpmtb {

template <int Dim>
class Damage final : public ModelBase<Dim, Damage<Dim>> {
 public:
  static constexpr std::string_view model_name = "damage";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{wolper2019,
  author = {Wolper, Joshuah and Fang, Yu and Li, Minchen and Lu, Jiecong and Gao, Ming and Jiang, Chenfanfu},
  title = {{CD-MPM}: continuum damage material point methods for dynamic fracture animation},
  journal = {ACM Transactions on Graphics},
  volume = {38},
  number = {4},
  year = {2019}
}
@article{wolper2020,
  author = {Wolper, Joshuah and Chen, Yunuo and Li, Minchen and Fang, Yu and Qu, Ziyin and Lu, Jiecong and Cheng, Meggie and Jiang, Chenfanfu},
  title = {{AnisoMPM}: animating anisotropic damage mechanics},
  journal = {ACM Transactions on Graphics},
  volume = {39},
  number = {4},
  year = {2020}
})bib";
  enum StateIndex { kDamage = 0, kDissipated = 1, kLapDamage = 2, kLapDiagonal = 3 };

  explicit Damage(Parameters& params)
      : c_(ElasticConstants::read(params)),
        sigma_crit_(params.required("sigma_crit", Range::positive())),
        zeta_(params.optional("zeta", 1, Range::positive())),
        eta_(params.optional("eta", 1e-3, Range::positive())),
        k_(params.optional("k", 1e-6, Range::half_open(0, 1))),
        l0_(params.optional("l0", 0.02, Range::non_negative())) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }
  int state_size() const override { return 4; }
  void initial_state(Real* q) const override {
    q[kDamage] = 0;
    q[kDissipated] = 0;
    q[kLapDamage] = 0;
    q[kLapDiagonal] = 0;
  }
  std::vector<std::string> state_names() const override {
    return {"damage", "dissipated", "lap_damage", "lap_diagonal"};
  }
  LaplacianRequest laplacian_request() const override {
    return l0_ > 0 ? LaplacianRequest{kDamage, kLapDamage} : LaplacianRequest{};
  }

  Real sigma_crit() const { return sigma_crit_; }
  Real zeta() const { return zeta_; }
  Real eta() const { return eta_; }
  Real l0() const { return l0_; }
  const ElasticConstants& elastic() const { return c_; }
  Real degradation(Real d) const { return degradation_of(d); }
  // The same for T = Real or Lanes (core/lanes.hpp), the same operations per lane.
  template <class T>
  MPMTB_INLINE T degradation_of(T d) const {
    return (Real(1) - d) * (Real(1) - d) * (1 - k_) + k_;
  }

  // The tensile (degraded) and compressive (kept) parts of the energy.
  struct Split {
    Real plus = 0, minus = 0;
  };
  Split split(const Mat<Dim>& F) const {
    const Real J = F.determinant(), logJ = std::log(J);
    return split(F, J, logJ, pow_2_over_dim(J, logJ));
  }
  // The same with J, ln J and s = J^(2/dim) given.
  Split split(const Mat<Dim>& F, Real J, Real logJ, Real s) const {
    // Rounding can leave tr C - dim s a few ulps below its bound 0.
    const Real dev = std::max(Real(0), Real(0.5) * c_.mu * ((F.transpose() * F).trace() - Dim * s));
    const Real vol =
        Real(0.5) * c_.mu * Dim * (s - 1) - c_.mu * logJ + Real(0.5) * c_.lambda * logJ * logJ;
    return J >= 1 ? Split{dev + vol, 0} : Split{dev, vol};
  }

  Real psi(const Mat<Dim>& F, const Real* q) const {
    const Split e = split(F);
    return degradation(damage(q)) * e.plus + e.minus;
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real* q) const {
    const Real J = F.determinant(), s = pow_2_over_dim(J, std::log(J));
    const Mat<Dim> F_invT = F.inverse().transpose();
    const Mat<Dim> P_dev = c_.mu * (F - s * F_invT);
    const Mat<Dim> P_vol = (c_.mu * (s - 1) + c_.lambda * std::log(J)) * F_invT;
    const Real g = degradation(damage(q));
    return J >= 1 ? Mat<Dim>(g * (P_dev + P_vol)) : Mat<Dim>(g * P_dev + P_vol);
  }
  // dP = (dP/dF) : dF at fixed d (the implicit integrators' Hessian), the
  // differential of P above with t = F^-T : dF = d ln J, ds = (2/dim) s t and
  // d(F^-T) = -F^-T dF^T F^-T (Bonet & Wood 2008, sec. 6.4.3):
  //   dP_dev = mu (dF - (2/dim) s t F^-T + s F^-T dF^T F^-T),
  //   dP_vol = ((2/dim) mu s + lambda) t F^-T - (mu (s - 1) + lambda ln J) F^-T dF^T F^-T,
  // degraded as P is (their sum is neo-Hookean's dP). At J = 1 the branch is P's.
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real* q) const {
    const Real J = F.determinant(), logJ = std::log(J), s = pow_2_over_dim(J, logJ);
    const Mat<Dim> F_invT = F.inverse().transpose();
    const Mat<Dim> dF_invT = -F_invT * dF.transpose() * F_invT;
    const Real t = F_invT.cwiseProduct(dF).sum(), ds = Real(2) / Dim * s * t;
    const Mat<Dim> dP_dev = c_.mu * (dF - ds * F_invT - s * dF_invT);
    const Mat<Dim> dP_vol =
        (c_.mu * ds + c_.lambda * t) * F_invT + (c_.mu * (s - 1) + c_.lambda * logJ) * dF_invT;
    const Real g = degradation(damage(q));
    return J >= 1 ? Mat<Dim>(g * (dP_dev + dP_vol)) : Mat<Dim>(g * dP_dev + dP_vol);
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const {
    return tau_with(F, degradation(damage(q)));
  }
  // tau with ln J given: the stress pass takes the logarithms of a batch at once
  // (ModelBase::kirchhoff_times_volume).
  Mat<Dim> tau_given_log(const Mat<Dim>& F, Real logJ, const Real* q) const {
    return tau_with(F, logJ, degradation(damage(q)));
  }
  // The same times V0, into out (ModelBase::kirchhoff_times_volume): entry by
  // entry, so that nothing is read back from the stack in wider loads.
  void tau_times_volume_given_log(const Mat<Dim>& F, Real logJ, const Real* q, Real V0,
                                  Mat<Dim>& out) const {
    tau_entries(F, logJ, degradation(damage(q)), [&](int i, int j, Real t) { out(i, j) = V0 * t; });
  }
  // In 3D the stress pass takes s = J^(2/3) = exp(kPowerOfLog ln J) a batch at
  // a time too (ModelBase::kirchhoff_times_volume, core/batch_exp.hpp).
  static constexpr Real kPowerOfLog = Real(2) / 3;
  void tau_times_volume_given_log_and_power(const Mat<Dim>& F, Real logJ, Real s, const Real* q,
                                            Real V0, Mat<Dim>& out) const requires(Dim == 3) {
    tau_entries(F, logJ, s, degradation(damage(q)),
                [&](int i, int j, Real t) { out(i, j) = V0 * t; });
  }
  // The same over a register of particles (ModelBase::stress_batch).
  MPMTB_INLINE void tau_times_volume_lanes(const Particles<Dim>& particles, const int* ids,
                                           int lanes, const Lanes (&F)[Dim][Dim], Lanes J,
                                           Lanes logJ, Lanes s, Lanes V0,
                                           Lanes (&out)[Dim][Dim]) const requires(Dim == 3) {
    // g(d) over the register (lane by lane, the formula was a third of the
    // lanes' instructions before the stress itself).
    const Lanes g = degradation_of(lanes_from(lanes, Real(0), [&](int l) MPMTB_INLINE_LAMBDA {
      return particles.state_of(ids[l])[kDamage];
    }));
    tau_entries_of<Lanes>([&](int i, int j) MPMTB_INLINE_LAMBDA { return F[i][j]; }, J, logJ, s, g,
                          [&](int i, int j, Lanes t) MPMTB_INLINE_LAMBDA { out[i][j] = V0 * t; });
  }
  // Undamaged Cauchy stress sigma = tau(F, d = 0) / J: the damage driver.
  Mat<Dim> undamaged_cauchy(const Mat<Dim>& F) const {
    return undamaged_cauchy(F, std::log(F.determinant()));
  }
  Mat<Dim> undamaged_cauchy(const Mat<Dim>& F, Real logJ) const {
    return undamaged_cauchy(F, logJ, pow_2_over_dim(F.determinant(), logJ));
  }
  // The same with s = J^(2/dim) given.
  Mat<Dim> undamaged_cauchy(const Mat<Dim>& F, Real logJ, Real s) const {
    const Real J = F.determinant();
    Mat<Dim> sigma;
    tau_entries(F, logJ, s, 1, [&](int i, int j, Real t) { sigma(i, j) = t / J; });
    return sigma;
  }
  Real max_principal_stress(const Mat<Dim>& F) const {
    return max_symmetric_eigenvalue(undamaged_cauchy(F));
  }
  // sigma_max - sigma_crit, or a negative number when a cheap bound shows that
  // sigma_max stays below sigma_crit (most particles, most steps).
  Real stress_excess(const Mat<Dim>& F) const {
    return stress_excess(F, std::log(F.determinant()));
  }
  Real stress_excess(const Mat<Dim>& F, Real logJ) const {
    return eigenvalue_excess(undamaged_cauchy(F, logJ), sigma_crit_);
  }
  // The largest eigenvalue of the symmetric part of s: in 3D in closed form
  // (largest_eigenvalue_3x3) where that is accurate, else by Eigen's iterative
  // solver.
  static Real max_symmetric_eigenvalue(const Mat<Dim>& s) {
    if constexpr (Dim == 1) {
      return s(0, 0);
    } else {
      const Mat<Dim> sym = Real(0.5) * (s + s.transpose());
      if constexpr (Dim == 3) {
        Real largest;
        if (largest_eigenvalue_3x3(sym, largest)) return largest;
      }
      Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig(sym, Eigen::EigenvaluesOnly);
      return eig.eigenvalues().maxCoeff();
    }
  }
  // The largest eigenvalue of a symmetric 3 x 3 matrix A in closed form (Smith
  // 1961, "Eigenvalues of a symmetric 3 x 3 matrix", Commun. ACM 4(4) 168): with
  // q = tr A / 3, p^2 = tr((A - q I)^2) / 6 and r = det((A - q I) / p) / 2 in
  // [-1, 1], the eigenvalues are q + 2 p cos((acos r + 2 pi k) / 3), k = 0, 1, 2,
  // the largest at k = 0. False, and nothing written, where the two largest
  // nearly coincide (r near -1, where acos is steep and the closed form loses
  // half its digits) or A is not finite: the caller's iterative solver decides.
  // Elsewhere within a few eps |A| of that solver (tests/unit/damage_test.cpp);
  // in the tearing pinned block the solve was 13 % of the run, about 320 ns a
  // particle against 50 for this.
  static bool largest_eigenvalue_3x3(const Mat<3>& A, Real& largest) {
    constexpr Real kNearDouble = Real(1e-2);  // r within this of -1: the solver
    const Real q = A.trace() / 3;
    const Real a = A(0, 0) - q, b = A(1, 1) - q, c = A(2, 2) - q;
    const Real d = A(0, 1), e = A(1, 2), f = A(0, 2);
    const Real p2 = (a * a + b * b + c * c + 2 * (d * d + e * e + f * f)) / 6;
    if (p2 == 0) {  // A = q I
      largest = q;
      return true;
    }
    const Real p = std::sqrt(p2);
    const Real det = a * (b * c - e * e) - d * (d * c - e * f) + f * (d * e - b * f);
    const Real r = det / (2 * p2 * p);
    if (!(r > -1 + kNearDouble)) return false;  // also NaN
    largest = q + 2 * p * std::cos(std::acos(std::min(r, Real(1))) / 3);
    return true;
  }
  // max_symmetric_eigenvalue(s) - limit, or a negative number when it is shown
  // to stay below the limit without the eigenvalue solve (the caller reads only
  // the sign of a negative excess). First Gershgorin's bound: every eigenvalue of
  // a symmetric A is at most max_i (A_ii + sum_{j != i} |A_ij|). Where that fails
  // (a strong shear: most particles near the ball of the pinned block, where
  // the solve took 12 % of the run), Sylvester's criterion: c I - A is positive
  // definite, i.e. every eigenvalue is below c, exactly when its leading
  // principal minors are all positive (Horn & Johnson 2013, Matrix Analysis,
  // Thm. 7.2.5). The margin below the limit, and the minors' own rounding
  // allowed for, keep the answer the solver's for stresses within round-off of
  // the limit. Shared with aniso-damage, which drives the damage with its
  // weighted stress.
  // (Gershgorin's bound inline, as the return map's common case: called out of
  // line, it read the stress back from the stack, and the early pinned block
  // spent 4 % of its time there; the rest out of line.)
  MPMTB_INLINE static Real eigenvalue_excess(const Mat<Dim>& s, Real limit) {
    if constexpr (Dim >= 2) {
      Real bound = -std::numeric_limits<Real>::infinity();
      for (int i = 0; i < Dim; ++i) {
        Real row = s(i, i);
        for (int j = 0; j < Dim; ++j) {
          if (j != i) row += Real(0.5) * std::abs(s(i, j) + s(j, i));
        }
        bound = std::max(bound, row);
      }
      if (bound < limit * (1 - kBelowLimit)) return bound - limit;
    }
    return excess_beyond_bound(s, limit);
  }
  // eigenvalue_excess where Gershgorin's bound fails: Sylvester's criterion, else
  // the solve.
  [[gnu::noinline]] static Real excess_beyond_bound(const Mat<Dim>& s, Real limit) {
    if constexpr (Dim >= 2) {
      const Real below = limit * (1 - kBelowLimit);
      const Mat<Dim> shifted = below * Mat<Dim>::Identity() - Real(0.5) * (s + s.transpose());
      if (certainly_positive_definite(shifted)) return below - limit;
    }
    return max_symmetric_eigenvalue(s) - limit;
  }
  // Sylvester's criterion with every leading minor above the rounding of its
  // own evaluation (a generous multiple of the unit round-off times the sum of
  // the magnitudes of its products): false when that cannot be decided.
  static bool certainly_positive_definite(const Mat<Dim>& M) {
    static_assert(Dim == 2 || Dim == 3);
    constexpr Real tol = 64 * std::numeric_limits<Real>::epsilon();
    if (!(M(0, 0) > 0)) return false;
    const Real m2 = M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0);
    if (!(m2 > tol * (std::abs(M(0, 0) * M(1, 1)) + std::abs(M(0, 1) * M(1, 0))))) return false;
    if constexpr (Dim == 2) {
      return true;
    } else {
      const Real c0 = M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1);
      const Real c1 = M(1, 0) * M(2, 2) - M(1, 2) * M(2, 0);
      const Real c2 = M(1, 0) * M(2, 1) - M(1, 1) * M(2, 0);
      const Real m3 = M(0, 0) * c0 - M(0, 1) * c1 + M(0, 2) * c2;
      const Real size =
          std::abs(M(0, 0)) * (std::abs(M(1, 1) * M(2, 2)) + std::abs(M(1, 2) * M(2, 1))) +
          std::abs(M(0, 1)) * (std::abs(M(1, 0) * M(2, 2)) + std::abs(M(1, 2) * M(2, 0))) +
          std::abs(M(0, 2)) * (std::abs(M(1, 0) * M(2, 1)) + std::abs(M(1, 1) * M(2, 0)));
      return m3 > tol * size;
    }
  }

  // Damage update at fixed F (lap d, when l0 > 0, from the step); F is not changed.
  void project(Mat<Dim>& F, Real* q, Real dt) const {
    project_given_log(F, std::log(F.determinant()), q, dt);
  }
  // The same with ln J given: the return map takes the logarithms of a batch at
  // once (ModelBase::return_map).
  void project_given_log(Mat<Dim>& F, Real logJ, Real* q, Real dt) const {
    project_by(
        F, logJ, q, dt, [&] { return stress_excess(F, logJ); }, [&] { return split(F).plus; });
  }
  // The same with s = J^(2/3) given too: the return map takes the exponentials
  // of a batch at once (ModelBase::return_map) where project_given_log took two
  // scalar ones, for the driver's stress and for the split (perf: 5 % of the
  // tearing pinned block). The batch's ln J and s round as core/batch_log.hpp
  // and core/batch_exp.hpp do, within an ulp of std::log and std::exp.
  void project_given_log_and_power(Mat<Dim>& F, Real logJ, Real s, Real* q, Real dt) const
      requires(Dim == 3) {
    project_by(
        F, logJ, q, dt,
        [&] { return eigenvalue_excess(undamaged_cauchy(F, logJ, s), sigma_crit_); },
        [&] { return split(F, F.determinant(), logJ, s).plus; });
  }
  // The damage update from the excess sigma_max - sigma_crit and the tensile
  // energy psi+, each computed only where needed.
  template <class Excess, class Plus>
  void project_by(const Mat<Dim>& F, Real logJ, Real* q, Real dt, Excess&& excess_of,
                  Plus&& plus_of) const {
    const Real d_old = q[kDamage];
    if (d_old >= 1) return;
    const Real excess = certainly_below_limit(F, logJ) ? -sigma_crit_ : excess_of();
    const Real d_new = advanced_damage(d_old, excess, q, dt);
    if (!(d_new > d_old)) return;
    q[kDissipated] += (degradation(d_old) - degradation(d_new)) * plus_of();
    q[kDamage] = d_new;
  }
  // True when sigma_max < sigma_crit (1 - 1e-9) is certain from a bound that
  // needs neither the exp of J^(2/dim) nor the divisions by J of
  // undamaged_cauchy: the undamaged tau is neo-Hookean's, mu F F^T + (lambda ln J
  // - mu) I (the split's s terms cancel), and Gershgorin bounds its eigenvalues
  // (as eigenvalue_excess), compared with J sigma_crit; the bound's own rounding,
  // a few eps of the sum of its terms' magnitudes, is allowed for. Where it holds
  // (most particles, most steps) the excess is negative, which is all the rate
  // law reads of it; elsewhere the exact driver decides.
  bool certainly_below_limit(const Mat<Dim>& F, Real logJ) const {
    return certainly_below_limit(F, F.determinant(), c_.lambda * logJ - c_.mu);
  }
  // The return map leaves the particle as it is (the particle-by-particle
  // statement; the return map screens with unsettled(), its lanes, which the
  // tests hold to it): fully damaged, or the stress certainly below the
  // threshold by the bound above with ln J bounded without the logarithm (ln J
  // <= J - 1, and ln J >= 1 - 1/J for lambda < 0) and no growth from the
  // nonlocal term either.
  bool settled(const Mat<Dim>& F, Real J, const Real* q, Real dt) const {
    const Real d_old = q[kDamage];
    if (d_old >= 1) return true;
    if (!(J > 0)) return false;
    const Real lnJ_bound = c_.lambda >= 0 ? J - 1 : 1 - 1 / J;
    return certainly_below_limit(F, J, c_.lambda * lnJ_bound - c_.mu) &&
           !(advanced_damage(d_old, -sigma_crit_, q, dt) > d_old);
  }
  // settled() for the particles ids[0..count), a vector register of them at a
  // time: the same operations lane by lane (det F as Eigen forms it, the bound
  // of certainly_below_limit, the rate law's growth test), so the same answers
  // and, for the logarithm that ModelBase::return_map takes next, the same
  // det F. Writes det F and the id of every particle not settled to J and
  // kept; returns their count. (Particle by particle, the screen was a chain
  // of scalar operations: 8 % of the pinned block's step before the ball
  // strikes, when it settles every particle.)
  int unsettled(const Particles<Dim>& P, const int* ids, int count, Real dt, Real* J,
                int* kept) const {
    constexpr int L = kLanes;  // core/lanes.hpp
    int m = 0;
    for (int first = 0; first < count; first += L) {
      const int n = std::min(L, count - first);
      Lanes F[Dim][Dim], d{}, lap{}, diag{};
      // F by transposes where a whole register's particles are there (core/lanes.hpp;
      // the identity in the lanes past the end, which are not read).
      load_lanes<Dim>(P.F, ids + first, n, F);
      bool loaded = false;
      if constexpr (kRecordTransposes) {
        if (n == L) {  // the state records by transposes (core/lanes.hpp)
          static_assert(kDamage == 0 && kLapDamage == 2 && kLapDiagonal == 3);
          Lanes record[4];
          load_record_lanes(P.state.data(), P.state_size, ids + first, record);
          d = record[kDamage], lap = record[kLapDamage], diag = record[kLapDiagonal];
          loaded = true;
        }
      }
      if (!loaded) {
        for (int k = 0; k < L; ++k) {
          const int p = ids[first + std::min(k, n - 1)];  // the last one again past the end
          const Real* q = P.state_of(p);
          d[k] = q[kDamage], lap[k] = q[kLapDamage], diag[k] = q[kLapDiagonal];
        }
      }
      const Lanes det = determinant_of<Dim>(F);  // Eigen's, lane by lane
      const auto settled = settled_lanes(F, det, d, lap, diag, dt);
      if (n == L && all_lanes(settled)) continue;  // most registers, most steps
      for (int k = 0; k < n; ++k) {
        if (!settled[k]) J[m] = det[k], kept[m++] = ids[first + k];
      }
    }
    return m;
  }
  // settled(F, J, q, dt) lane by lane, with q's damage, lap d and its diagonal
  // in d_old, lap and diag: the mask of the particles settled.
  template <class Lanes>
  MPMTB_INLINE auto settled_lanes(const Lanes (&F)[Dim][Dim], Lanes J, Lanes d_old, Lanes lap,
                                  Lanes diag, Real dt) const {
    const Lanes zero{}, one = zero + 1;
    const auto abs = [](Lanes x) MPMTB_INLINE_LAMBDA {  // std::abs: the sign bit cleared
      using Ints = decltype(x < x);
      using Int = std::remove_cvref_t<decltype(Ints{}[0])>;
      return std::bit_cast<Lanes>(std::bit_cast<Ints>(x) &
                                  ~(Ints{} + std::numeric_limits<Int>::min()));
    };
    // certainly_below_limit(F, J, lambda lnJ_bound - mu)
    const Lanes lnJ_bound = c_.lambda >= 0 ? J - 1 : 1 - 1 / J;
    const Lanes shift = c_.lambda * lnJ_bound - c_.mu;
    Lanes bound = zero - std::numeric_limits<Real>::infinity(), size = abs(shift);
    for (int i = 0; i < Dim; ++i) {
      Lanes row = shift, magnitude = zero;
      for (int j = 0; j < Dim; ++j) {
        Lanes FFt = F[i][0] * F[j][0];
        for (int k = 1; k < Dim; ++k) FFt += F[i][k] * F[j][k];
        row += i == j ? c_.mu * FFt : c_.mu * abs(FFt);
        magnitude += c_.mu * abs(FFt);
      }
      bound = bound < row ? row : bound;  // std::max(bound, row)
      size += magnitude;
    }
    constexpr Real rounding = 32 * std::numeric_limits<Real>::epsilon();
    const auto below = (J > 0) & (bound + rounding * size < sigma_crit_ * (1 - kBelowLimit) * J);
    // advanced_damage(d_old, -sigma_crit, q, dt) > d_old: the excess is negative, D = 0.
    Lanes drive = (one - d_old) * zero - d_old, h = zero + dt / eta_;
    if (l0_ > 0) {
      const Real l2 = l0_ * l0_;
      drive += l2 * lap;
      h /= 1 + h * l2 * diag;
    }
    const Lanes rate = zero < drive ? drive : zero;  // std::max(Real(0), drive)
    const Lanes grown = d_old + h * rate;
    const Lanes d_new = grown < one ? grown : one;  // std::min(Real(1), grown)
    const auto grows = (rate > 0) & (d_new > d_old);
    return (d_old >= 1) | (below & ~grows);
  }
  // The bound for a given lambda ln J - mu (or an upper bound of it).
  bool certainly_below_limit(const Mat<Dim>& F, Real J, Real shift) const {
    if (!(J > 0)) return false;
    Real bound = -std::numeric_limits<Real>::infinity(), size = std::abs(shift);
    for (int i = 0; i < Dim; ++i) {
      Real row = shift, magnitude = 0;
      for (int j = 0; j < Dim; ++j) {
        Real FFt = F(i, 0) * F(j, 0);
        for (int k = 1; k < Dim; ++k) FFt += F(i, k) * F(j, k);
        row += i == j ? c_.mu * FFt : c_.mu * std::abs(FFt);
        magnitude += c_.mu * std::abs(FFt);
      }
      bound = std::max(bound, row);
      size += magnitude;
    }
    constexpr Real rounding = 32 * std::numeric_limits<Real>::epsilon();
    return bound + rounding * size < sigma_crit_ * (1 - kBelowLimit) * J;
  }
  // The rate law's step from d_old < 1, driven by excess = sigma_max -
  // sigma_crit (the nonlocal terms from q when l0 > 0); d_old when it does not
  // grow. Shared with aniso-damage, which drives it with its weighted stress.
  Real advanced_damage(Real d_old, Real excess, const Real* q, Real dt) const {
    // D~ = zeta <phi - 1> with phi = sigma_max / sigma_crit, written so that
    // D~ > 0 exactly when sigma_max > sigma_crit (no rounding of the quotient).
    const Real D = excess > 0 ? zeta_ * excess / sigma_crit_ : Real(0);
    Real drive = (1 - d_old) * D - d_old, h = dt / eta_;
    if (l0_ > 0) {  // the nonlocal term; the local path is untouched otherwise
      const Real l2 = l0_ * l0_;
      drive += l2 * q[kLapDamage];
      h /= 1 + h * l2 * q[kLapDiagonal];
    }
    const Real rate = std::max(Real(0), drive);
    if (!(rate > 0)) return d_old;  // also guards against NaN
    return std::min(Real(1), d_old + h * rate);
  }
  Real dissipated(const Real* q) const { return q[kDissipated]; }

 private:
  static Real damage(const Real* q) { return q ? q[kDamage] : Real(0); }
  // J^(2/dim); in 3D as exp(2/3 ln J), reusing the logarithm the stress needs anyway.
  static Real pow_2_over_dim(Real J, Real logJ) {
    if constexpr (Dim == 1) return J * J;
    if constexpr (Dim == 2) return J;
    if constexpr (Dim == 3) return std::exp(Real(2) / 3 * logJ);
  }
  // Kirchhoff stress with the tensile part scaled by g.
  Mat<Dim> tau_with(const Mat<Dim>& F, Real g) const {
    return tau_with(F, std::log(F.determinant()), g);
  }
  Mat<Dim> tau_with(const Mat<Dim>& F, Real logJ, Real g) const {
    Mat<Dim> tau;
    tau_entries(F, logJ, g, [&](int i, int j, Real t) { tau(i, j) = t; });
    return tau;
  }
  // out(i, j, tau_ij) for every entry of tau = tau_dev + tau_vol with the tensile
  // part scaled by g, tau_dev = mu (F F^T - s I), tau_vol = (mu (s - 1) + lambda
  // ln J) I, entry by entry (F F^T is symmetric): written with Eigen's
  // expressions, the temporaries went through the stack in pieces read back by
  // wider loads, and half of the stress stalled on store forwarding (perf, the
  // pinned block).
  template <class Out>
  MPMTB_INLINE void tau_entries(const Mat<Dim>& F, Real logJ, Real g, Out&& out) const {
    tau_entries(F, logJ, pow_2_over_dim(F.determinant(), logJ), g, out);
  }
  // The same with s = J^(2/dim) given.
  template <class Out>
  MPMTB_INLINE void tau_entries(const Mat<Dim>& F, Real logJ, Real s, Real g, Out&& out) const {
    tau_entries_of<Real>([&](int i, int j) MPMTB_INLINE_LAMBDA { return F(i, j); }, F.determinant(),
                         logJ, s, g, out);
  }
  // The same for T = Real (one particle) or Lanes (a register of particles,
  // core/lanes.hpp: the tension test a select per lane, the same bits),
  // F(i, j) the entries, J = det F.
  template <class T, class FAt, class Out>
  MPMTB_INLINE void tau_entries_of(FAt&& F, T J, T logJ, T s, T g, Out&& out) const {
    const T vol = c_.mu * (s - Real(1)) + c_.lambda * logJ;
    for (int j = 0; j < Dim; ++j) {
      for (int i = 0; i <= j; ++i) {
        T FFt = F(i, 0) * F(j, 0);
        for (int k = 1; k < Dim; ++k) FFt += F(i, k) * F(j, k);
        const T dev = c_.mu * (i == j ? FFt - s : FFt);
        const T t = i != j ? T(g * dev) : T(J >= Real(1) ? g * (dev + vol) : g * dev + vol);
        out(i, j, t);
        if (i != j) out(j, i, t);
      }
    }
  }

  // How far below the limit eigenvalue_excess's bounds must show the stress,
  // relative: well above the solver's round-off in the precision built.
  static constexpr Real kBelowLimit =
      std::max(Real(1e-9), 1000 * std::numeric_limits<Real>::epsilon());

  ElasticConstants c_;
  Real sigma_crit_, zeta_, eta_, k_, l0_;
};

}  // namespace mpmtb
