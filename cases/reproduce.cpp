#include "reproduce.hpp"

#include <fmt/format.h>

#include <fstream>

#include "core/errors.hpp"

namespace mpmtb {
namespace {

toml::array json_to_toml_array(const nlohmann::json& a);

template <class Insert>
void insert_value(const nlohmann::json& v, Insert&& insert) {
  if (v.is_object()) {
    insert(json_to_toml(v));
  } else if (v.is_array()) {
    insert(json_to_toml_array(v));
  } else if (v.is_boolean()) {
    insert(v.get<bool>());
  } else if (v.is_number_integer()) {
    insert(v.get<std::int64_t>());
  } else if (v.is_number()) {
    insert(v.get<double>());
  } else if (v.is_string()) {
    insert(v.get<std::string>());
  } else {
    throw InputError("config: null values are not allowed");
  }
}

toml::array json_to_toml_array(const nlohmann::json& a) {
  toml::array out;
  for (const auto& v : a) insert_value(v, [&](auto&& x) { out.push_back(std::move(x)); });
  return out;
}

}  // namespace

toml::table json_to_toml(const nlohmann::json& object) {
  toml::table out;
  for (const auto& item : object.items()) {
    const std::string key = item.key();  // named: clang 14 cannot capture a structured binding
    insert_value(item.value(), [&](auto&& x) { out.insert_or_assign(key, std::move(x)); });
  }
  return out;
}

nlohmann::json read_summary(const std::filesystem::path& summary) {
  std::ifstream in(summary);
  if (!in) throw InputError(fmt::format("--config: cannot read '{}'", summary.string()));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("--config: '{}' is not JSON: {}", summary.string(), e.what()));
  }
}

Scene load_recorded_scene(const nlohmann::json& summary, const std::string& source,
                          const Overrides& o) {
  if (!summary.contains("config") || !summary["config"].is_object()) {
    throw InputError(fmt::format(
        "--config: '{}' has no `config` table (allowed: a summary.json written by mpmtb run)",
        source));
  }
  toml::table tree = json_to_toml(summary["config"]);
  apply_overrides(tree, o);
  return read_scene(tree, source);
}

std::optional<int> recorded_threads(const nlohmann::json& summary) {
  if (summary.contains("threads") && summary["threads"].is_number_integer())
    return summary["threads"].get<int>();
  return std::nullopt;
}

}  // namespace mpmtb
