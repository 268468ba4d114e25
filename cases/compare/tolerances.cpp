#include "compare/tolerances.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace mpmtb::compare {

// Generated from cases/compare/tolerances.toml by cases/CMakeLists.txt.
extern const char* const kBuiltinTolerances;

namespace {

std::vector<std::string> strings(const toml::table& t, const char* key, const std::string& where) {
  std::vector<std::string> out;
  const toml::node* n = t.get(key);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a) throw InputError(fmt::format("{}: {} must be an array of strings", where, key));
  for (const auto& e : *a) {
    if (!e.is_string()) throw InputError(fmt::format("{}: {} must hold strings", where, key));
    out.push_back(*e.value<std::string>());
  }
  return out;
}

Rule numeric(const toml::table& t, const std::string& where, const Rule& fallback) {
  Rule r = fallback;
  for (auto [key, value] : {std::pair{"rel", &r.rel}, std::pair{"abs", &r.abs}}) {
    const toml::node* n = t.get(key);
    if (!n) continue;
    const auto v = n->value<double>();
    if (!v || *v < 0) {
      throw InputError(fmt::format("{}.{}: a number >= 0 is required", where, key));
    }
    *value = *v;
  }
  return r;
}

bool matches(const std::vector<std::string>& patterns, std::string_view metric) {
  const auto dot = metric.rfind('.');
  const std::string_view last = dot == std::string_view::npos ? metric : metric.substr(dot + 1);
  for (const auto& p : patterns) {
    if (glob_match(p, metric) || glob_match(p, last)) return true;
  }
  return false;
}

}  // namespace

bool glob_match(std::string_view pattern, std::string_view text) {
  // Iterative wildcard match with backtracking to the last '*'.
  std::size_t p = 0, t = 0, star = std::string_view::npos, mark = 0;
  while (t < text.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = t;
    } else if (p < pattern.size() && pattern[p] == text[t]) {
      ++p;
      ++t;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      t = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

Tolerances Tolerances::parse(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: malformed TOML: {}", source, e.description()));
  }
  Tolerances t;
  const toml::table empty;
  auto table = [&](const char* key) -> const toml::table& {
    const toml::node* n = root.get(key);
    if (n && !n->is_table()) throw InputError(fmt::format("{}: [{}] must be a table", source, key));
    return n ? *n->as_table() : empty;
  };
  t.include_ = strings(table("files"), "include", source + ": files");
  t.exclude_ = strings(table("files"), "exclude", source + ": files");
  t.csv_keys_ = strings(table("csv"), "keys", source + ": csv");
  const toml::table& d = table("default");
  t.default_ = numeric(d, source + ": default", Rule{RuleKind::kNumeric, 1e-9, 0});
  t.ignore_ = strings(d, "ignore", source + ": default");
  t.timing_ = strings(d, "timing", source + ": default");
  t.exact_ = strings(d, "exact", source + ": default");
  if (const toml::node* m = root.get("metric")) {
    const toml::array* a = m->as_array();
    if (!a) throw InputError(fmt::format("{}: metric must be an array of tables", source));
    for (const auto& e : *a) {
      const std::string where = fmt::format("{}: metric[{}]", source, t.metrics_.size());
      const toml::table* mt = e.as_table();
      const auto pattern = mt ? mt->get("match") : nullptr;
      if (!pattern || !pattern->is_string()) {
        throw InputError(fmt::format("{}: a table with `match = \"PATTERN\"` is required", where));
      }
      t.metrics_.push_back({*pattern->value<std::string>(), numeric(*mt, where, t.default_)});
    }
  }
  if (t.include_.empty()) throw InputError(fmt::format("{}: files.include is empty", source));
  return t;
}

Tolerances Tolerances::load(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot read the tolerance file", file.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return parse(text.str(), file.string());
}

Tolerances Tolerances::builtin() {
  return parse(kBuiltinTolerances, "cases/compare/tolerances.toml (built in)");
}

Rule Tolerances::rule(std::string_view metric) const {
  if (matches(ignore_, metric)) return {RuleKind::kIgnore};
  if (matches(timing_, metric)) return {RuleKind::kTiming};
  if (matches(exact_, metric)) return {RuleKind::kExact};
  for (const auto& m : metrics_) {
    if (matches({m.pattern}, metric)) return m.rule;
  }
  return default_;
}

bool Tolerances::compared_file(std::string_view file_name) const {
  auto any = [&](const std::vector<std::string>& patterns) {
    for (const auto& p : patterns) {
      if (glob_match(p, file_name)) return true;
    }
    return false;
  };
  return any(include_) && !any(exclude_);
}

}  // namespace mpmtb::compare
