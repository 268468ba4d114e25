// Walls impose their condition on the interpolated velocity field itself,
// sum_i w_i(x) v_i, at every point of the face, for every kernel.
#include <gtest/gtest.h>

#include "core/registry.hpp"
#include "core/stencil.hpp"
#include "kernels/all.hpp"
#include "setup.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace walls_test {

template <int Dim, class Kernel>
Vec<Dim> interpolate(const Grid<Dim>& g, const Vec<Dim>& x) {
  Vec<Dim> v = Vec<Dim>::Zero();
  Stencil<Dim, Kernel>(x, g.geo).for_each_node(
      g.geo, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) { v += w * g.v[node]; });
  return v;
}

// A 2D body pressed into the lower-left corner: sticky wall at x = 0, slip at y = 0.
template <class Kernel>
void check_faces(int ppc = 2) {
  const std::string toml = testing::free_body_toml(
      2, "mls", "quadratic", "[boundary]\nx_min = \"sticky\"\ny_min = \"slip\"\n");
  Scene scene = testing::scene_from_toml(toml, {.dim = 2, .ppc = ppc});
  scene.bodies[0].min = Vec3(0, 0, 0);
  scene.bodies[0].velocity = Vec3(-0.4, -0.3, 0);
  State<2> s = build_state<2>(scene);
  Parameters params;
  // The walls act in update_grid; any transfer compiled with the kernel will do.
  std::string transfer;
  for (const auto& t : transfer_list()) {
    if (transfer.empty() && unsupported_reason(t.name, Kernel::name).empty() &&
        compiled_combination(t.name, Kernel::name))
      transfer = t.name;
  }
  if (transfer.empty()) GTEST_SKIP() << "no transfer supports " << Kernel::name;
  auto st = make_stepper<2>(transfer, Kernel::name, params);
  st->particles_to_grid(s, 1e-3);
  st->update_grid(s, 1e-3);
  Real speed = 0;
  for (int k = 0; k <= 20; ++k) {
    const Real along = 0.02 * k;  // points on each face, inside the body's extent
    const Vec<2> on_x_face = interpolate<2, Kernel>(s.grid, Vec<2>(0, along));
    const Vec<2> on_y_face = interpolate<2, Kernel>(s.grid, Vec<2>(along + 0.01, 0));
    EXPECT_NEAR(on_x_face.norm(), 0, 1e-14) << "sticky face at y = " << along;
    EXPECT_NEAR(on_y_face[1], 0, 1e-14) << "slip face at x = " << along;
    speed = std::max(speed, std::abs(on_y_face[0]));
  }
  EXPECT_GT(speed, 0.1) << "slip must keep the tangential velocity";
}

TEST(Walls, ConditionHoldsOnTheFaceLinear) {
  check_faces<LinearKernel>();
}
TEST(Walls, ConditionHoldsOnTheFaceQuadratic) {
  check_faces<QuadraticKernel>();
}
TEST(Walls, ConditionHoldsOnTheFaceCubic) {
  check_faces<CubicKernel>();
}
// uGIMP's support, 1 + l cells, follows the particle half-width l = 1/(2 ppc).
TEST(Walls, ConditionHoldsOnTheFaceGimp) {
  for (const int ppc : {1, 2, 4}) {
    SCOPED_TRACE(::testing::Message() << "ppc " << ppc);
    check_faces<GimpKernel>(ppc);
  }
}

// A separate wall lets material leave: a body moving away keeps its velocity;
// moving into the wall, the normal velocity at the wall nodes is removed.
TEST(Walls, SeparateHoldsOnlyInward) {
  for (double vx : {-0.4, 0.4}) {
    Scene scene = testing::scene_from_toml(
        testing::free_body_toml(1, "mls", "quadratic", "[boundary]\nx_min = \"separate\"\n"));
    scene.bodies[0].min = Vec3(0, 0, 0);
    scene.bodies[0].velocity = Vec3(vx, 0, 0);
    State<1> s = build_state<1>(scene);
    Parameters params;
    auto st = make_stepper<1>("mls", "quadratic", params);
    st->particles_to_grid(s, 0);
    st->update_grid(s, 0);
    const long face_node = GridGeometry<1>::pad;
    if (vx < 0) {
      EXPECT_EQ(s.grid.v[face_node][0], 0);
    } else {
      EXPECT_NEAR(s.grid.v[face_node][0], vx, 1e-12);
    }
  }
}

}  // namespace walls_test
}  // namespace mpmtb

namespace mpmtb {
namespace walls_test {

// Pinned particles hold every node they touch at rest, so they do not move at
// all, while the rest of the body sags under gravity.
TEST(Pins, PinnedParticlesStayPutUnderGravity) {
  for (const char* transfer : {"pic", "flip", "apic", "mls"}) {
    const Scene scene = testing::scene_from_toml(
        testing::free_body_toml(2, transfer, "quadratic",
                                "[physics]\ngravity = [0.0, -9.81, 0.0]\n"
                                "[[pins]]\nmin = [0.0, 0.55, 0.0]\nmax = [1.0, 1.0, 1.0]\n"),
        {.set = {"bodies.0.velocity=[0,0,0]", "bodies.0.angular_velocity=[0,0,0]"}});
    State<2> s = build_state<2>(scene);
    Parameters params;
    auto st = make_stepper<2>(transfer, "quadratic", params);
    const auto x0 = s.particles.x;
    for (int i = 0; i < 100; ++i) st->step(s, 1e-3);
    int pinned = 0;
    Real sag = 0;
    for (std::size_t p = 0; p < x0.size(); ++p) {
      if (s.particles.pinned[p]) {
        ++pinned;
        EXPECT_EQ(s.particles.x[p], x0[p]) << transfer << " pinned particle " << p << " moved";
      } else {
        sag = std::max(sag, x0[p][1] - s.particles.x[p][1]);
      }
    }
    EXPECT_GT(pinned, 0);
    EXPECT_GT(sag, 1e-3) << transfer << ": the free part must fall";
  }
}

// The grid update skips fold() (and adds gravity in its own loop) where
// Walls::may_fold says that no ghost layer meets the active box. Checked
// against fold() itself, which must then change nothing: for a body against a
// sticky wall (fold() acts) and one a few cells from every wall (it is skipped).
TEST(Walls, FoldIsSkippedOnlyWhereItCannotAct) {
  for (const char* kernel : {"quadratic", "cubic"}) {
    for (const bool at_wall : {true, false}) {
      const std::string toml = testing::free_body_toml(
          2, "mls", kernel, "[boundary]\nx_min = \"sticky\"\nx_max = \"slip\"\n");
      Scene scene = testing::scene_from_toml(toml, {.dim = 2});
      // Against the sticky wall, or 6.4 cells from it and 6 from the slip wall.
      scene.bodies[0].min = Vec3(at_wall ? 0 : 0.4, 0.35, 0);
      State<2> s = build_state<2>(scene);
      Parameters params;
      auto st = make_stepper<2>("mls", kernel, params);
      st->particles_to_grid(s, 1e-3);
      Grid<2> folded = s.grid;
      s.walls.fold(folded);
      const bool changed = folded.m != s.grid.m || folded.p != s.grid.p;
      const bool may_fold = s.walls.may_fold(s.grid);
      if (!may_fold) {
        EXPECT_FALSE(changed) << kernel << ": fold() acted where it was skipped";
      }
      EXPECT_EQ(changed, at_wall) << kernel;
      EXPECT_EQ(may_fold, at_wall) << kernel;
    }
  }
}

}  // namespace walls_test
}  // namespace mpmtb
