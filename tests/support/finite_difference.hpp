// Central finite differences of a model's energy density: P = dpsi/dF.
#pragma once

#include "models/model.hpp"

namespace mpmtb::testing {

template <int Dim>
Mat<Dim> FiniteDifferenceP(const ConstitutiveModel<Dim>& m, const Mat<Dim>& F, const Real* q,
                           Real h = 1e-6) {
  Mat<Dim> P_fd;
  for (int i = 0; i < Dim; ++i) {
    for (int j = 0; j < Dim; ++j) {
      Mat<Dim> Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      P_fd(i, j) = (m.energy_density(Fp, q) - m.energy_density(Fm, q)) / (2 * h);
    }
  }
  return P_fd;
}

}  // namespace mpmtb::testing
