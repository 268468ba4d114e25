// A seeded random search over scene texts and `--set` assignments: the
// built-in scenes, mutated (spans deleted, TOML tokens and odd values inserted,
// lines duplicated and swapped, truncated) plus random assignments to real
// and garbled key paths. Every input must be accepted or rejected with an
// InputError naming the scene (support/scene_fuzz.hpp); the run is bounded by
// the number of inputs, MPMTB_FUZZ_INPUTS (default 20000), and is reproducible
// (fixed seed). tests/fuzz/scene_fuzz.cpp is the coverage-guided libFuzzer
// counterpart, built with clang.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "support/scene_fuzz.hpp"
#include "support/scenes.hpp"
#include "table_reader.hpp"

namespace mpmtb {
namespace scene_fuzz_test {

const std::vector<std::string> kTokens = {"[",
                                          "]",
                                          "[[bodies]]",
                                          "[grid]",
                                          "[time]",
                                          "[materials.x]",
                                          "=",
                                          "\"",
                                          "'",
                                          ".",
                                          ",",
                                          "\n",
                                          "#",
                                          "{",
                                          "}",
                                          "{a = 1}",
                                          "1e308",
                                          "-1e308",
                                          "1e-320",
                                          "-0",
                                          "nan",
                                          "inf",
                                          "-inf",
                                          "0",
                                          "-1",
                                          "2",
                                          "17",
                                          "0.5",
                                          "-0.99",
                                          "99999999999999999999",
                                          "2147483648",
                                          "true",
                                          "\"x\"",
                                          "\"\"",
                                          "[1, 2, 3, 4]",
                                          "[]",
                                          "[[]]",
                                          "[1, \"a\"]",
                                          "1979-05-27",
                                          "cells",
                                          "ppc",
                                          "dt",
                                          "cfl",
                                          "t_end",
                                          "shape",
                                          "material",
                                          "model",
                                          "E",
                                          "nu",
                                          "density",
                                          "min",
                                          "max",
                                          "center",
                                          "radius",
                                          "inner_radius",
                                          "kind",
                                          "mode",
                                          "v0",
                                          "dims",
                                          "dim",
                                          "\"ring\"",
                                          "\"sphere\"",
                                          "\"box\"",
                                          "\"mls\"",
                                          "\"cubic\"",
                                          "\"snow\"",
                                          "\"damage\"",
                                          "\xff",
                                          "\xc3\x28",
                                          "\t",
                                          "\r\n",
                                          "\\u0000"};

const std::vector<std::string> kValues = {"0",
                                          "1",
                                          "-1",
                                          "0.5",
                                          "1e308",
                                          "nan",
                                          "inf",
                                          "-inf",
                                          "3.5",
                                          "99999999999",
                                          "true",
                                          "x",
                                          "\"\"",
                                          "[]",
                                          "[1]",
                                          "[0,0]",
                                          "[1,2,3,4]",
                                          "[nan]",
                                          "{a=1}",
                                          "[[1]]",
                                          "\"quadratic\"",
                                          "\"pic\"",
                                          "\"flip\"",
                                          "\"neo-hookean\"",
                                          "\"fixed-corotated\"",
                                          "\"sphere\"",
                                          "\"ring\"",
                                          "\"slip\"",
                                          "\"free\"",
                                          "16",
                                          "2",
                                          "0.001",
                                          "1e-300",
                                          "'lit'",
                                          "[0.1, 0.2, 0.3]"};

// Every dotted path of the tree, arrays by index ("bodies.0.center").
void collect_paths(const toml::node& node, const std::string& prefix,
                   std::vector<std::string>& out) {
  if (const auto* t = node.as_table()) {
    for (const auto& [k, v] : *t) {
      const std::string path =
          prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      out.push_back(path);
      collect_paths(v, path, out);
    }
  } else if (const auto* a = node.as_array()) {
    for (std::size_t i = 0; i < a->size(); ++i) {
      out.push_back(prefix + "." + std::to_string(i));
      collect_paths(*a->get(i), prefix + "." + std::to_string(i), out);
    }
  }
}

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : rng_(seed) {}

