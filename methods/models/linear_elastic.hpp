// Small-strain isotropic linear elasticity (Hooke's law), the material of the
// colliding disks of Sulsky, Chen & Schreyer 1994 ("A particle method for
// history-dependent materials", CMAME 118):
//   eps = (F + F^T)/2 - I
//   psi = mu eps : eps + lambda/2 tr(eps)^2
//   P   = 2 mu eps + lambda tr(eps) I   (= dpsi/dF, eps symmetric)
//   tau = P F^T
// For comparison with small-deformation analytic solutions only. NOT frame
// indifferent: a rigid rotation F = R gives eps = (R + R^T)/2 - I != 0, so a
// rotating body builds up spurious stress (second order in the angle). The
// model conformance test names it as the documented exception.
#pragma once

#include "core/papers.hpp"
#include "models/lame.hpp"
#include "models/model.hpp"

namespace mpmtb {

template <int Dim>
class LinearElastic final : public ModelBase<Dim, LinearElastic<Dim>> {
 public:
  static constexpr std::string_view model_name = "linear-elastic";
  static constexpr std::string_view bibtex = papers::sulsky1994;  // mpmtb list --bibtex

  explicit LinearElastic(Parameters& params) : c_(ElasticConstants::read(params)) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }

  static Mat<Dim> strain(const Mat<Dim>& F) {
    return Real(0.5) * (F + F.transpose()) - Mat<Dim>::Identity();
  }
  Real psi(const Mat<Dim>& F, const Real*) const {
    const Mat<Dim> eps = strain(F);
    const Real tr = eps.trace();
    return c_.mu * eps.squaredNorm() + Real(0.5) * c_.lambda * tr * tr;
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real*) const {
    const Mat<Dim> eps = strain(F);
    return 2 * c_.mu * eps + c_.lambda * eps.trace() * Mat<Dim>::Identity();
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const { return P(F, q) * F.transpose(); }
  // dP = 2 mu sym(dF) + lambda tr(dF) I: constant in F (psi is quadratic).
  Mat<Dim> dP(const Mat<Dim>&, const Mat<Dim>& dF, const Real*) const {
    return c_.mu * (dF + dF.transpose()) + c_.lambda * dF.trace() * Mat<Dim>::Identity();
  }

 private:
  ElasticConstants c_;
};

}  // namespace mpmtb
