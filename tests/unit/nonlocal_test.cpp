// The grid Laplacian of a particle field (methods/core/nonlocal.hpp) and the
// damage length scale l0 that uses it (methods/models/damage.hpp; AnisoMPM,
// Wolper et al. 2020; REFERENCE.md "Damage").
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/nonlocal.hpp"
#include "core/registry.hpp"
#include "kernels/all.hpp"
#include "models/damage.hpp"
#include "setup.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace nonlocal_test {

// A box of damage material [0.2, 0.8]^dim on a grid of `cells`, 2 ppc.
std::string block_toml(int dim, int cells, const std::string& kernel) {
  return "[scene]\nname = \"block\"\ndim = " + std::to_string(dim) +
         "\ndims = [1, 2, 3]\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = " +
         std::to_string(cells) + "\nppc = 2\n[method]\ntransfer = \"mls\"\nkernel = \"" + kernel +
         "\"\n[time]\nt_end = 0.01\ndt = 1e-3\n"
         "[materials.m]\nmodel = \"damage\"\nE = 1e4\nnu = 0.3\ndensity = 1000.0\n"
         "sigma_crit = 100.0\nl0 = 0.05\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.2, 0.2, 0.2]\nmax = [0.8, 0.8, 0.8]\n"
         "material = \"m\"\n";
}

// A field with its Laplacian.
template <int Dim>
struct Field {
  Real (*value)(const Vec<Dim>&);
  Real (*laplacian)(const Vec<Dim>&);
};

// Quadratic and cubic fields in 2D and 3D (arbitrary coefficients).
Real cubic2(const Vec<2>& x) {
  return 0.3 - 0.7 * x[0] + 1.1 * x[1] + 2 * x[0] * x[0] - 1.5 * x[0] * x[1] + 0.8 * x[1] * x[1] +
         1.3 * x[0] * x[0] * x[0] - 0.9 * x[0] * x[0] * x[1] + 0.6 * x[1] * x[1] * x[1];
}
Real lap_cubic2(const Vec<2>& x) {
  return 4 + 1.6 + 7.8 * x[0] - 1.8 * x[1] + 3.6 * x[1];
}
Real quadratic2(const Vec<2>& x) {
  return 0.5 + x[0] - 2 * x[1] + 3 * x[0] * x[0] + x[0] * x[1];
}
Real lap_quadratic2(const Vec<2>&) {
  return 6;
}
Real quartic2(const Vec<2>& x) {
  return x[0] * x[0] * x[0] * x[0];
}
Real lap_quartic2(const Vec<2>& x) {
  return 12 * x[0] * x[0];
}
Real cubic3(const Vec<3>& x) {
  return 0.2 * x[0] - x[1] * x[2] + 0.7 * x[2] * x[2] + x[0] * x[1] * x[2] -
         0.4 * x[2] * x[2] * x[2];
}
Real lap_cubic3(const Vec<3>& x) {
  return 1.4 - 2.4 * x[2];
}

// Sets q_p = f(x_p) in the damage slot, applies the operator, and returns the
// largest |lap_p - lap f(x_p)| over the particles at least `margin` cells
// inside the body (where every stencil sees a full, symmetric particle lattice).
template <int Dim, class Kernel>
Real max_interior_error(int cells, const Field<Dim>& f, Real margin) {
  const Scene scene =
      testing::scene_from_toml(block_toml(Dim, cells, std::string(Kernel::name)), {.dim = Dim});
  State<Dim> s = build_state<Dim>(scene);
  auto& P = s.particles;
  for (std::size_t p = 0; p < P.size(); ++p) P.state_of(p)[0] = f.value(P.x[p]);
  NonlocalLaplacian<Dim, Kernel> op;
  op.apply(s);
  const Real dx = s.grid.geo.dx;
  Real err = 0;
  int checked = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    EXPECT_EQ(P.state_of(p)[3], 2 * Dim / (dx * dx)) << "the operator's diagonal";
    if (((P.x[p].array() - 0.2).minCoeff() < margin * dx) ||
        ((0.8 - P.x[p].array()).minCoeff() < margin * dx))
      continue;
    err = std::max(err, std::abs(P.state_of(p)[2] - f.laplacian(P.x[p])));
    ++checked;
  }
  EXPECT_GT(checked, 10) << "too few interior particles";
  return err;
}

