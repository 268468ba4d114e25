// The stress-update order (core/stepper.hpp): usl, usf and musl. The energy
// behaviour of each order is checked against its derivation in
// tests/verification/update_order_test.cpp; here: conservation for every
// gradient-based transfer under every order, usl as the unchanged default,
// and the input rules (mls refused, unknown names rejected, recorded config).
#include <gtest/gtest.h>

#include "core/diagnostics.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "run.hpp"
#include "setup.hpp"
#include "support/cli.hpp"
#include "support/combinations.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace update_order_test {

using testing::Combination;

// A transfer that does not declare the trait is gradient-based, so that new
// transfers need no edit; MLS-MPM declares that it is not.
struct UndeclaredTransfer {};
static_assert(transfer_is_gradient_based<UndeclaredTransfer>());

struct OrderCase {
  Combination c;
  UpdateOrder order;
};
void PrintTo(const OrderCase& o, std::ostream* os) {
  *os << o.c.dim << "D " << o.c.transfer << " " << o.c.kernel << " " << update_order_name(o.order);
}

std::vector<OrderCase> gradient_based_cases() {
  std::vector<OrderCase> out;
  for (const auto& c : testing::all_combinations()) {
    Parameters params(c.transfer);
    if (!make_stepper<1>(c.transfer, c.kernel, params)->gradient_based()) continue;  // mls
    for (UpdateOrder o : {UpdateOrder::usl, UpdateOrder::usf, UpdateOrder::musl})
      out.push_back({c, o});
  }
  return out;
}

class OrderTest : public ::testing::TestWithParam<OrderCase> {
 protected:
  template <int Dim>
  void run(const std::function<void(State<Dim>&, Stepper<Dim>&)>& check) {
    const auto& [c, order] = GetParam();
    const Scene scene =
        testing::scene_from_toml(testing::free_body_toml(Dim, c.transfer, c.kernel));
    State<Dim> s = build_state<Dim>(scene);
    Parameters params = scene.transfer_params;
    auto stepper = make_stepper<Dim>(c.transfer, c.kernel, params);
    stepper->set_update_order(order);
    check(s, *stepper);
  }
};

// No gravity, no walls in reach: every order scatters the same momentum, and
// the internal forces -V0 tau grad w sum to zero over the nodes (partition of
// unity), whichever stress they come from, so linear momentum is kept to
// round-off; mass is carried by the particles and exact.
TEST_P(OrderTest, FreeFlightConservesMassAndMomentum) {
  testing::with_dim(GetParam().c.dim, [&]<int Dim>() {
    run<Dim>([](State<Dim>& s, Stepper<Dim>& st) {
      const Diagnostics d0 = measure(s, st);
      for (int i = 0; i < 40; ++i) {
        const StepReport r = st.step(s, 1e-3);
        ASSERT_EQ(r.non_finite, -1);
      }
      const Diagnostics d1 = measure(s, st);
      const Real p_scale = d0.mass * 0.5;  // mass times a typical speed
      EXPECT_LE((d1.momentum - d0.momentum).norm(), 1e-12 * p_scale);
      EXPECT_NEAR(d1.mass, d0.mass, 0);
      // The body spins and deforms in 2D and 3D, so F was updated; in 1D the
      // rigid translation keeps F = I (no spurious strain energy) in every order.
      if (Dim == 1) {
        EXPECT_LT(d1.strain, 1e-24 * d0.kinetic);
      } else {
        EXPECT_GT(d1.strain, 0);
      }
    });
  });
}

std::string order_case_name(const ::testing::TestParamInfo<OrderCase>& info) {
  const auto& c = info.param.c;
  return std::to_string(c.dim) + "d_" + c.transfer + "_" + c.kernel + "_" +
         std::string(update_order_name(info.param.order));
}

INSTANTIATE_TEST_SUITE_P(GradientBased, OrderTest, ::testing::ValuesIn(gradient_based_cases()),
                         order_case_name);

