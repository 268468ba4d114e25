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

#include "core/combinations.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "kernels/all.hpp"
#include "models/registry.hpp"
#include "support/combinations.hpp"
#include "transfers/all.hpp"

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

// Every compiled (dimension, transfer, kernel) has its conformance tests; the
// transfers that claim angular momentum conservation also have those checks.
// A combination this build does not compile (MPMTB_COMBINATIONS=reduced) has
// none: the generator leaves it out rather than letting it fail.
TEST(Registry, EveryCombinationJoinsTheConformanceTests) {
  const auto tests = registered_tests();
  int combinations = 0;
  for (int dim : {1, 2, 3}) {
    for (const auto& t : transfer_list()) {
      for (const auto& k : kernel_list()) {
        if (!unsupported_reason(t.name, k.name).empty()) continue;
        const bool compiled = compiled_combination(t.name, k.name);
        combinations += compiled;
        const std::string id = std::to_string(dim) + "d_" + t.name + "_" + k.name;
        for (const char* test : {"AllCombinations/TransferTest.G2PConservesMomentum/",
                                 "AllCombinations/StepTest.P2GConservesMass/",
                                 "AllCombinations/StepTest.FreeFlightConservesMomentum/"})
          EXPECT_EQ(tests.count(test + id) > 0, compiled) << test << id;
        if (t.conserves_angular_momentum && dim >= 2) {
          const std::string test = "AffineCombinations/AffineTransferTest.";
          EXPECT_EQ(tests.count(test + "AngularMomentumConservedBothWays/" + id) > 0, compiled)
              << id;
          EXPECT_EQ(tests.count(test + "AffineFieldRoundTripIsExact/" + id) > 0, compiled) << id;
        }
      }
    }
  }
  EXPECT_GE(combinations, 3 * static_cast<int>(transfer_list().size()));
}

// The query the registry answers is the predicate the solvers are compiled by
// (core/combinations.hpp), and the set keeps what it promises: every transfer
// runs (with the quadratic B-spline), and every kernel runs with a transfer that
// keeps v_old (its force scattered apart) and one that does not. The default
// build compiles every supported combination, a reduced one fewer.
TEST(Registry, CompiledCombinationsCoverEveryTransferAndKernel) {
  int supported = 0, compiled = 0;
  AllTransfers::for_each([&]<class T>() {
    AllKernels::for_each([&]<class K>() {
      EXPECT_EQ(compiled_combination(T::name, K::name), (kCompiled<T, K>))
          << T::name << " " << K::name;
      supported += T::template supports<K>;
      compiled += kCompiled<T, K>;
    });
    EXPECT_TRUE((kCompiled<T, QuadraticKernel>)) << T::name;
  });
  AllKernels::for_each([&]<class K>() {
    bool keeps_v_old = false, does_not = false;
    AllTransfers::for_each([&]<class T>() {
      if constexpr (kCompiled<T, K>) (T::needs_old_velocity ? keeps_v_old : does_not) = true;
    });
    EXPECT_TRUE(keeps_v_old) << K::name << ": no compiled transfer keeps v_old";
    EXPECT_TRUE(does_not) << K::name << ": every compiled transfer keeps v_old";
  });
  if (kReducedCombinations) {
    EXPECT_LT(compiled, supported);
  } else {
    EXPECT_EQ(compiled, supported);
  }
}

// make_stepper resolves every compiled combination, in every dimension.
TEST(Registry, EveryCompiledCombinationMakesAStepper) {
  int made = 0;
  for (const auto& t : transfer_list()) {
    for (const auto& k : kernel_list()) {
      if (!unsupported_reason(t.name, k.name).empty() || !compiled_combination(t.name, k.name))
        continue;
      Parameters p1(t.name), p2(t.name), p3(t.name);
      EXPECT_NE(make_stepper<1>(t.name, k.name, p1), nullptr) << t.name << " " << k.name;
      EXPECT_NE(make_stepper<2>(t.name, k.name, p2), nullptr) << t.name << " " << k.name;
      EXPECT_NE(make_stepper<3>(t.name, k.name, p3), nullptr) << t.name << " " << k.name;
      ++made;
    }
  }
  EXPECT_GE(made, static_cast<int>(transfer_list().size()));
}

// In a reduced build a supported combination that is not compiled is an input
// error that names the field, the build option and the kernels that are
// compiled for the transfer, not a null stepper or a link error.
TEST(Registry, UncompiledCombinationIsRefusedWithTheCompiledKernels) {
  if (!kReducedCombinations) GTEST_SKIP() << "every supported combination is compiled";
  std::string transfer, kernel;
  for (const auto& t : transfer_list()) {
    for (const auto& k : kernel_list()) {
      if (transfer.empty() && unsupported_reason(t.name, k.name).empty() &&
          !compiled_combination(t.name, k.name)) {
        transfer = t.name;
        kernel = k.name;
      }
    }
  }
  ASSERT_FALSE(transfer.empty()) << "a reduced build compiles every supported combination";
  std::string compiled;
  for (const auto& k : kernel_list()) {
    if (compiled_combination(transfer, k.name)) compiled += (compiled.empty() ? "" : ", ") + k.name;
  }
  ASSERT_FALSE(compiled.empty());
  Parameters params(transfer);
  try {
    make_stepper<2>(transfer, kernel, params);
    ADD_FAILURE() << transfer << " with " << kernel << " was made";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& part :
         {std::string("method.kernel"), "'" + transfer + "'", "'" + kernel + "'",
          std::string("not compiled in this build (MPMTB_COMBINATIONS=reduced)"),
          "kernels compiled for '" + transfer + "': " + compiled})
      EXPECT_NE(what.find(part), std::string::npos) << part << " not in: " << what;
  }
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