// Transfer support + one node + interpolation support, in cells.
template <class Kernel>
constexpr Real kMargin = Kernel::support + 1.01;

template <class K>
class NonlocalLaplacianTest : public ::testing::Test {};
using Kernels = ::testing::Types<LinearKernel, QuadraticKernel, CubicKernel>;
TYPED_TEST_SUITE(NonlocalLaplacianTest, Kernels);

// Exact (to round-off) on quadratic and cubic fields: the mass-weighted
// transfer adds only a polynomial of degree <= 1 on a symmetric lattice, the
// 5-point Laplacian is exact on cubics, and the B-splines reproduce linear
// fields (core/nonlocal.hpp).
TYPED_TEST(NonlocalLaplacianTest, ExactOnQuadraticAndCubicFields) {
  const Real margin = kMargin<TypeParam>;
  const Real quadratic = max_interior_error<2, TypeParam>(32, {quadratic2, lap_quadratic2}, margin);
  const Real cubic = max_interior_error<2, TypeParam>(32, {cubic2, lap_cubic2}, margin);
  EXPECT_LT(quadratic, 1e-8);
  EXPECT_LT(cubic, 1e-8);
}

TEST(NonlocalLaplacian, ExactOnACubicFieldIn3D) {
  const Real err =
      max_interior_error<3, QuadraticKernel>(20, {cubic3, lap_cubic3}, kMargin<QuadraticKernel>);
  EXPECT_LT(err, 1e-8);
}

// Degree 4 is not exact: every stage errs by O(dx^2) (the kernel's second
// moment and the finite-difference truncation), so halving dx quarters the error.
TEST(NonlocalLaplacian, SecondOrderOnAQuarticField) {
  const Real margin = kMargin<QuadraticKernel>;
  const Real coarse = max_interior_error<2, QuadraticKernel>(32, {quartic2, lap_quartic2}, margin);
  const Real fine = max_interior_error<2, QuadraticKernel>(64, {quartic2, lap_quartic2}, margin);
  EXPECT_GT(coarse, 1e-4) << "a quartic is beyond the operator's exactness";
  const Real order = std::log2(coarse / fine);
  EXPECT_GT(order, 1.8);
  EXPECT_LT(order, 2.2);
}

// The operator keeps its grid between calls and clears only the box of nodes
// its last particles reached: after the body moves by several cells, a second
// call must equal a fresh operator's, bit for bit (no value left behind).
TEST(NonlocalLaplacian, ReusedAfterTheBodyMovesEqualsAFreshOperator) {
  const Scene scene = testing::scene_from_toml(block_toml(2, 32, "quadratic"), {.dim = 2});
  State<2> reused_state = build_state<2>(scene), fresh_state = build_state<2>(scene);
  // The cubic field at the particles, moved by `shift` first.
  const auto place = [](State<2>& s, const Vec<2>& shift) {
    for (std::size_t p = 0; p < s.particles.size(); ++p) {
      s.particles.x[p] += shift;
      s.particles.state_of(p)[0] = cubic2(s.particles.x[p]);
    }
  };
  place(reused_state, Vec<2>::Zero());
  NonlocalLaplacian<2, QuadraticKernel> reused, fresh;
  reused.apply(reused_state);
  const Real dx = reused_state.grid.geo.dx;
  const Vec<2> shift(3.3 * dx, -2.6 * dx);
  place(reused_state, shift);
  place(fresh_state, shift);
  reused.apply(reused_state);
  fresh.apply(fresh_state);
  const auto& P = reused_state.particles;
  for (std::size_t p = 0; p < P.size(); ++p) {
    ASSERT_EQ(P.state_of(p)[2], fresh_state.particles.state_of(p)[2]) << "particle " << p;
  }
}

