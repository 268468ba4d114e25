// The deformed particle domains (issue 21): cpGIMP (kernels/cpgimp.hpp) and CPDI1
// (kernels/cpdi.hpp) at random deformation gradients F. Conformance: partition of
// unity, zero first moment, linear reproduction, sum grad w = 0 and
// sum x_i grad w^T = I (the gradient reproduces linear fields), gradients against
// finite differences where the definition makes them derivatives, and the F = I
// limits against uGIMP.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "core/grid.hpp"
#include "core/stencil.hpp"
#include "kernels/all.hpp"

namespace mpmtb {
namespace particle_domain_test {

constexpr Real kDx = 0.37;
constexpr int kCells = 9;

template <int Dim>
GridGeometry<Dim> TestGrid(Real l = 0.25) {
  Vec<Dim> lo;
  for (int a = 0; a < Dim; ++a) lo[a] = -1.3 + 0.9 * a;
  std::array<int, Dim> cells;
  cells.fill(kCells);
  GridGeometry<Dim> g(lo, kDx, cells);
  g.l = l;
  return g;
}

// Positions at least 2 cells inside the grid box.
template <int Dim>
Vec<Dim> RandomPosition(const GridGeometry<Dim>& g, std::mt19937& gen) {
  std::uniform_real_distribution<Real> u(2 * g.dx, (kCells - 2) * g.dx);
  Vec<Dim> x;
  for (int a = 0; a < Dim; ++a) x[a] = g.lo[a] + u(gen);
  return x;
}

// F with singular values in [0.4, 2.5] (stretch, compression and shear), det > 0.
template <int Dim>
Mat<Dim> RandomF(std::mt19937& gen) {
  std::uniform_real_distribution<Real> u(-1, 1), s(0.4, 2.5);
  auto rotation = [&] {
    Mat<Dim> A;
    for (int i = 0; i < Dim; ++i)
      for (int j = 0; j < Dim; ++j) A(i, j) = u(gen);
    Eigen::HouseholderQR<Mat<Dim>> qr(A);
    Mat<Dim> Q = qr.householderQ();
    if (Q.determinant() < 0) Q.col(0) *= -1;
    return Q;
  };
  Vec<Dim> sigma;
  for (int a = 0; a < Dim; ++a) sigma[a] = s(gen);
  return rotation() * sigma.asDiagonal() * rotation().transpose();
}

template <int Dim>
struct Node {
  Real w;
  Vec<Dim> grad, d;
};

template <int Dim, class K>
std::map<long, Node<Dim>> Nodes(const Vec<Dim>& x, const Mat<Dim>& F, const GridGeometry<Dim>& g) {
  std::map<long, Node<Dim>> out;
  Stencil<Dim, K>(x, F, g).for_each_node(
      g, [&](long n, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        out[n] = {w, grad, d};
      });
  return out;
}

// The identities every interpolation of a partition of unity with linear
// reproduction satisfies, whatever the domain.
template <int Dim, class K>
void ExpectLinearlyExact(const Vec<Dim>& x, const Mat<Dim>& F, const GridGeometry<Dim>& g) {
  Real sum = 0, min_w = 1;
  Vec<Dim> first = Vec<Dim>::Zero(), grad = Vec<Dim>::Zero();
  Mat<Dim> x_grad = Mat<Dim>::Zero();
  for (const auto& [n, node] : Nodes<Dim, K>(x, F, g)) {
    const Vec<Dim> xi = g.position(n);
    EXPECT_LT((xi - x - node.d).norm(), 1e-13) << "offset";
    sum += node.w;
    min_w = std::min(min_w, node.w);
    first += node.w * (xi - x);
    grad += node.grad;
    x_grad += node.grad * xi.transpose();
  }
  EXPECT_NEAR(sum, 1, 1e-13) << "partition of unity, F =\n" << F;
  EXPECT_GE(min_w, 0);
  EXPECT_LT(first.norm(), 1e-13 * g.dx) << "first moment, F =\n" << F;
  EXPECT_LT(grad.norm(), 1e-11 / g.dx) << "sum grad w, F =\n" << F;
  EXPECT_LT((x_grad - Mat<Dim>::Identity()).norm(), 1e-11 * (1 + x.norm() / g.dx))
      << "sum x_i grad w^T, F =\n"
      << F;
}

// ---- cpGIMP ------------------------------------------------------------------

TEST(CpGimp, EqualsUgimpBitForBitAtIdentity) {
  std::mt19937 gen(21);
  const auto g = TestGrid<3>();
  for (int s = 0; s < 300; ++s) {
    const Vec<3> x = RandomPosition(g, gen);
    const auto cp = Nodes<3, CpGimpKernel>(x, Mat<3>::Identity(), g);
    const auto u = Nodes<3, GimpKernel>(x, Mat<3>::Identity(), g);
    for (const auto& [n, node] : cp) {
      const auto it = u.find(n);
      if (it == u.end()) {
        EXPECT_EQ(node.w, 0) << "a node beyond uGIMP's support carries weight";
        EXPECT_EQ(node.grad.norm(), 0);
        continue;
      }
      EXPECT_EQ(node.w, it->second.w);
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(node.grad[a], it->second.grad[a]);
        EXPECT_EQ(node.d[a], it->second.d[a]);
      }
    }
    EXPECT_EQ(cp.size(), 64u);
  }
}

template <int Dim>
void CheckCpGimpRandomF() {
  std::mt19937 gen(100 + Dim);
  const auto g = TestGrid<Dim>();
  for (int s = 0; s < 200; ++s) {
    const Vec<Dim> x = RandomPosition(g, gen);
    const Mat<Dim> F = RandomF<Dim>(gen);
    ExpectLinearlyExact<Dim, CpGimpKernel>(x, F, g);
    // cpGIMP is uGIMP with the half-widths l_a = l0 F_aa: its gradient is d w / d x_p
    // at fixed F (away from the breakpoints, where the difference is not a derivative).
    const Real h = 1e-7 * g.dx;
    const auto base = Nodes<Dim, CpGimpKernel>(x, F, g);
    for (int a = 0; a < Dim; ++a) {
      auto plus = Nodes<Dim, CpGimpKernel>(x + h * Vec<Dim>::Unit(a), F, g);
      auto minus = Nodes<Dim, CpGimpKernel>(x - h * Vec<Dim>::Unit(a), F, g);
      for (const auto& [n, node] : base) {
        const Real fd = (plus[n].w - minus[n].w) / (2 * h);
        EXPECT_NEAR(node.grad[a], fd, 1e-5 / g.dx) << "axis " << a << ", F =\n" << F;
      }
    }
  }
}

TEST(CpGimp, LinearlyExactAndGradientIsDerivativeAtRandomF) {
  CheckCpGimpRandomF<1>();
  CheckCpGimpRandomF<2>();
  CheckCpGimpRandomF<3>();
}

TEST(CpGimp, HalfWidthFollowsFaaAndIsClamped) {
  using K = CpGimpKernel;
  EXPECT_EQ(K::half_width(0.25, 1), 0.25);
  EXPECT_EQ(K::half_width(0.25, 3), 0.75);
  EXPECT_EQ(K::half_width(0.25, 5), K::kMaxHalfWidth);  // the 4-node support's limit
  EXPECT_EQ(K::half_width(0.25, -1), K::kMinHalfWidth);
  EXPECT_TRUE(K::clamped(0.25, 5));
  EXPECT_FALSE(K::clamped(0.25, 3.9));
  // Beyond the clamp the weights stay a partition of unity on the 4 nodes.
  const auto g = TestGrid<2>();
  std::mt19937 gen(7);
  for (int s = 0; s < 50; ++s) {
    Mat<2> F;
    F << 6, 0.3, -0.2, 0.01;
    ExpectLinearlyExact<2, K>(RandomPosition(g, gen), F, g);
  }
}

// ---- CPDI1 -------------------------------------------------------------------

template <int Dim>
void CheckCpdiRandomF() {
  std::mt19937 gen(200 + Dim);
  const auto g = TestGrid<Dim>();
  for (int s = 0; s < 300; ++s)
    ExpectLinearlyExact<Dim, CpdiKernel>(RandomPosition(g, gen), RandomF<Dim>(gen), g);
}

TEST(Cpdi, LinearlyExactAtRandomF) {
  CheckCpdiRandomF<1>();
  CheckCpdiRandomF<2>();
  CheckCpdiRandomF<3>();
}

// The CPDI gradient is (1/V_p) oint N_i^h n ds with N_i^h linear along each edge
// between its corner values (Sadeghirad et al. 2011): the trapezoid rule
// per edge of the parallelogram, computed here from the hats at the corners.
TEST(Cpdi, GradientIsTheBoundaryIntegralOfTheCornerInterpolant) {
  std::mt19937 gen(31);
  const auto g = TestGrid<2>();
  const auto hat = [&](long n, const Vec<2>& x) {
    const Vec<2> r = (x - g.position(n)) / g.dx;
    return std::max(Real(0), 1 - std::abs(r[0])) * std::max(Real(0), 1 - std::abs(r[1]));
  };
  for (int s = 0; s < 300; ++s) {
    const Vec<2> x = RandomPosition(g, gen);
    const Mat<2> F = RandomF<2>(gen);
    const Mat<2> J = g.l * g.dx * F;
    // Counter-clockwise corners (det J > 0).
    const Vec<2> c[4] = {x - J.col(0) - J.col(1), x + J.col(0) - J.col(1), x + J.col(0) + J.col(1),
                         x - J.col(0) + J.col(1)};
    const Real area = 4 * J.determinant();
    for (const auto& [n, node] : Nodes<2, CpdiKernel>(x, F, g)) {
      Vec<2> integral = Vec<2>::Zero();
      Real w = 0;
      for (int e = 0; e < 4; ++e) {
        const Vec<2>& a = c[e];
        const Vec<2>& b = c[(e + 1) % 4];
        const Vec<2> normal_length(b[1] - a[1], a[0] - b[0]);
        integral += Real(0.5) * (hat(n, a) + hat(n, b)) * normal_length;
        w += hat(n, a) / 4;
      }
      EXPECT_NEAR(node.w, w, 1e-14);
      EXPECT_LT((node.grad - integral / area).norm(), 1e-12 / g.dx) << "F =\n" << F;
    }
  }
}

// With F diagonal and no grid line inside the domain, the hat is multilinear over
// it, its corner interpolant is exact, and the CPDI weight is the GIMP average:
// the gradient is then d w / d x_p.
TEST(Cpdi, GradientIsDerivativeWhereTheHatIsMultilinearOverTheDomain) {
  std::mt19937 gen(41);
  const auto g = TestGrid<3>();
  std::uniform_real_distribution<Real> stretch(0.5, 1.8);
  int checked = 0;
  for (int s = 0; s < 3000 && checked < 100; ++s) {
    const Vec<3> x = RandomPosition(g, gen);
    Mat<3> F = Mat<3>::Zero();
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      F(a, a) = stretch(gen);
      const Real xi = (x[a] - g.lo[a]) / g.dx, l = g.l * F(a, a);
      inside = inside && std::floor(xi - l - 1e-6) == std::floor(xi + l + 1e-6);
    }
    if (!inside) continue;
    ++checked;
    const Real h = 1e-7 * g.dx;
    const auto base = Nodes<3, CpdiKernel>(x, F, g);
    for (int a = 0; a < 3; ++a) {
      auto plus = Nodes<3, CpdiKernel>(x + h * Vec<3>::Unit(a), F, g);
      auto minus = Nodes<3, CpdiKernel>(x - h * Vec<3>::Unit(a), F, g);
      for (const auto& [n, node] : base) {
        EXPECT_NEAR(node.grad[a], (plus[n].w - minus[n].w) / (2 * h), 1e-6 / g.dx);
      }
    }
  }
  EXPECT_GE(checked, 50);
}

