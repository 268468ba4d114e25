// Compressible neo-Hookean elasticity (Bonet & Wood 2008, eq. 6.28; as used in
// Jiang et al. 2016, "The Material Point Method for Simulating Continuum
// Materials", eq. 48):
//   psi = mu/2 (tr(F^T F) - d) - mu ln J + lambda/2 (ln J)^2
//   P   = mu (F - F^-T) + lambda ln J F^-T
//   tau = P F^T = mu (F F^T - I) + lambda ln J I
// Undefined for J <= 0: the step loop reports such a state as unstable.
#pragma once

#include <cmath>

#include "models/lame.hpp"
#include "models/model.hpp"

namespace mpmtb {

template <int Dim>
class NeoHookean final : public ModelBase<Dim, NeoHookean<Dim>> {
 public:
  static constexpr std::string_view model_name = "neo-hookean";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@book{bonet2008,
  author = {Bonet, Javier and Wood, Richard D.},
  title = {Nonlinear Continuum Mechanics for Finite Element Analysis},
  edition = {2nd},
  publisher = {Cambridge University Press},
  year = {2008}
})bib";

  explicit NeoHookean(Parameters& params) : c_(ElasticConstants::read(params)) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }

  Real psi(const Mat<Dim>& F, const Real*) const {
    const Real logJ = std::log(F.determinant());
    return Real(0.5) * c_.mu * ((F.transpose() * F).trace() - Dim) - c_.mu * logJ +
           Real(0.5) * c_.lambda * logJ * logJ;
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real*) const {
    const Mat<Dim> F_invT = F.inverse().transpose();
    const Real logJ = std::log(F.determinant());
    return c_.mu * (F - F_invT) + c_.lambda * logJ * F_invT;
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const {
    return tau_given_log(F, std::log(F.determinant()), q);
  }
  // tau with ln J given, through the batches' formula below (one particle).
  Mat<Dim> tau_given_log(const Mat<Dim>& F, Real logJ, const Real*) const {
    Real f[Dim][Dim], tau[Dim][Dim];
    for (int i = 0; i < Dim; ++i) {
      for (int j = 0; j < Dim; ++j) f[i][j] = F(i, j);
    }
    tau_times_volume_lanes<Real>(f, logJ, 1, tau);
    Mat<Dim> out;
    for (int i = 0; i < Dim; ++i) {
      for (int j = 0; j < Dim; ++j) out(i, j) = tau[i][j];
    }
    return out;
  }
  // V0 tau = V0 (mu (F F^T - I) + lambda ln J I) with ln J given, lane by lane
  // (core/lanes.hpp: the stress pass takes a register of particles at a time
  // and the logarithms of a batch at once, ModelBase::stress_batch). F F^T is
  // symmetric: its upper triangle, each entry summed over k in order. (Eigen's
  // F * F.transpose() summed rows 0 and 1 in vector registers with FMA and row
  // 2 without on AVX-512 targets, another way on SSE2 ones: neither symmetric
  // bit for bit nor the same bits across instruction sets. This order is.)
  // ModelBase::stress_batch's call: no state, no power of J.
  MPMTB_INLINE void tau_times_volume_lanes(const Particles<Dim>&, const int*, int,
                                           const Lanes (&F)[Dim][Dim], Lanes, Lanes logJ, Lanes,
                                           Lanes V0, Lanes (&out)[Dim][Dim]) const {
    tau_times_volume_lanes<Lanes>(F, logJ, V0, out);
  }
  template <class T>
  MPMTB_INLINE void tau_times_volume_lanes(const T (&F)[Dim][Dim], T logJ, T V0,
                                           T (&out)[Dim][Dim]) const {
    const T lambda_logJ = c_.lambda * logJ;
    for (int i = 0; i < Dim; ++i) {
      for (int j = i; j < Dim; ++j) {
        T FFt = F[i][0] * F[j][0];
        for (int k = 1; k < Dim; ++k) FFt = FFt + F[i][k] * F[j][k];
        out[i][j] = V0 * (i == j ? c_.mu * (FFt - Real(1)) + lambda_logJ : c_.mu * FFt);
        out[j][i] = out[i][j];
      }
    }
  }
  // The differential of P with d(F^-T) = -F^-T dF^T F^-T and d ln J = F^-T : dF
  // (Bonet & Wood 2008, sec. 6.4.3):
  //   dP = mu dF + (mu - lambda ln J) F^-T dF^T F^-T + lambda (F^-T : dF) F^-T.
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real*) const {
    const Mat<Dim> F_invT = F.inverse().transpose();
    const Real logJ = std::log(F.determinant());
    return c_.mu * dF + (c_.mu - c_.lambda * logJ) * F_invT * dF.transpose() * F_invT +
           c_.lambda * (F_invT.cwiseProduct(dF)).sum() * F_invT;
  }

 private:
  ElasticConstants c_;
};

}  // namespace mpmtb
