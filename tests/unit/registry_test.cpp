// The third user job (methods/README.md): a variant registered by its one line
// reaches the command line and every conformance test, with no list to edit.
// These tests fail when a test hard-codes the variants it covers, or when the
// program's `list` misses what the registries hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include "core/registry.hpp"
#include "kernels/all.hpp"
#include "models/registry.hpp"
#include "support/combinations.hpp"

namespace mpmtb {
namespace registry_test {

// Standard output of `mpmtb ARGS`.
std::string cli_stdout(const std::string& args) {
  const std::string command = std::string(MPMTB_CLI) + " " + args;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  std::string out;
  if (!pipe) return out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe.get())) > 0;)
    out.append(buffer, n);
  return out;
}

std::set<std::string> lines_of(const std::string& text) {
  std::set<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.insert(line);
  return lines;
}

template <class Infos>
std::set<std::string> names_of(const Infos& infos) {
  std::set<std::string> names;
  for (const auto& info : infos) names.insert(info.name);
  return names;
}

TEST(Registry, ListShowsExactlyTheRegisteredVariants) {
  EXPECT_EQ(lines_of(cli_stdout("list transfers")), names_of(transfer_list()));
  EXPECT_EQ(lines_of(cli_stdout("list kernels")), names_of(kernel_list()));
  EXPECT_EQ(lines_of(cli_stdout("list models")), names_of(model_list()));
}

// The full listing gives each variant a description (its paper), not just a name.
TEST(Registry, EveryVariantHasADescription) {
  for (const auto& v : transfer_list()) EXPECT_FALSE(v.description.empty()) << v.name;
  for (const auto& v : kernel_list()) EXPECT_FALSE(v.description.empty()) << v.name;
  for (const auto& v : model_list()) EXPECT_FALSE(v.description.empty()) << v.name;
  const std::string full = cli_stdout("list");
  for (const auto& v : transfer_list()) EXPECT_NE(full.find(v.description), std::string::npos);
}

// Names of the tests gtest has registered in this program.
std::set<std::string> registered_tests() {
  std::set<std::string> names;
  const auto& unit = *::testing::UnitTest::GetInstance();
  for (int s = 0; s < unit.total_test_suite_count(); ++s) {
    const auto& suite = *unit.GetTestSuite(s);
    for (int t = 0; t < suite.total_test_count(); ++t)
      names.insert(std::string(suite.name()) + "." + suite.GetTestInfo(t)->name());
  }
  return names;
}

// Every supported (dimension, transfer, kernel) has its conformance tests; the
// transfers that claim angular momentum conservation also have those checks.
TEST(Registry, EveryCombinationJoinsTheConformanceTests) {
  const auto tests = registered_tests();
  int combinations = 0;
  for (int dim : {1, 2, 3}) {
    for (const auto& t : transfer_list()) {
      for (const auto& k : kernel_list()) {
        if (!unsupported_reason(t.name, k.name).empty()) continue;
        ++combinations;
        const std::string id = std::to_string(dim) + "d_" + t.name + "_" + k.name;
        for (const char* test : {"AllCombinations/TransferTest.G2PConservesMomentum/",
                                 "AllCombinations/StepTest.P2GConservesMass/",
                                 "AllCombinations/StepTest.FreeFlightConservesMomentum/"})
          EXPECT_TRUE(tests.count(test + id)) << test << id;
        if (t.conserves_angular_momentum && dim >= 2) {
          const std::string test = "AffineCombinations/AffineTransferTest.";
          EXPECT_TRUE(tests.count(test + "AngularMomentumConservedBothWays/" + id)) << id;
          EXPECT_TRUE(tests.count(test + "AffineFieldRoundTripIsExact/" + id)) << id;
        }
      }
    }
  }
  EXPECT_GE(combinations, 3 * static_cast<int>(transfer_list().size()));
}

// Every kernel is one instance of the typed kernel tests (KernelTest/0, /1, ...).
TEST(Registry, EveryKernelJoinsTheKernelTests) {
  const auto tests = registered_tests();
  for (std::size_t k = 0; k < kernel_list().size(); ++k) {
    const std::string test =
        "KernelTest/" + std::to_string(k) + ".ReproducesConstantAndLinearFields";
    EXPECT_TRUE(tests.count(test)) << test << " (" << kernel_list()[k].name << ")";
  }
  EXPECT_FALSE(tests.count("KernelTest/" + std::to_string(kernel_list().size()) +
                           ".ReproducesConstantAndLinearFields"));
}

// Every model in every dimension has its conformance tests (P = dpsi/dF, ...).
TEST(Registry, EveryModelJoinsTheModelTests) {
  const auto tests = registered_tests();
  for (const auto& m : model_list()) {
    std::string id = m.name;
    std::replace(id.begin(), id.end(), '-', '_');
    for (int dim : {1, 2, 3}) {
      const std::string suffix = "/" + id + "_" + std::to_string(dim) + "d";
      bool found = false;
      for (const auto& name : tests)
        found |= name.starts_with("Registered/ModelConformance.") && name.ends_with(suffix);
      EXPECT_TRUE(found) << m.name << " " << dim << "D";
    }
  }
}

}  // namespace registry_test
}  // namespace mpmtb