// F = I: where the particle domains tile the cells (the lattice of 2 particles per
// cell: xi = k + 1/4, k + 3/4, domains [k, k + 1/2] and [k + 1/2, k + 1]) no hat kink
// lies inside a domain, and CPDI1's corner average is uGIMP's domain average. A
// domain with a node inside differs: the trapezoid rule misses the hat's peak
// (at a node, uGIMP gives 1 - l/2 = 0.875 and CPDI1 the corners' 1 - l = 0.75).
TEST(Cpdi, EqualsUgimpAtIdentityWhereTheDomainsTileTheCells) {
  const auto g = TestGrid<2>();
  for (int i = 2; i < kCells - 2; ++i) {
    for (int j = 2; j < kCells - 2; ++j) {
      for (const Real fi : {0.25, 0.75}) {
        for (const Real fj : {0.25, 0.75}) {
          const Vec<2> x = g.lo + g.dx * Vec<2>(i + fi, j + fj);
          const auto c = Nodes<2, CpdiKernel>(x, Mat<2>::Identity(), g);
          const auto u = Nodes<2, GimpKernel>(x, Mat<2>::Identity(), g);
          for (const auto& [n, node] : c) {
            const auto it = u.find(n);
            const Real wu = it == u.end() ? 0 : it->second.w;
            const Vec<2> gu = it == u.end() ? Vec<2>::Zero() : it->second.grad;
            EXPECT_NEAR(node.w, wu, 1e-15);
            EXPECT_LT((node.grad - gu).norm(), 1e-13 / g.dx);
          }
        }
      }
    }
  }
  EXPECT_NEAR(CpdiKernel::N(0), 0.75, 1e-15);
  EXPECT_NEAR(GimpKernel::N(0), 0.875, 1e-15);
}