  std::size_t below(std::size_t n) {
    return n ? std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_) : 0;
  }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[below(v.size())];
  }

  std::string mutate_text(std::string text) {
    const int edits = 1 + static_cast<int>(below(4));
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const std::size_t at = below(text.size() + 1);
      switch (below(6)) {
        case 0:  // delete a span
          text.erase(std::min(at, text.size()), 1 + below(40));
          break;
        case 1:  // insert a token
        case 2:
          text.insert(std::min(at, text.size()), pick(kTokens));
          break;
        case 3: {  // duplicate a line
          const auto lines = split_lines(text);
          text += pick(lines) + "\n";
          break;
        }
        case 4: {  // swap two lines
          auto lines = split_lines(text);
          std::swap(lines[below(lines.size())], lines[below(lines.size())]);
          text = join_lines(lines);
          break;
        }
        default:  // truncate
          text.resize(at);
      }
    }
    return text;
  }

  std::vector<std::string> assignments(const std::vector<std::string>& paths) {
    std::vector<std::string> set;
    const std::size_t n = below(4);
    for (std::size_t i = 0; i < n; ++i) {
      std::string path = pick(paths);
      switch (below(8)) {
        case 0:
          path += ".x";
          break;
        case 1:
          path += "..y";
          break;
        case 2:
          path = "bodies.9." + pick(kTokens);
          break;
        case 3:
          path = pick(kTokens);
          break;
        default:
          break;
      }
      switch (below(10)) {
        case 0:
          set.push_back(path);  // no '='
          break;
        case 1:
          set.push_back("=" + pick(kValues));
          break;
        default:
          set.push_back(path + "=" + pick(kValues));
      }
    }
    return set;
  }

 private:
  static std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::stringstream ss(text);
    for (std::string l; std::getline(ss, l);) lines.push_back(l);
    if (lines.empty()) lines.push_back("");
    return lines;
  }
  static std::string join_lines(const std::vector<std::string>& lines) {
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
  }
  std::mt19937_64 rng_;
};

long fuzz_inputs() {
  const char* env = std::getenv("MPMTB_FUZZ_INPUTS");
  return env ? std::atol(env) : 20000;
}

TEST(SceneFuzz, EveryInputIsAcceptedOrRejectedWithAMessage) {
  std::vector<std::string> texts;
  for (const auto& b : builtin_scenes()) texts.push_back(b.text);
  texts.push_back(testing::free_body_toml(2, "flip", "cubic", "[flip]\nalpha = 0.95\n"));
  std::vector<std::vector<std::string>> paths;
  for (const auto& t : texts) {
    paths.emplace_back();
    collect_paths(parse_scene_text(t, "seed"), "", paths.back());
  }

  Mutator m(20261125);
  const long inputs = fuzz_inputs();
  long accepted = 0, rejected = 0;
  for (long i = 0; i < inputs; ++i) {
    const std::size_t k = m.below(texts.size());
    // A quarter keep the text and vary only the assignments.
    const std::string text = m.below(4) == 0 ? texts[k] : m.mutate_text(texts[k]);
    const auto set = m.assignments(paths[k]);
    try {
      const testing::FuzzVerdict v = testing::check_scene_input(text, set);
      (v.accepted ? accepted : rejected) += 1;
      if (!v.accepted) {
        ASSERT_GT(v.message.size(), std::string("fuzz.toml: ").size());
      }
    } catch (const std::exception& e) {
      std::string sets;
      for (const auto& s : set) sets += "  --set " + s + "\n";
      FAIL() << "input " << i << " threw " << e.what() << "\n--- text ---\n"
             << text << "\n--- assignments ---\n"
             << sets;
    }
  }
  std::printf("scene fuzz: %ld inputs, %ld accepted, %ld rejected\n", inputs, accepted, rejected);
  // Both outcomes are exercised, so the check means something.
  EXPECT_GT(accepted, inputs / 20);
  EXPECT_GT(rejected, inputs / 5);
}

// Found by libFuzzer (scripts/fuzz.sh): an integer beyond 2^53, which a double
// cannot hold exactly, ended the program (std::bad_optional_access) as a
// material parameter and as a number field. It is read at the nearest double,
// as the same number with a decimal point is.
TEST(SceneFuzz, IntegersBeyondTwoToThe53AreReadAsTheNearestDouble) {
  const std::string text = testing::free_body_toml(2, "flip", "linear", "");
  const testing::FuzzVerdict v =
      testing::check_scene_input(text, {"materials.jelly.E=39647841760435743"});
  EXPECT_TRUE(v.accepted) << v.message;
  // A number field (TableReader::number): accepted or refused with a message, never a crash.
  EXPECT_NO_THROW(testing::check_scene_input(text, {"time.t_end=9007199254740993"}));
  // The value read by each numeric reader is the nearest double, which the
  // compiler's rounding of the same literal with a decimal point gives
  // independently (2^53 + 1 rounds to 2^53, ties to even).
  const toml::table table =
      toml::parse("E = 39647841760435743\nv = [9007199254740993, 2]\nk = -39647841760435743\n");
  TableReader reader(table, "t");
  EXPECT_EQ(reader.number("E", Range::any()), static_cast<Real>(39647841760435743.0));
  EXPECT_EQ(reader.vec3("v")[0], static_cast<Real>(9007199254740992.0));
  EXPECT_EQ(reader.numbers_as_parameters({"E", "v"}).values().at("k"),
            static_cast<Real>(-39647841760435743.0));
}

}  // namespace scene_fuzz_test
}  // namespace mpmtb
