// `mpmtb compare` on small synthetic results trees: what counts as a change
// (beyond the tolerance of its kind), what never does (timings, provenance),
// one-sided runs, and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "compare/compare.hpp"
#include "compare/csv.hpp"
#include "core/errors.hpp"

namespace mpmtb::compare {
namespace compare_test {

namespace fs = std::filesystem;

// A run's summary with the fields a real one has (values made up, not ours).
nlohmann::json summary() {
  return {{"status", "ok"},
          {"steps", 120},
          {"particles", 32},
          {"wall_seconds", 0.25},
          {"particle_steps_per_second", 15360.0},
          {"git_revision", "abc1234"},
          {"version", {{"version", "0.2.0"}, {"march", "x86-64-v3"}}},
          {"drift", {{"energy", -0.0125}, {"mass", 0.0}, {"angular_momentum", 3e-16}}},
          {"error", {{"disp_l2", 4.5e-6}, {"disp_linf", 7.25e-6}}}};
}

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

class CompareTrees : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("mpmtb_compare_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    for (const char* side : {"old", "new"}) {
      for (const char* run : {"apic-quadratic", "pic-linear"}) {
        write(root_ / side / run / "summary.json", summary().dump(1));
        // A time series is not compared (its summary is).
        write(root_ / side / run / "series.csv", "step,t,kinetic\n0,0,1\n");
      }
      write(root_ / side / "convergence" / "bar.csv",
            "case,transfer,level,status,error,order\n"
            "bar,pic,0,ok,0.00338285,\n"
            "bar,pic,1,ok,0.000679541,2.3156\n");
    }
  }
  void TearDown() override { fs::remove_all(root_); }

  // Changes one field of new/apic-quadratic/summary.json.
  template <class F>
  void edit(F&& f) {
    nlohmann::json j = summary();
    f(j);
    write(root_ / "new" / "apic-quadratic" / "summary.json", j.dump(1));
  }
  Report run() const { return compare_paths(root_ / "old", root_ / "new", Tolerances::builtin()); }

  fs::path root_;
};

TEST_F(CompareTrees, IdenticalTreesPass) {
  const Report r = run();
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.files, 3);  // two summaries and the table; the series are left out
  EXPECT_GT(r.values, 20);
}

TEST_F(CompareTrees, MicroChangeOfAnErrorNormFailsNamingIt) {
  edit([](nlohmann::json& j) { j["error"]["disp_l2"] = 4.5e-6 * (1 + 1e-6); });
  const Report r = run();
  ASSERT_TRUE(r.changed());
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(r.changes[0].file, "apic-quadratic/summary.json");
  EXPECT_EQ(r.changes[0].metric, "error.disp_l2");
  EXPECT_NEAR(r.changes[0].rel_diff, 1e-6, 1e-12);
  const std::string text = render(r, "old", "new", 50);
  EXPECT_NE(text.find("error.disp_l2"), std::string::npos);
  EXPECT_NE(text.find("rel 1e-09"), std::string::npos);
}

TEST_F(CompareTrees, RoundOffSizedChangePasses) {
  edit([](nlohmann::json& j) {
    j["error"]["disp_l2"] = 4.5e-6 * (1 + 1e-12);
    j["drift"]["angular_momentum"] = -2e-16;  // round-off around zero: the absolute floor
  });
  EXPECT_FALSE(run().changed());
}

TEST_F(CompareTrees, StatusAndCountsAreExact) {
  edit([](nlohmann::json& j) { j["status"] = "unstable"; });
  Report r = run();
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(r.changes[0].metric, "status");
  EXPECT_EQ(r.changes[0].tolerance, "exact");
  edit([](nlohmann::json& j) { j["steps"] = 121; });
  r = run();
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(r.changes[0].metric, "steps");
}

TEST_F(CompareTrees, TimingsAndProvenanceNeverFail) {
  edit([](nlohmann::json& j) {
    j["wall_seconds"] = 2.5;
    j["particle_steps_per_second"] = 1536.0;
    j["git_revision"] = "def5678";
    j["version"]["march"] = "native";
  });
  const Report r = run();
  EXPECT_FALSE(r.changed());
  // The timings are reported: the changed wall time's ratio is 10.
  bool seen = false;
  for (const auto& t : r.timings) seen |= t.metric == "wall_seconds" && t.new_value == 2.5;
  EXPECT_TRUE(seen);
  EXPECT_NE(render(r, "old", "new", 50).find("never failed"), std::string::npos);
}