// D_p = J J^T + the corners' hat variances (kernels/cpdi.hpp): full under shear.
TEST(Cpdi, InertiaIsFullUnderShear) {
  std::mt19937 gen(51);
  const auto g = TestGrid<2>();
  for (int s = 0; s < 100; ++s) {
    const Vec<2> x = RandomPosition(g, gen);
    const Mat<2> F = RandomF<2>(gen);
    const Mat<2> J = g.l * g.dx * F;
    Mat<2> expected = J * J.transpose();
    for (int c = 0; c < 4; ++c) {
      const Vec<2> corner = x + J * Vec<2>(c & 2 ? 1 : -1, c & 1 ? 1 : -1);
      for (int a = 0; a < 2; ++a) {
        const Real xi = (corner[a] - g.lo[a]) / g.dx, f = xi - std::floor(xi);
        expected(a, a) += f * (1 - f) * g.dx * g.dx / 4;
      }
    }
    const Mat<2> D = Stencil<2, CpdiKernel>(x, F, g).inertia();
    EXPECT_LT((D - expected).norm(), 1e-13 * g.dx * g.dx) << "F =\n" << F;
  }
  Mat<2> shear;
  shear << 1, 0.8, 0, 1;
  const Mat<2> D = Stencil<2, CpdiKernel>(g.lo + Vec<2>(4.3, 4.6) * g.dx, shear, g).inertia();
  EXPECT_GT(std::abs(D(0, 1)), 1e-2 * g.dx * g.dx);
}

// A domain longer than the 4-node box holds is scaled down to it: still exact.
TEST(Cpdi, OversizedDomainIsScaledIntoTheBox) {
  std::mt19937 gen(61);
  const auto g = TestGrid<3>();
  Mat<3> F;
  F << 7, 2, 0, -1, 5, 1, 0.5, 0, 6;
  for (int s = 0; s < 100; ++s) ExpectLinearlyExact<3, CpdiKernel>(RandomPosition(g, gen), F, g);
}

}  // namespace particle_domain_test
}  // namespace mpmtb
