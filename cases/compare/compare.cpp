#include "compare/compare.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "compare/csv.hpp"
#include "core/errors.hpp"

namespace mpmtb::compare {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One side of a compared value.
struct Value {
  bool present = false;
  std::optional<double> number;
  std::string text;
  double printed_ulp = 0;  // a CSV number: one unit in its last printed digit
};

// A CSV cell: a number when the whole cell reads as a finite one.
Value cell_value(const std::string& cell) {
  Value v{true, std::nullopt, cell};
  if (cell.empty()) return v;
  char* end = nullptr;
  const double x = std::strtod(cell.c_str(), &end);
  if (end != cell.c_str() + cell.size() || !std::isfinite(x)) return v;
  v.number = x;
  // 10^(exponent - digits after the point): "0.00338285" -> 1e-8, "1.8438e+06" -> 100.
  const auto e = cell.find_first_of("eE");
  const std::string mantissa = cell.substr(0, e);
  const auto point = mantissa.find('.');
  const long decimals =
      point == std::string::npos ? 0 : static_cast<long>(mantissa.size() - point - 1);
  const long exponent = e == std::string::npos ? 0 : std::strtol(cell.c_str() + e + 1, nullptr, 10);
  v.printed_ulp = std::pow(10.0, static_cast<double>(exponent - decimals));
  return v;
}

Value json_value(const nlohmann::json& j) {
  Value v;
  v.present = true;
  if (j.is_number()) v.number = j.get<double>();
  v.text = j.is_string() ? j.get<std::string>() : j.dump();
  return v;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot read the file", p.string()));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Comparer {
 public:
  Comparer(const Tolerances& t, Report& r) : tol_(t), report_(r) {}

  // `rule_name` selects the tolerance; `shown` is what the table prints.
  void leaf(const std::string& file, const std::string& rule_name, const std::string& shown,
            const Value& a, const Value& b) {
    const Rule rule = tol_.rule(rule_name);
    if (rule.kind == RuleKind::kIgnore) return;
    if (rule.kind == RuleKind::kTiming) {
      if (a.number && b.number) report_.timings.push_back({rule_name, *a.number, *b.number});
      return;
    }
    ++report_.values;
    Change c{file, shown,  a.present ? a.text : "(absent)", b.present ? b.text : "(absent)",
             kNaN, "exact"};
    if (a.number && b.number) {
      const double x = *a.number, y = *b.number;
      c.rel_diff = x != 0 ? (y - x) / std::abs(x) : (y == x ? 0 : kNaN);
      if (rule.kind == RuleKind::kExact) {
        if (x == y) return;
      } else {
        const double floor = std::max(a.printed_ulp, b.printed_ulp) * (1 + 1e-9);
        const double allowed =
            std::max({rule.rel * std::max(std::abs(x), std::abs(y)), rule.abs, floor});
        if (std::abs(y - x) <= allowed) return;
        c.tolerance = fmt::format("rel {:g} abs {:g}", rule.rel, rule.abs);
        if (floor > 0) c.tolerance += fmt::format(" printed {:g}", floor);
      }
    } else if (a.present == b.present && a.text == b.text) {
      return;
    }
    report_.changes.push_back(std::move(c));
  }

  void json(const std::string& file, const std::string& path, const nlohmann::json* a,
            const nlohmann::json* b) {
    // Containers of the same kind (or present on one side only) are walked.
    auto kind = [](const nlohmann::json* j) {
      return !j ? 0 : j->is_object() ? 1 : j->is_array() ? 2 : 3;
    };
    const int ka = kind(a), kb = kind(b), k = ka ? ka : kb;
    if (k == 1 && (ka == kb || !ka || !kb)) {
      std::set<std::string> keys;
      for (const auto* side : {a, b}) {
        if (side) {
          for (const auto& [key, v] : side->items()) keys.insert(key);
        }
      }
      for (const auto& key : keys) {
        json(file, path.empty() ? key : path + "." + key, child(a, key), child(b, key));
      }
      return;
    }
    if (k == 2 && (ka == kb || !ka || !kb)) {
      const std::size_t n = std::max(a ? a->size() : 0, b ? b->size() : 0);
      for (std::size_t i = 0; i < n; ++i) {
        const auto* x = a && i < a->size() ? &(*a)[i] : nullptr;
        const auto* y = b && i < b->size() ? &(*b)[i] : nullptr;
        json(file, fmt::format("{}.{}", path, i), x, y);
      }
      return;
    }
    leaf(file, path, path, a ? json_value(*a) : Value{}, b ? json_value(*b) : Value{});
  }

  void csv(const std::string& file, const CsvText& a, const CsvText& b) {
    const auto rows_a = keyed(a), rows_b = keyed(b);
    std::set<std::string> columns(a.header.begin(), a.header.end());
    columns.insert(b.header.begin(), b.header.end());
    for (const auto& [key, ra] : rows_a) {
      const auto it = rows_b.find(key);
      if (it == rows_b.end()) {
        leaf(file, "row", fmt::format("row {}", key), Value{true, {}, "present"}, Value{});
        continue;
      }
      for (const auto& col : columns) {
        leaf(file, col, fmt::format("{}: {}", key, col), cell(a, *ra, col),
             cell(b, *it->second, col));
      }
    }
    for (const auto& [key, rb] : rows_b) {
      if (!rows_a.count(key)) {
        leaf(file, "row", fmt::format("row {}", key), Value{}, Value{true, {}, "present"});
      }
    }
  }

 private:
  static const nlohmann::json* child(const nlohmann::json* j, const std::string& k) {
    return j && j->is_object() && j->contains(k) ? &(*j)[k] : nullptr;
  }

  static Value cell(const CsvText& t, const std::vector<std::string>& row, const std::string& col) {
    for (std::size_t i = 0; i < t.header.size(); ++i) {
      if (t.header[i] == col) return cell_value(row[i]);
    }
    return {};
  }

  // Rows by their key columns' values ("bar/grid/pic/linear/3"), repeats numbered.
  std::map<std::string, const std::vector<std::string>*> keyed(const CsvText& t) const {
    std::vector<std::size_t> key_columns;
    for (std::size_t i = 0; i < t.header.size(); ++i) {
      for (const auto& k : tol_.csv_keys()) {
        if (t.header[i] == k) key_columns.push_back(i);
      }
    }
    std::map<std::string, const std::vector<std::string>*> out;
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
      std::string key;
      for (std::size_t c : key_columns) key += (key.empty() ? "" : "/") + t.rows[r][c];
      if (key_columns.empty()) key = fmt::format("{}", r + 1);
      std::string unique = key;
      for (int n = 2; out.count(unique); ++n) unique = fmt::format("{}#{}", key, n);
      out[unique] = &t.rows[r];
    }
    return out;
  }