// The local operator (the default: the isotropic path transfers, forms and
// interpolates only near the particles with q_p != 0, core/nonlocal.hpp) gives
// every particle the bits of the whole operator (localise(false)): for a field
// zero everywhere, and for one nonzero only in a ball, inside the body and
// across its corner (where the mirror condition acts).
template <int Dim, class Kernel>
void expect_local_equals_whole(int cells, const Vec<Dim>& centre, Real radius) {
  const Scene scene =
      testing::scene_from_toml(block_toml(Dim, cells, std::string(Kernel::name)), {.dim = Dim});
  State<Dim> local_state = build_state<Dim>(scene), whole_state = build_state<Dim>(scene);
  int nonzero = 0;
  for (State<Dim>* s : {&local_state, &whole_state}) {
    auto& P = s->particles;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Real r = (P.x[p] - centre).norm();
      P.state_of(p)[0] = r < radius ? 1 + std::cos(P.x[p].sum()) : 0;
      P.state_of(p)[2] = P.state_of(p)[3] = -1;  // overwritten by the operator
    }
  }
  NonlocalLaplacian<Dim, Kernel> local, whole;
  whole.localise(false);
  local.apply(local_state);
  whole.apply(whole_state);
  const auto& P = local_state.particles;
  for (std::size_t p = 0; p < P.size(); ++p) {
    for (const int slot : {2, 3}) {
      const Real a = P.state_of(p)[slot], b = whole_state.particles.state_of(p)[slot];
      ASSERT_EQ(std::bit_cast<std::uint64_t>(double(a)), std::bit_cast<std::uint64_t>(double(b)))
          << "particle " << p << " slot " << slot << ": " << a << " vs " << b;
    }
    nonzero += P.state_of(p)[2] != 0;
  }
  if (radius > 0) {
    EXPECT_GT(nonzero, 0) << "the field's Laplacian is nonzero near the ball";
    EXPECT_LT(nonzero, static_cast<int>(P.size()) * 3 / 4) << "and zero far from it";
  } else {
    EXPECT_EQ(nonzero, 0);
  }
}

// A field zero everywhere: every particle of a requesting material takes lap_p
// = +0 and the operator's diagonal, and no other particle's state is written.
// With one material (every request the same: source_nodes' sweep over the state
// records alone) and with a second, elastic one beside it (the sweep by material).
TEST(NonlocalLaplacian, ZeroFieldWritesTheRequestingParticlesOnly) {
  const std::string elastic_body =
      "[materials.e]\nmodel = \"neo-hookean\"\nE = 1e4\nnu = 0.3\ndensity = 1000.0\n"
      "[[bodies]]\nshape = \"box\"\nmin = [0.05, 0.05, 0.05]\nmax = [0.15, 0.95, 0.95]\n"
      "material = \"e\"\n";
  for (const bool two_materials : {false, true}) {
    const Scene scene = testing::scene_from_toml(
        block_toml(2, 32, "quadratic") + (two_materials ? elastic_body : ""), {.dim = 2});
    State<2> s = build_state<2>(scene);
    auto& P = s.particles;
    const int damage = s.materials[0]->laplacian_request().active() ? 0 : 1;
    int requested = 0, others = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      for (int k = 0; k < P.state_size; ++k) P.state_of(p)[k] = -1;
      if (P.material[p] == damage) P.state_of(p)[0] = 0;
    }
    NonlocalLaplacian<2, QuadraticKernel> op;
    op.apply(s);
    const Real dx = s.grid.geo.dx;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Real* q = P.state_of(p);
      if (P.material[p] == damage) {
        ASSERT_EQ(std::bit_cast<std::uint64_t>(double(q[2])), 0u) << "particle " << p;
        ASSERT_EQ(q[3], 4 / (dx * dx)) << "particle " << p;
        ++requested;
      } else {
        for (int k = 0; k < P.state_size; ++k) ASSERT_EQ(q[k], -1) << "particle " << p;
        ++others;
      }
    }
    EXPECT_GT(requested, 0);
    EXPECT_EQ(others > 0, two_materials);
  }
}

TYPED_TEST(NonlocalLaplacianTest, LocalOperatorEqualsTheWholeOneBitForBit) {
  expect_local_equals_whole<2, TypeParam>(32, Vec<2>(0.5, 0.45), 0.08);
  expect_local_equals_whole<2, TypeParam>(32, Vec<2>(0.2, 0.8), 0.1);  // the body's corner
  expect_local_equals_whole<2, TypeParam>(32, Vec<2>(0.5, 0.5), 0);    // zero everywhere
  expect_local_equals_whole<3, TypeParam>(24, Vec<3>(0.45, 0.5, 0.55), 0.08);
  expect_local_equals_whole<3, TypeParam>(24, Vec<3>(0.8, 0.2, 0.8), 0.1);
}

}  // namespace nonlocal_test
}  // namespace mpmtb
