// The step's conservation laws and exact motions, for every registered
// transfer and kernel in 1D, 2D and 3D.
#include <gtest/gtest.h>
#include <omp.h>

#include "core/diagnostics.hpp"
#include "core/registry.hpp"
#include "setup.hpp"
#include "support/combinations.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace step_test {

using testing::Combination;

class StepTest : public ::testing::TestWithParam<Combination> {
 protected:
  template <int Dim>
  void run(const std::function<void(State<Dim>&, Stepper<Dim>&, const Scene&)>& check,
           const std::string& extra = "", Overrides o = {}) {
    const auto& c = GetParam();
    const Scene scene =
        testing::scene_from_toml(testing::free_body_toml(Dim, c.transfer, c.kernel, extra), o);
    State<Dim> s = build_state<Dim>(scene);
    Parameters params = scene.transfer_params;
    auto stepper = make_stepper<Dim>(c.transfer, c.kernel, params);
    check(s, *stepper, scene);
  }
  bool positions_follow_momentum() const {
    for (const auto& t : transfer_list())
      if (t.name == GetParam().transfer) return t.positions_follow_momentum;
    return true;
  }
  template <class F>
  void for_dim(F&& f) {
    testing::with_dim(GetParam().dim, f);
  }
};

// Partition of unity makes the grid mass equal the particle mass.
TEST_P(StepTest, P2GConservesMass) {
  for_dim([&]<int Dim>() {
    run<Dim>([](State<Dim>& s, Stepper<Dim>& st, const Scene&) {
      st.particles_to_grid(s, 1e-3);
      const GridDiagnostics g = measure_grid(s.grid);
      const Diagnostics d = measure(s, st);
      EXPECT_NEAR(g.mass, d.mass, 1e-14 * d.mass);
      // Zero first moment: the affine part adds no net momentum.
      EXPECT_LE((g.momentum - d.momentum).norm(), 1e-12 * d.momentum.norm());
    });
  });
}

// No gravity, no walls in reach: internal forces sum to zero, so linear
// momentum (and for affine transfers angular momentum) is kept to round-off.
TEST_P(StepTest, FreeFlightConservesMomentum) {
  for_dim([&]<int Dim>() {
    run<Dim>([](State<Dim>& s, Stepper<Dim>& st, const Scene&) {
      const Diagnostics d0 = measure(s, st);
      for (int i = 0; i < 40; ++i) st.step(s, 1e-3);
      const Diagnostics d1 = measure(s, st);
      const Real p_scale = d0.mass * 0.5;  // mass times a typical speed
      EXPECT_LE((d1.momentum - d0.momentum).norm(), 1e-12 * p_scale);
      EXPECT_NEAR(d1.mass, d0.mass, 0);
      if (Dim == 1) {
        // Rigid translation: the B-spline and hat interpolants reproduce the
        // uniform field, so no spurious strain energy appears.
        EXPECT_LT(d1.strain, 1e-24 * d0.kinetic);
      } else {
        EXPECT_GT(d1.strain, 0) << "the spinning body should deform";
      }
    });
  });
}

// Under gravity alone the centre of mass follows symplectic Euler exactly:
// v_n = v_0 + n dt g, x_n = x_0 + n dt v_0 + n (n + 1) / 2 dt^2 g, which differs
// from the parabola x_0 + v_0 t + g t^2 / 2 by g dt t / 2.
TEST_P(StepTest, FreeFallFollowsTheParabola) {
  const bool follows = positions_follow_momentum();
  for_dim([&]<int Dim>() {
    run<Dim>(
        [follows](State<Dim>& s, Stepper<Dim>& st, const Scene& scene) {
          const Diagnostics d0 = measure(s, st);
          const Vec3 g = scene.gravity;
          const Real dt = 1e-3;
          const int n = 40;
          for (int i = 0; i < n; ++i) st.step(s, dt);
          const Diagnostics d = measure(s, st);
          const Real t = n * dt;
          const Vec3 v0 = d0.center_of_mass_velocity, x0 = d0.center_of_mass;
          const Vec3 discrete = x0 + t * v0 + Real(n * (n + 1)) / 2 * dt * dt * g;
          const Vec3 parabola = x0 + t * v0 + Real(0.5) * t * t * g;
          for (int a = 0; a < Dim; ++a) {
            EXPECT_NEAR(d.center_of_mass_velocity[a], v0[a] + t * g[a], 1e-11);
            if (!follows) continue;  // ASFLIP: see its header
            EXPECT_NEAR(d.center_of_mass[a], discrete[a], 1e-12);
            EXPECT_NEAR(d.center_of_mass[a], parabola[a], std::abs(g[a]) * dt * t / 2 + 1e-12);
          }
          EXPECT_GT((discrete - x0).norm(), 1e-3) << "the body must actually fall";
        },
        "[physics]\ngravity = [-3.0, -9.81, 2.0]\n");
  });
}

