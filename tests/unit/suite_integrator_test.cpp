// The time integrator as the suites' third method axis (issue 19,
// cases/suite/README.md): the explicit runs keep the arguments and folders they
// had before the axis (so their results are the same runs), the implicit runs
// carry --integrator and live in folders of their own, only transfers that take
// an implicit integrator get one, the stability sweeps reach far beyond the
// explicit limit, the work-precision runs take larger steps, and the
// --integrator filter selects and refuses names like --transfer and --kernel.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "core/errors.hpp"
#include "suite/plan.hpp"

namespace mpmtb::suite {
namespace suite_integrator_test {

Plan PlanOf(const std::string& name, std::vector<std::string> integrators = {},
            std::vector<std::string> cases = {}) {
  SuiteRequest r;
  r.name = name;
  r.quiet = true;
  r.out = "unused";
  r.integrators = std::move(integrators);
  r.cases = std::move(cases);
  auto plans = plan_suites(r);
  EXPECT_EQ(plans.size(), 1u);
  return std::move(plans.at(0));
}

// The value after `flag` in a run's arguments, or "" without the flag.
std::string ArgumentOf(const RunSpec& s, const std::string& flag) {
  const auto a = s.arguments("out");
  const auto it = std::find(a.begin(), a.end(), flag);
  return it == a.end() || it + 1 == a.end() ? "" : *(it + 1);
}

TEST(SuiteIntegrators, ExplicitRunsKeepTheirArgumentsAndFolders) {
  for (const char* suite : {"convergence", "stability", "speed-accuracy"}) {
    const Plan p = PlanOf(suite);
    std::set<std::string> dirs;
    int explicit_runs = 0;
    for (const RunSpec& s : p.specs) {
      EXPECT_TRUE(dirs.insert(s.dir.generic_string()).second) << "folder twice: " << s.dir;
      if (!s.integrator.empty()) continue;
      ++explicit_runs;
      EXPECT_EQ(ArgumentOf(s, "--integrator"), "") << s.dir;
      // runs/<case>/<transfer>-<kernel>[/<label>]: no integrator in the name.
      const std::string method = s.transfer + "-" + s.kernel;
      int named = 0;
      for (const auto& part : s.dir) {
        named += part.string() == method;
        EXPECT_EQ(part.string().find(method + "-"), std::string::npos) << s.dir;
      }
      EXPECT_EQ(named, 1) << s.dir;
    }
    EXPECT_GT(explicit_runs, 10) << suite;
  }
}

TEST(SuiteIntegrators, ImplicitRunsCarryTheIntegratorAndTakeLargeSteps) {
  // Convergence: explicit unless named.
  for (const RunSpec& s : PlanOf("convergence").specs) EXPECT_TRUE(s.integrator.empty()) << s.dir;
  const std::set<std::string> refused = {"mls", "xpic"};  // core/stepper.hpp
  for (const char* suite : {"stability", "speed-accuracy"}) {
    std::set<std::string> integrators;
    double largest_cfl = 0;
    for (const RunSpec& s : PlanOf(suite).specs) {
      if (s.integrator.empty()) continue;
      integrators.insert(s.integrator);
      EXPECT_EQ(ArgumentOf(s, "--integrator"), s.integrator) << s.dir;
      EXPECT_EQ(refused.count(s.transfer), 0u) << s.dir;
      EXPECT_NE(s.dir.generic_string().find(s.transfer + "-" + s.kernel + "-" + s.integrator),
                std::string::npos)
          << s.dir;
      ASSERT_TRUE(s.cfl.has_value()) << s.dir;
      largest_cfl = std::max(largest_cfl, *s.cfl);
    }
    EXPECT_EQ(integrators, (std::set<std::string>{"backward-euler", "newmark"})) << suite;
    // Far beyond the explicit limit (von Neumann: 1 to 1.9 in 1D, shared/REFERENCE.md).
    EXPECT_GE(largest_cfl, 16) << suite;
  }
}

TEST(SuiteIntegrators, TheFilterSelectsAndRefusesNames) {
  for (const RunSpec& s : PlanOf("stability", {"newmark"}).specs) {
    EXPECT_EQ(s.integrator, "newmark") << s.dir;
  }
  for (const RunSpec& s : PlanOf("stability", {"explicit"}).specs) {
    EXPECT_TRUE(s.integrator.empty()) << s.dir;
  }
  // Named, an implicit integrator joins the convergence suite: every method that takes it.
  std::set<std::string> transfers;
  for (const RunSpec& s : PlanOf("convergence", {"backward-euler"}, {"bar"}).specs) {
    EXPECT_EQ(s.integrator, "backward-euler") << s.dir;
    transfers.insert(s.transfer);
  }
  EXPECT_TRUE(transfers.count("apic") && transfers.count("pic") && !transfers.count("mls"));
  try {
    PlanOf("stability", {"crank-nicolson"});
    ADD_FAILURE() << "an unknown integrator was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--integrator 'crank-nicolson'"), std::string::npos) << m;
    EXPECT_NE(m.find("explicit, backward-euler, newmark"), std::string::npos) << m;
  }
}

}  // namespace suite_integrator_test
}  // namespace mpmtb::suite
