// Named numeric parameters of a variant (a material's E, nu, density; a
// transfer's alpha), read with range checks. Keys that nobody asked for are
// rejected with the list of the allowed ones.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <string_view>

#include "types.hpp"

namespace mpmtb {

// A validity range with its description for error messages.
struct Range {
  std::function<bool(Real)> ok;
  std::string text;

  static Range any();
  static Range positive();
  static Range non_negative();
  static Range open(Real lo, Real hi);       // (lo, hi)
  static Range closed(Real lo, Real hi);     // [lo, hi]
  static Range half_open(Real lo, Real hi);  // [lo, hi)
};

class Parameters {
 public:
  // context: where the values come from, e.g. "materials.steel" (used in messages).
  explicit Parameters(std::string context = {}, std::map<std::string, Real> values = {});

  Real required(const std::string& key, const Range& range);
  Real optional(const std::string& key, Real fallback, const Range& range);
  // Throws InputError if a key was given that no reader asked for.
  void reject_unknown() const;

  // What the readers asked for: the value used, its allowed range, and whether
  // the value was the default (for `mpmtb describe`).
  struct Read {
    Real value = 0;
    std::string range;
    bool defaulted = false;
  };
  const std::map<std::string, Read>& read() const { return read_; }

  const std::string& context() const { return context_; }
  const std::map<std::string, Real>& values() const { return values_; }
  void set(const std::string& key, Real value) { values_[key] = value; }

 private:
  Real checked(const std::string& key, Real value, const Range& range) const;
  std::string context_;
  std::map<std::string, Real> values_;
  std::set<std::string> asked_;
  std::map<std::string, Read> read_;
};

}  // namespace mpmtb
