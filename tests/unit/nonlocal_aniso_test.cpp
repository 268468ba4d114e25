// The anisotropic grid operator div(A grad q) of methods/core/nonlocal.hpp,
// with A = I + alpha_l a a^T from an aniso-damage body's fibre a (the
// regularisation of anisotropic phase-field fracture, Teichtmeister et al.
// 2017; models/aniso_damage.hpp):
//   * constant A: div(A grad q) = A : H for a quadratic or cubic q (H its
//     Hessian), exact to round-off away from the boundary, because the
//     transfer, the flux-form differences and the interpolation are each
//     exact there (the header's exactness argument), in 2D and 3D;
//   * a field varying only along the fibre, q = f(a . x), has A grad q =
//     (1 + alpha_l) f' a, so the operator is (1 + alpha_l) times the isotropic
//     Laplacian of the same particles; one varying only across it, q = g(b . x)
//     with b . a = 0, is untouched (the isotropic Laplacian);
//   * the diagonal written for the linearly implicit update is that of the
//     flux form, 2 tr(A) / dx^2 where A is constant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "core/nonlocal.hpp"
#include "kernels/all.hpp"
#include "setup.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace nonlocal_aniso_test {

constexpr Real kAlphaL = 4;

// A box of aniso-damage material [0.2, 0.8]^dim, 2 ppc, fibre `fiber`, the
// grain of the length scale alpha_l (alpha_l = 0: the isotropic operator).
std::string block_toml(int dim, int cells, Real alpha_l, const std::string& fiber) {
  return "[scene]\nname = \"block\"\ndim = " + std::to_string(dim) +
         "\ndims = [2, 3]\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = " +
         std::to_string(cells) +
         "\nppc = 2\n[method]\ntransfer = \"mls\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 0.01\ndt = 1e-3\n"
         "[materials.m]\nmodel = \"aniso-damage\"\nE = 1e4\nnu = 0.3\ndensity = 1000.0\n"
         "sigma_crit = 100.0\nl0 = 0.05\nalpha = 10.0\nalpha_l = " +
         std::to_string(alpha_l) +
         "\n[[bodies]]\nshape = \"box\"\nmin = [0.2, 0.2, 0.2]\nmax = [0.8, 0.8, 0.8]\n"
         "material = \"m\"\nfiber = " +
         fiber + "\n";
}

// Applies the operator to q_p = f(x_p) and calls check(x_p, result, diagonal)
// at the particles at least `margin` cells inside the body.
template <int Dim>
void apply_inside(int cells, Real alpha_l, const std::string& fiber,
                  const std::function<Real(const Vec<Dim>&)>& f,
                  const std::function<void(const Vec<Dim>&, Real, Real)>& check) {
  const Scene scene =
      testing::scene_from_toml(block_toml(Dim, cells, alpha_l, fiber), {.dim = Dim});
  State<Dim> s = build_state<Dim>(scene);
  auto& P = s.particles;
  for (std::size_t p = 0; p < P.size(); ++p) P.state_of(p)[0] = f(P.x[p]);
  NonlocalLaplacian<Dim, QuadraticKernel> op;
  op.apply(s);
  const Real margin = QuadraticKernel::support + 2.01, dx = s.grid.geo.dx;
  int checked = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if ((P.x[p].array() - 0.2).minCoeff() < margin * dx ||
        (0.8 - P.x[p].array()).minCoeff() < margin * dx)
      continue;
    check(P.x[p], P.state_of(p)[2], P.state_of(p)[3]);
    ++checked;
  }
  EXPECT_GT(checked, 10) << "too few interior particles";
}

// A = I + alpha_l a a^T.
template <int Dim>
Mat<Dim> structural(const Vec<Dim>& a) {
  return Mat<Dim>::Identity() + kAlphaL * a * a.transpose();
}

TEST(NonlocalAnisotropic, ExactOnQuadraticAndCubicFieldsIn2D) {
  const Vec<2> a(0.6, 0.8);  // a fibre at 53 degrees from x
  const std::string fiber = "[0.6, 0.8, 0.0]";
  const Mat<2> A = structural<2>(a);
  // q = x^T H x + linear: div(A grad q) = 2 A : H.
  Mat<2> H;
  H << 3, 0.5, 0.5, -1.2;
  const auto quadratic = [&](const Vec<2>& x) { return x.dot(H * x) + 0.7 * x[0] - 0.2; };
  const Real dx = 1.0 / 32;
  apply_inside<2>(32, kAlphaL, fiber, quadratic, [&](const Vec<2>&, Real div, Real diag) {
    EXPECT_NEAR(div, 2 * (A.cwiseProduct(H)).sum(), 1e-8);
    EXPECT_NEAR(diag, 2 * A.trace() / (dx * dx), 1e-8 * A.trace() / (dx * dx));
  });
  // q = x^2 y + y^3: H = [[2y, 2x], [2x, 6y]].
  const auto cubic = [](const Vec<2>& x) { return x[0] * x[0] * x[1] + x[1] * x[1] * x[1]; };
  apply_inside<2>(32, kAlphaL, fiber, cubic, [&](const Vec<2>& x, Real div, Real) {
    Mat<2> Hx;
    Hx << 2 * x[1], 2 * x[0], 2 * x[0], 6 * x[1];
    EXPECT_NEAR(div, (A.cwiseProduct(Hx)).sum(), 1e-8);
  });
}

TEST(NonlocalAnisotropic, ExactOnAQuadraticFieldIn3D) {
  const Vec<3> a = Vec<3>(0.6, 0.0, 0.8);
  const Mat<3> A = structural<3>(a);
  Mat<3> H;
  H << 1, 0.3, -0.4, 0.3, 2, 0.6, -0.4, 0.6, -1;
  const auto quadratic = [&](const Vec<3>& x) { return x.dot(H * x) - x[2]; };
  apply_inside<3>(20, kAlphaL, "[0.6, 0.0, 0.8]", quadratic, [&](const Vec<3>&, Real div, Real) {
    EXPECT_NEAR(div, 2 * (A.cwiseProduct(H)).sum(), 1e-8);
  });
}

// The operator on f(s) for the rotated tensor against the isotropic one on the
// same particles: (1 + alpha_l) times it along the fibre, equal across it.
TEST(NonlocalAnisotropic, RotatedTensorScalesTheLaplacianAlongTheFibreOnly) {
  const Vec<2> a = Vec<2>(0.8, 0.6), b(-0.6, 0.8);
  const std::string fiber = "[0.8, 0.6, 0.0]";
  for (const auto& [dir, factor] : {std::pair{a, 1 + kAlphaL}, std::pair{b, Real(1)}}) {
    const auto f = [dir = dir](const Vec<2>& x) {
      const Real s = dir.dot(x);
      return 2 * s * s - s * s * s + s;
    };
    std::vector<Real> iso, aniso;
    apply_inside<2>(32, 0, fiber, f, [&](const Vec<2>&, Real lap, Real) { iso.push_back(lap); });
    apply_inside<2>(32, kAlphaL, fiber, f,
                    [&](const Vec<2>&, Real div, Real) { aniso.push_back(div); });
    ASSERT_EQ(iso.size(), aniso.size());
    for (std::size_t k = 0; k < iso.size(); ++k) {
      EXPECT_NEAR(aniso[k], factor * iso[k], 1e-8 * (1 + std::abs(factor * iso[k])));
    }
  }
}

}  // namespace nonlocal_aniso_test
}  // namespace mpmtb
