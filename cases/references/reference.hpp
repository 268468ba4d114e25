// Analytic references: a scene may name one in [reference]. It sets the initial
// condition it describes, adds its columns to series.csv and reports error
// norms in summary.json. Adding one: its files + one line in reference.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "core/diagnostics.hpp"

namespace mpmtb {

struct Scene;

template <int Dim>
class Reference {
 public:
  virtual ~Reference() = default;
  // Sets the initial state the reference describes (e.g. a mode's velocity field).
  virtual void initialize(State<Dim>& s) = 0;
  // Names of the extra series.csv columns.
  virtual std::vector<std::string> columns() const = 0;
  // Values of those columns at the current state; accumulates the error norms.
  virtual std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) = 0;
  // Error norms over the samples so far (the summary's "error" object).
  virtual nlohmann::json errors() const = 0;
  // Measured and exact characteristic values (the summary's "measured" object).
  virtual nlohmann::json measured() const { return nlohmann::json::object(); }
  // What sample() has accumulated so far, for a checkpoint: restore(saved()) on
  // a reference built and initialized from the same scene continues it as if
  // the run had not stopped (a resumed run reports the same error norms).
  virtual std::vector<Real> saved() const = 0;
  virtual void restore(const std::vector<Real>& values) = 0;
};

std::vector<std::string> reference_kinds();

// The scene's reference, or nullptr when it names none. Throws InputError.
template <int Dim>
std::unique_ptr<Reference<Dim>> make_reference(const Scene& scene);

}  // namespace mpmtb
