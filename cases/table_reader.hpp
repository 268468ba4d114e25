// Typed, checked access to one TOML table of a scene file. Every key read is
// remembered; finish() rejects any other key, naming it and the allowed ones.
#pragma once

#include <toml++/toml.h>

#include <set>
#include <string>
#include <vector>

#include "core/parameters.hpp"
#include "core/types.hpp"

namespace mpmtb {

class TableReader {
 public:
  // path: the table's dotted name in messages ("grid", "materials.steel").
  TableReader(const toml::table& table, std::string path);

  bool has(const std::string& key) const;
  Real number(const std::string& key, const Range& range);
  Real number_or(const std::string& key, Real fallback, const Range& range);
  int integer(const std::string& key, int lo, int hi);
  int integer_or(const std::string& key, int fallback, int lo, int hi);
  bool boolean_or(const std::string& key, bool fallback);
  std::string string(const std::string& key);
  std::string string_or(const std::string& key, const std::string& fallback);
  // A string restricted to `allowed`.
  std::string choice(const std::string& key, const std::vector<std::string>& allowed);
  // An array of 1 to 3 numbers; missing components are `fill`.
  Vec3 vec3(const std::string& key, Real fill = 0);
  Vec3 vec3_or(const std::string& key, const Vec3& fallback);
  std::vector<int> int_list(const std::string& key, int lo, int hi);
  // Sub-tables and arrays of tables (marked as read).
  const toml::table& table(const std::string& key);
  const toml::table* table_or_null(const std::string& key);
  std::vector<const toml::table*> table_array(const std::string& key);
  // Every numeric entry of this table as named parameters (for variant parameters).
  Parameters numbers_as_parameters(const std::set<std::string>& skip);

  void finish() const;
  std::string field(const std::string& key) const;  // "path.key"

 private:
  const toml::node& node(const std::string& key);
  const toml::table& table_;
  std::string path_;
  std::set<std::string> asked_;
};

}  // namespace mpmtb
