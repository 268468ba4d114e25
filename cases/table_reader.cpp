#include "table_reader.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <optional>

#include "core/errors.hpp"

namespace mpmtb {
namespace {

// A TOML number as a real. toml++'s value<double>() is empty for an integer
// that a double cannot hold exactly (beyond 2^53; the scene fuzz target found
// E = 39647841760435743 ending the program): such an integer is read at the
// nearest double, as the same number written with a decimal point would be.
std::optional<double> real_of(const toml::node& n) {
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  return n.value<double>();
}

}  // namespace

TableReader::TableReader(const toml::table& table, std::string path)
    : table_(table), path_(std::move(path)) {}

std::string TableReader::field(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

bool TableReader::has(const std::string& key) const {
  return table_.contains(key);
}

const toml::node& TableReader::node(const std::string& key) {
  asked_.insert(key);
  const toml::node* n = table_.get(key);
  if (!n) throw InputError(fmt::format("{}: missing required field", field(key)));
  return *n;
}

Real TableReader::number(const std::string& key, const Range& range) {
  const toml::node& n = node(key);
  if (!n.is_number()) {
    throw InputError(fmt::format("{}: expected a number ({})", field(key), range.text));
  }
  const Real v = *real_of(n);
  if (!std::isfinite(v)) {
    throw InputError(fmt::format("{} = {} is not allowed: the value must be finite ({})",
                                 field(key), v, range.text));
  }
  if (!range.ok(v)) {
    throw InputError(fmt::format("{} = {} is out of range: must be {}", field(key), v, range.text));
  }
  return v;
}

Real TableReader::number_or(const std::string& key, Real fallback, const Range& range) {
  asked_.insert(key);
  return has(key) ? number(key, range) : fallback;
}

int TableReader::integer(const std::string& key, int lo, int hi) {
  const toml::node& n = node(key);
  if (!n.is_integer()) {
    throw InputError(fmt::format("{}: expected an integer in [{}, {}]", field(key), lo, hi));
  }
  const auto v = n.value<std::int64_t>().value();
  if (v < lo || v > hi) {
    throw InputError(
        fmt::format("{} = {} is out of range: must be in [{}, {}]", field(key), v, lo, hi));
  }
  return static_cast<int>(v);
}

int TableReader::integer_or(const std::string& key, int fallback, int lo, int hi) {
  asked_.insert(key);
  return has(key) ? integer(key, lo, hi) : fallback;
}

bool TableReader::boolean_or(const std::string& key, bool fallback) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  const toml::node& n = node(key);
  if (!n.is_boolean()) throw InputError(fmt::format("{}: expected true or false", field(key)));
  return n.value<bool>().value();
}

std::string TableReader::string(const std::string& key) {
  const toml::node& n = node(key);
  if (!n.is_string()) throw InputError(fmt::format("{}: expected a string", field(key)));
  return n.value<std::string>().value();
}

std::string TableReader::string_or(const std::string& key, const std::string& fallback) {
  asked_.insert(key);
  return has(key) ? string(key) : fallback;
}

std::string TableReader::choice(const std::string& key, const std::vector<std::string>& allowed) {
  const std::string v = string(key);
  for (const auto& a : allowed) {
    if (a == v) return v;
  }
  throw InputError(
      fmt::format("{}: unknown value '{}'; allowed: {}", field(key), v, fmt::join(allowed, ", ")));
}

Vec3 TableReader::vec3(const std::string& key, Real fill) {
  const toml::node& n = node(key);
  const toml::array* a = n.as_array();
  if (!a || a->empty() || a->size() > 3) {
    throw InputError(fmt::format("{}: expected an array of 1 to 3 numbers", field(key)));
  }
  Vec3 v = Vec3::Constant(fill);
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto x = real_of((*a)[i]);
    if (!x || !std::isfinite(*x)) {
      throw InputError(fmt::format("{}[{}]: expected a finite number", field(key), i));
    }
    v[static_cast<int>(i)] = *x;
  }
  return v;
}

Vec3 TableReader::vec3_or(const std::string& key, const Vec3& fallback) {
  asked_.insert(key);
  return has(key) ? vec3(key) : fallback;
}

std::vector<int> TableReader::int_list(const std::string& key, int lo, int hi) {
  const toml::array* a = node(key).as_array();
  if (!a) throw InputError(fmt::format("{}: expected an array of integers", field(key)));
  std::vector<int> out;
  for (const auto& e : *a) {
    const auto* v = e.as_integer();  // never value<int64_t>(): it converts floats
    if (!v || v->get() < lo || v->get() > hi) {
      throw InputError(fmt::format("{}: expected integers in [{}, {}]", field(key), lo, hi));
    }
    out.push_back(static_cast<int>(v->get()));
  }
  return out;
}

const toml::table& TableReader::table(const std::string& key) {
  const toml::table* t = node(key).as_table();
  if (!t) throw InputError(fmt::format("{}: expected a table", field(key)));
  return *t;
}

const toml::table* TableReader::table_or_null(const std::string& key) {
  asked_.insert(key);
  return has(key) ? &table(key) : nullptr;
}

std::vector<const toml::table*> TableReader::table_array(const std::string& key) {
  const toml::array* a = node(key).as_array();
  std::vector<const toml::table*> out;
  if (a) {
    for (const auto& e : *a) out.push_back(e.as_table());
  }
  if (!a || a->empty() || std::count(out.begin(), out.end(), nullptr)) {
    throw InputError(fmt::format("{}: expected an array of tables ([[{}]])", field(key), key));
  }
  return out;
}

Parameters TableReader::numbers_as_parameters(const std::set<std::string>& skip) {
  std::map<std::string, Real> values;
  for (const auto& [k, v] : table_) {
    const std::string key(k.str());
    if (skip.count(key)) continue;
    asked_.insert(key);
    if (!v.is_number()) throw InputError(fmt::format("{}: expected a number", field(key)));
    values[key] = *real_of(v);
  }
  return Parameters(path_, std::move(values));
}

void TableReader::finish() const {
  for (const auto& [k, v] : table_) {
    const std::string key(k.str());
    if (!asked_.count(key)) {
      throw InputError(
          fmt::format("{}: unknown field; allowed here: {}", field(key), fmt::join(asked_, ", ")));
    }
  }
}

}  // namespace mpmtb
