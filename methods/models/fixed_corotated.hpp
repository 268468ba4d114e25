// Fixed-corotated elasticity (Stomakhin, Howes, Schroeder & Teran 2012,
// "Energetically consistent invertible elasticity", SCA, sec. 4, eq. 3; as
// used in Stomakhin et al. 2013, "A material point method for snow
// simulation", eq. 2-3, and Jiang et al. 2016, eq. 49):
//   psi = mu |F - R|^2 + lambda/2 (J - 1)^2 = mu sum_i (sigma_i - 1)^2 + lambda/2 (J - 1)^2
//   P   = 2 mu (F - R) + lambda (J - 1) J F^-T
//   tau = P F^T = 2 mu (F - R) F^T + lambda (J - 1) J I
// with F = R S the polar decomposition (R a rotation, polar.hpp). J F^-T is
// written as the cofactor matrix, so the model is defined for every F,
// including J = 0 and inverted elements (J < 0): it is invertible.
#pragma once

#include "models/lame.hpp"
#include "models/model.hpp"
#include "models/polar.hpp"

namespace mpmtb {

// The fixed-corotated formulas for given Lame parameters, shared with the snow model.
template <int Dim>
Real fixed_corotated_psi(const Mat<Dim>& F, Real mu, Real lambda) {
  const Real J = F.determinant();
  return mu * (F - polar_rotation<Dim>(F)).squaredNorm() + Real(0.5) * lambda * (J - 1) * (J - 1);
}

template <int Dim>
Mat<Dim> fixed_corotated_P(const Mat<Dim>& F, Real mu, Real lambda) {
  const Real J = F.determinant();
  return 2 * mu * (F - polar_rotation<Dim>(F)) + lambda * (J - 1) * cofactor<Dim>(F);
}

template <int Dim>
Mat<Dim> fixed_corotated_tau(const Mat<Dim>& F, Real mu, Real lambda) {
  const Real J = F.determinant();
  return 2 * mu * (F - polar_rotation<Dim>(F)) * F.transpose() +
         lambda * (J - 1) * J * Mat<Dim>::Identity();
}

template <int Dim>
class FixedCorotated final : public ModelBase<Dim, FixedCorotated<Dim>> {
 public:
  static constexpr std::string_view model_name = "fixed-corotated";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@inproceedings{stomakhin2012,
  author = {Stomakhin, Alexey and Howes, Russell and Schroeder, Craig and Teran, Joseph M.},
  title = {Energetically consistent invertible elasticity},
  booktitle = {Proceedings of the ACM SIGGRAPH/Eurographics Symposium on Computer Animation},
  pages = {25--32},
  year = {2012}
})bib";

  explicit FixedCorotated(Parameters& params) : c_(ElasticConstants::read(params)) {}

  std::string_view name() const override { return model_name; }
  Real density() const override { return c_.density; }
  Real wave_speed() const override { return c_.wave_speed(); }

  Real psi(const Mat<Dim>& F, const Real*) const {
    return fixed_corotated_psi<Dim>(F, c_.mu, c_.lambda);
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real*) const {
    return fixed_corotated_P<Dim>(F, c_.mu, c_.lambda);
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real*) const {
    return fixed_corotated_tau<Dim>(F, c_.mu, c_.lambda);
  }

 private:
  ElasticConstants c_;
};

}  // namespace mpmtb