// The same inputs and thread count give bit-identical states; 1 and 2 threads
// agree bit for bit too, since P2G scatters in a fixed order. The grids are
// fine enough for the loops to run in parallel (kParallelMinimum).
TEST_P(StepTest, ThreadCountDoesNotChangeTheResult) {
  for_dim([&]<int Dim>() {
    std::vector<Vec<Dim>> x[2];
    // Enough particles for the parallel loops (kParallelMinimum) and several
    // blocks per colour: ~5k in 1D and 2D, ~16k in 3D.
    const int cells = Dim == 1 ? 8192 : Dim == 2 ? 128 : 40;
    // Within the CFL limit: at 8192 cells dt = 1e-4 is ~10x the stable step, and a
    // run that overflows to NaN has no defined stencil (seen with uGIMP + MLS).
    const Real dt = Dim == 1 ? 5e-6 : 1e-4;
    for (int threads = 1; threads <= 2; ++threads) {
      omp_set_num_threads(threads);
      run<Dim>(
          [&](State<Dim>& s, Stepper<Dim>& st, const Scene&) {
            ASSERT_GE(static_cast<long>(s.particles.size()), kParallelMinimum);
            for (int i = 0; i < 10; ++i) st.step(s, dt);
            x[threads - 1] = s.particles.x;
          },
          "", Overrides{.cells = cells});
    }
    omp_set_num_threads(2);
    ASSERT_EQ(x[0].size(), x[1].size());
    for (std::size_t p = 0; p < x[0].size(); ++p) ASSERT_EQ(x[0][p], x[1][p]) << "particle " << p;
  });
}

// Outside the active box every nodal field is zero after each step (Grid::active),
// with the body moving fast enough for the box to move across the grid, which
// P2G clears only where the box left (SolverStages::clear_for_unpack). usl, and
// musl for the transfers that take it (its momentum scatter clears the box).
TEST_P(StepTest, TheGridIsZeroOutsideTheActiveBox) {
  for_dim([&]<int Dim>() {
    run<Dim>([](State<Dim>&, Stepper<Dim>& st, const Scene& scene) {
      const std::vector<UpdateOrder> orders = st.gradient_based()
                                                  ? std::vector{UpdateOrder::usl, UpdateOrder::musl}
                                                  : std::vector{UpdateOrder::usl};
      for (const UpdateOrder order : orders) {
        State<Dim> s = build_state<Dim>(scene);
        st.set_update_order(order);
        Vec<Dim> drift;  // about a cell every 10 steps along each axis
        for (int a = 0; a < Dim; ++a) drift[a] = a % 2 ? -5 : 6;
        for (auto& v : s.particles.v) v += drift;
        const Grid<Dim>& g = s.grid;
        int moved = 0;
        NodeBox<Dim> last;
        for (int i = 0; i < 30; ++i) {
          st.step(s, 1e-3);
          moved += i > 0 && (g.active.lo != last.lo || g.active.hi != last.hi);
          last = g.active;
          long nonzero = 0;
          for (long node = 0; node < g.geo.node_count(); ++node) {
            const auto idx = g.geo.multi_index(node);
            bool inside = true;
            for (int a = 0; a < Dim; ++a)
              inside = inside && idx[a] >= g.active.lo[a] && idx[a] <= g.active.hi[a];
            if (inside) continue;
            nonzero += g.m[node] != 0 || g.p[node] != Vec<Dim>::Zero() ||
                       g.f[node] != Vec<Dim>::Zero() || g.v[node] != Vec<Dim>::Zero() ||
                       g.v_old[node] != Vec<Dim>::Zero() || g.pinned[node] != 0;
          }
          ASSERT_EQ(nonzero, 0) << "step " << i << ", " << update_order_name(order);
        }
        EXPECT_GE(moved, 3) << "the box should move across the grid";
      }
    });
  });
}

INSTANTIATE_TEST_SUITE_P(AllCombinations, StepTest,
                         ::testing::ValuesIn(testing::all_combinations()),
                         testing::combination_name);

// Affine transfers keep angular momentum, the affine part included, to round-off.
TEST(AffineTransfer, FreeFlightConservesAngularMomentum) {
  for (const char* kernel : {"quadratic", "cubic"}) {
    for (int dim : {2, 3}) {
      const Scene scene = testing::scene_from_toml(testing::free_body_toml(dim, "mls", kernel));
      auto check = [&]<int Dim>() {
        State<Dim> s = build_state<Dim>(scene);
        Parameters params;
        auto st = make_stepper<Dim>("mls", kernel, params);
        const Diagnostics d0 = measure(s, *st);
        for (int i = 0; i < 40; ++i) st->step(s, 1e-3);
        const Diagnostics d1 = measure(s, *st);
        EXPECT_LE((d1.angular_momentum - d0.angular_momentum).norm(),
                  1e-12 * d0.angular_momentum.norm())
            << kernel << " " << Dim << "D";
      };
      if (dim == 2) check.template operator()<2>();
      if (dim == 3) check.template operator()<3>();
    }
  }
}

}  // namespace step_test
}  // namespace mpmtb
