// The rules of `mpmtb compare`: which files are compared, how CSV rows pair up,
// and the tolerance of each metric (cases/compare/tolerances.toml documents them).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mpmtb::compare {

// '*' matches any run of characters (including none); everything else literally.
bool glob_match(std::string_view pattern, std::string_view text);

enum class RuleKind { kNumeric, kExact, kTiming, kIgnore };

struct Rule {
  RuleKind kind = RuleKind::kNumeric;
  double rel = 0;  // numeric: |new - old| <= max(rel max(|old|, |new|), abs)
  double abs = 0;
};

class Tolerances {
 public:
  // Parses the TOML text; `source` names it in error messages.
  static Tolerances parse(const std::string& text, const std::string& source);
  static Tolerances load(const std::filesystem::path& file);
  // The built-in copy of cases/compare/tolerances.toml.
  static Tolerances builtin();

  Rule rule(std::string_view metric) const;
  // Whether a file (by its name) is one that compare pairs and compares.
  bool compared_file(std::string_view file_name) const;
  const std::vector<std::string>& csv_keys() const { return csv_keys_; }

 private:
  struct MetricRule {
    std::string pattern;
    Rule rule;
  };
  std::vector<std::string> include_, exclude_, csv_keys_, ignore_, timing_, exact_;
  std::vector<MetricRule> metrics_;
  Rule default_;
};

}  // namespace mpmtb::compare