TEST_F(CompareTrees, MissingRunIsListedAndFails) {
  fs::remove_all(root_ / "new" / "pic-linear");
  Report r = run();
  EXPECT_TRUE(r.changed());
  ASSERT_EQ(r.only_old.size(), 1u);
  EXPECT_EQ(r.only_old[0], "pic-linear/summary.json");
  EXPECT_NE(render(r, "old", "new", 50).find("only in old: pic-linear/summary.json"),
            std::string::npos);
  // A metric present on one side only is a change too.
  edit([](nlohmann::json& j) { j["error"].erase("disp_linf"); });
  r = run();
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(r.changes[0].new_value, "(absent)");
}

TEST_F(CompareTrees, TableRowsPairByKeyAndRespectPrintedDigits) {
  // One unit in the last printed digit is the table's rounding, not a change;
  // a status change in a row is; rows are paired by their keys, not their order.
  write(root_ / "new" / "convergence" / "bar.csv",
        "case,transfer,level,status,error,order\n"
        "bar,pic,1,unstable,,\n"
        "bar,pic,0,ok,0.00338286,\n");
  const Report r = run();
  std::vector<std::string> metrics;
  for (const auto& c : r.changes) metrics.push_back(c.metric);
  EXPECT_EQ(metrics, (std::vector<std::string>{"bar/pic/1: error", "bar/pic/1: order",
                                               "bar/pic/1: status"}));
}

TEST_F(CompareTrees, MalformedJsonIsAClearError) {
  write(root_ / "new" / "pic-linear" / "summary.json", "{\"status\": \"ok\",");
  try {
    run();
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pic-linear/summary.json"), std::string::npos) << what;
    EXPECT_NE(what.find("malformed JSON"), std::string::npos) << what;
  }
}

TEST_F(CompareTrees, MissingTreeIsAnError) {
  EXPECT_THROW(compare_paths(root_ / "nothing", root_ / "new", Tolerances::builtin()), InputError);
}

TEST(CompareTolerances, RulesFollowTheFile) {
  const Tolerances t = Tolerances::parse(R"(
[files]
include = ["*.json"]
[default]
rel = 1e-6
exact = ["steps"]
timing = ["*_seconds"]
[[metric]]
match = "drift.*"
rel = 1e-3
abs = 1e-10
)",
                                         "test.toml");
  EXPECT_EQ(t.rule("steps").kind, RuleKind::kExact);
  EXPECT_EQ(t.rule("wall_seconds").kind, RuleKind::kTiming);
  EXPECT_EQ(t.rule("drift.energy").rel, 1e-3);
  EXPECT_EQ(t.rule("error.disp_l2").rel, 1e-6);
  EXPECT_TRUE(t.compared_file("summary.json"));
  EXPECT_FALSE(t.compared_file("runs.csv"));
  EXPECT_THROW(Tolerances::parse("[default]\nrel = -1\n[files]\ninclude=['*']", "bad.toml"),
               InputError);
  EXPECT_THROW(Tolerances::parse("[default", "bad.toml"), InputError);
}

TEST(CompareCsv, QuotedFieldsAndRaggedRows) {
  const CsvText t = parse_csv("a,b\n\"x, \"\"y\"\"\",2\n", "t.csv");
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.rows[0][0], "x, \"y\"");
  EXPECT_THROW(parse_csv("a,b\n1,2,3\n", "t.csv"), InputError);
  EXPECT_THROW(parse_csv("a,b\n\"1,2\n", "t.csv"), InputError);
}

TEST(CompareGlob, Wildcards) {
  EXPECT_TRUE(glob_match("*.csv", "runs.csv"));
  EXPECT_TRUE(glob_match("drift.*", "drift.energy"));
  EXPECT_TRUE(glob_match("a*b*c", "aXbYc"));
  EXPECT_FALSE(glob_match("a*b*c", "aXbY"));
  EXPECT_FALSE(glob_match("series.csv", "bar.csv"));
}

}  // namespace compare_test
}  // namespace mpmtb::compare