// The default order is usl, and step() under it is the textbook pipeline of
// the stages, bit for bit.
TEST(UpdateOrder, DefaultIsUslAndStepIsTheUslPipeline) {
  const Scene scene = testing::scene_from_toml(testing::free_body_toml(2, "apic", "quadratic"));
  EXPECT_EQ(scene.update_order, UpdateOrder::usl);
  State<2> a = build_state<2>(scene), b = build_state<2>(scene);
  Parameters pa = scene.transfer_params, pb = scene.transfer_params;
  auto sa = make_stepper<2>("apic", "quadratic", pa);
  auto sb = make_stepper<2>("apic", "quadratic", pb);
  EXPECT_EQ(sa->update_order(), UpdateOrder::usl);
  for (int i = 0; i < 10; ++i) {
    sa->step(a, 1e-3);
    sb->particles_to_grid(b, 1e-3);
    sb->update_grid(b, 1e-3);
    sb->grid_to_particles(b, 1e-3);
    sb->constitutive_update(b, 1e-3);
  }
  for (std::size_t p = 0; p < a.particles.size(); ++p) {
    ASSERT_EQ(a.particles.x[p], b.particles.x[p]);
    ASSERT_EQ(a.particles.v[p], b.particles.v[p]);
    ASSERT_EQ(a.particles.F[p], b.particles.F[p]);
  }
}

// The orders really differ: after one step with stress, usf and musl give
// another F than usl (they use other grid velocities), and the same motion of
// the centre of mass.
TEST(UpdateOrder, OrdersChangeTheDeformationNotTheMomentum) {
  const Scene scene = testing::scene_from_toml(testing::free_body_toml(2, "flip", "quadratic"));
  std::vector<State<2>> states;
  for (UpdateOrder o : {UpdateOrder::usl, UpdateOrder::usf, UpdateOrder::musl}) {
    State<2> s = build_state<2>(scene);
    Parameters params = scene.transfer_params;
    auto st = make_stepper<2>("flip", "quadratic", params);
    st->set_update_order(o);
    for (int i = 0; i < 3; ++i) st->step(s, 1e-3);
    states.push_back(std::move(s));
  }
  for (int k : {1, 2}) {
    Real dF = 0;
    for (std::size_t p = 0; p < states[0].particles.size(); ++p)
      dF = std::max(dF, (states[k].particles.F[p] - states[0].particles.F[p]).norm());
    EXPECT_GT(dF, 1e-8) << update_order_name(static_cast<UpdateOrder>(k));
  }
}

TEST(UpdateOrder, MlsRefusesUsfAndMusl) {
  for (int dim : {1, 2}) {
    testing::with_dim(dim, [&]<int Dim>() {
      Parameters params("mls");
      auto st = make_stepper<Dim>("mls", "quadratic", params);
      EXPECT_FALSE(st->gradient_based());
      st->set_update_order(UpdateOrder::usl);
      for (UpdateOrder o : {UpdateOrder::usf, UpdateOrder::musl}) {
        try {
          st->set_update_order(o);
          ADD_FAILURE() << "mls accepted " << update_order_name(o);
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("method.update_order"), std::string::npos);
          EXPECT_NE(std::string(e.what()).find("mls"), std::string::npos);
        }
      }
      EXPECT_EQ(st->update_order(), UpdateOrder::usl);
    });
  }
  // Through a scene: the run is refused before anything is written.
  const Scene scene = testing::scene_from_toml(testing::free_body_toml(1, "mls", "linear"),
                                               {.update_order = std::string("musl")});
  EXPECT_THROW(run_scene(scene, testing::scratch_path("order_mls")), InputError);
}

TEST(UpdateOrder, UnknownOrderIsRejectedNamingFieldAndValues) {
  try {
    testing::scene_from_toml(testing::free_body_toml(1, "flip", "linear"),
                             {.update_order = std::string("usx")});
    ADD_FAILURE() << "usx accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("method.update_order"), std::string::npos) << what;
    EXPECT_NE(what.find("usl, usf, musl"), std::string::npos) << what;
  }
}

// Recorded in summary.json's config like the other method keys, the default too.
TEST(UpdateOrder, RecordedInTheSummaryConfig) {
  const auto out = testing::scratch_path("order_cli");
  const auto r = testing::run_cli(
      "run single_point --t-end 0.02 --update-order usf --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(testing::read_json(out / "summary.json")["config"]["method"]["update_order"], "usf");
  const Scene bar = load_scene("bar");
  EXPECT_EQ(bar.resolved.at_path("method.update_order").value_or(std::string()), "usl");
  const auto bad = testing::run_cli("run single_point --update-order usx --quiet --out " +
                                    testing::scratch_path("order_bad").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("method.update_order"), std::string::npos) << bad.err;
  std::filesystem::remove_all(out);
}

}  // namespace update_order_test
}  // namespace mpmtb