  const Tolerances& tol_;
  Report& report_;
};

std::set<std::string> compared_files(const fs::path& root, const Tolerances& t) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file() && t.compared_file(e.path().filename().string())) {
      out.insert(fs::relative(e.path(), root).generic_string());
    }
  }
  return out;
}

void compare_file(Comparer& c, const std::string& name, const fs::path& a, const fs::path& b) {
  const std::string ta = read_text(a), tb = read_text(b);
  if (a.extension() == ".json") {
    auto parse = [](const std::string& text, const fs::path& p) {
      try {
        return nlohmann::json::parse(text);
      } catch (const nlohmann::json::parse_error& e) {
        throw InputError(fmt::format("{}: malformed JSON: {}", p.string(), e.what()));
      }
    };
    const nlohmann::json ja = parse(ta, a), jb = parse(tb, b);
    c.json(name, "", &ja, &jb);
  } else {
    c.csv(name, parse_csv(ta, a.string()), parse_csv(tb, b.string()));
  }
}

}  // namespace

Report compare_paths(const fs::path& old_root, const fs::path& new_root,
                     const Tolerances& tolerances) {
  for (const auto& p : {old_root, new_root}) {
    if (!fs::exists(p)) throw InputError(fmt::format("{}: no such file or folder", p.string()));
  }
  Report report;
  Comparer comparer(tolerances, report);
  if (!fs::is_directory(old_root) || !fs::is_directory(new_root)) {
    if (fs::is_directory(old_root) != fs::is_directory(new_root)) {
      throw InputError(fmt::format("{} and {}: compare two folders or two files", old_root.string(),
                                   new_root.string()));
    }
    report.files = 1;
    compare_file(comparer, new_root.filename().string(), old_root, new_root);
    return report;
  }
  const auto a = compared_files(old_root, tolerances), b = compared_files(new_root, tolerances);
  for (const auto& f : a) {
    if (!b.count(f)) {
      report.only_old.push_back(f);
      continue;
    }
    ++report.files;
    compare_file(comparer, f, old_root / f, new_root / f);
  }
  for (const auto& f : b) {
    if (!a.count(f)) report.only_new.push_back(f);
  }
  return report;
}

}  // namespace mpmtb::compare
