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

// psi from the signed singular values sigma of F (polar.hpp): mu |F - R|^2 =
// mu sum_i (sigma_i - 1)^2 and J = prod_i sigma_i (the header's second form),
// for a caller that has the SVD already (the snow return map).
template <int Dim>
Real fixed_corotated_psi_of_sigma(const Vec<Dim>& sigma, Real mu, Real lambda) {
  const Real J = sigma.prod();
  return mu * (sigma.array() - 1).square().sum() + Real(0.5) * lambda * (J - 1) * (J - 1);
}

template <int Dim>
Mat<Dim> fixed_corotated_P(const Mat<Dim>& F, Real mu, Real lambda) {
  const Real J = F.determinant();
  return 2 * mu * (F - polar_rotation<Dim>(F)) + lambda * (J - 1) * cofactor<Dim>(F);
}

template <int Dim>
MPMTB_INLINE inline Mat<Dim> fixed_corotated_tau(const Mat<Dim>& F, Real mu, Real lambda) {
  const Real J = F.determinant();
  return 2 * mu * (F - polar_rotation<Dim>(F)) * F.transpose() +
         lambda * (J - 1) * J * Mat<Dim>::Identity();
}

// dP = 2 mu (dF - dR) + lambda (cof(F) : dF) cof(F) + lambda (J - 1) d cof(F)
// (Sifakis & Barbic 2012, "FEM simulation of 3D deformable solids", SIGGRAPH
// course notes, sec. 5; Stomakhin et al. 2012, sec. 4). With F = R S, the
// spin W = R^T dR is antisymmetric and solves W S + S W = R^T dF - dF^T R:
// in 2D W = w [0 -1; 1 0] with w (s11 + s22) = the (1,0) entry of the right
// side; in 3D W = [w]x with (tr(S) I - S) w = the axial vector of the right
// side. d cof(F) is cof(dF) in 2D and the product rule on the cross products
// of columns (polar.hpp, cofactor) in 3D; 0 in 1D, where R = sign F is locally
// constant. Singular where two singular values sum to zero (an element
// inverted through a degenerate state); the solve is then skipped (dR = 0).
template <int Dim>
Mat<Dim> fixed_corotated_dP(const Mat<Dim>& F, const Mat<Dim>& dF, Real mu, Real lambda) {
  const Real J = F.determinant();
  const Mat<Dim> cof = cofactor<Dim>(F);
  Mat<Dim> dR = Mat<Dim>::Zero(), dcof = Mat<Dim>::Zero();
  if constexpr (Dim >= 2) {
    const Mat<Dim> R = polar_rotation<Dim>(F);
    const Mat<Dim> S = R.transpose() * F;
    const Mat<Dim> A = R.transpose() * dF - dF.transpose() * R;
    Mat<Dim> W = Mat<Dim>::Zero();
    if constexpr (Dim == 2) {
      const Real t = S.trace();
      if (t != 0) {
        const Real w = A(1, 0) / t;
        W << 0, -w, w, 0;
      }
      dcof = cofactor<2>(dF);
    } else {
      const Vec<3> a(A(2, 1), A(0, 2), A(1, 0));
      const Mat<3> B = S.trace() * Mat<3>::Identity() - Real(0.5) * (S + S.transpose());
      const Real detB = B.determinant();
      if (detB != 0) {
        const Vec<3> w = B.inverse() * a;
        W << 0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0;
      }
      dcof.col(0) = dF.col(1).cross(F.col(2)) + F.col(1).cross(dF.col(2));
      dcof.col(1) = dF.col(2).cross(F.col(0)) + F.col(2).cross(dF.col(0));
      dcof.col(2) = dF.col(0).cross(F.col(1)) + F.col(0).cross(dF.col(1));
    }
    dR = R * W;
  }
  return 2 * mu * (dF - dR) + lambda * cof.cwiseProduct(dF).sum() * cof + lambda * (J - 1) * dcof;
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
  Mat<Dim> dP(const Mat<Dim>& F, const Mat<Dim>& dF, const Real*) const {
    return fixed_corotated_dP<Dim>(F, dF, c_.mu, c_.lambda);
  }

 private:
  ElasticConstants c_;
};

}  // namespace mpmtb
