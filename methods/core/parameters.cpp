#include "parameters.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "errors.hpp"

namespace mpmtb {

Range Range::any() {
  return {[](Real v) { return std::isfinite(v); }, "any finite number"};
}
Range Range::positive() {
  return {[](Real v) { return std::isfinite(v) && v > 0; }, "> 0"};
}
Range Range::non_negative() {
  return {[](Real v) { return std::isfinite(v) && v >= 0; }, ">= 0"};
}
Range Range::open(Real lo, Real hi) {
  return {[=](Real v) { return v > lo && v < hi; }, fmt::format("in ({}, {})", lo, hi)};
}
Range Range::closed(Real lo, Real hi) {
  return {[=](Real v) { return v >= lo && v <= hi; }, fmt::format("in [{}, {}]", lo, hi)};
}
Range Range::half_open(Real lo, Real hi) {
  return {[=](Real v) { return v >= lo && v < hi; }, fmt::format("in [{}, {})", lo, hi)};
}

Parameters::Parameters(std::string context, std::map<std::string, Real> values)
    : context_(std::move(context)), values_(std::move(values)) {}

Real Parameters::checked(const std::string& key, Real value, const Range& range) const {
  if (!range.ok(value)) {
    throw InputError(
        fmt::format("{}.{} = {} is out of range: must be {}", context_, key, value, range.text));
  }
  return value;
}

Real Parameters::required(const std::string& key, const Range& range) {
  asked_.insert(key);
  const auto it = values_.find(key);
  if (it == values_.end()) {
    throw InputError(
        fmt::format("{}: missing required parameter '{}' ({})", context_, key, range.text));
  }
  read_[key] = {it->second, range.text, false};
  return checked(key, it->second, range);
}

Real Parameters::optional(const std::string& key, Real fallback, const Range& range) {
  asked_.insert(key);
  const auto it = values_.find(key);
  const bool defaulted = it == values_.end();
  read_[key] = {defaulted ? fallback : it->second, range.text, defaulted};
  return checked(key, defaulted ? fallback : it->second, range);
}

void Parameters::reject_unknown() const {
  for (const auto& [key, value] : values_) {
    if (!asked_.count(key)) {
      throw InputError(fmt::format("{}: unknown parameter '{}'; allowed: {}", context_, key,
                                   fmt::join(asked_, ", ")));
    }
  }
}

}  // namespace mpmtb
