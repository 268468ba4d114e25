// What the suites' plans share (suite.cpp, stability.cpp, speed_accuracy.cpp):
// a method (transfer x kernel x integrator), the filters of a request, the
// refinement series of the convergence and speed-accuracy suites, and the CSV
// tables they write.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "cases.hpp"
#include "runner.hpp"
#include "scene.hpp"
#include "suite.hpp"

namespace mpmtb::suite {

// A method of the suites: transfer x kernel x time integrator. Its runs live
// in runs/<case>/<name>/...; an explicit method keeps the folder it had before
// the integrators joined (transfer-kernel).
struct Method {
  std::string transfer, kernel, integrator = "explicit";
  bool is_explicit() const { return integrator == "explicit"; }
  std::string name() const {
    return transfer + "-" + kernel + (is_explicit() ? "" : "-" + integrator);
  }
};

// true when the filter is empty or names the value.
bool wanted(const std::vector<std::string>& filter, const std::string& name);

// Throws InputError naming the option and the allowed values for a filter
// value that names no transfer, kernel or integrator.
void check_filters(const SuiteRequest& r);

// Every registered transfer x kernel the registry accepts, with `integrator`,
// through the request's filters (none when the integrator filter leaves it
// out). For an implicit integrator only the transfers it accepts (a
// gradient-based one: core/stepper.hpp) and, where `transfers` or `kernels`
// are not empty, only those.
std::vector<Method> methods(const SuiteRequest& r, const std::string& integrator = "explicit",
                            const std::vector<std::string>& transfers = {},
                            const std::vector<std::string>& kernels = {});

// The integrators of the request that are implicit (every one when the filter is empty).
std::vector<std::string> implicit_integrators(const SuiteRequest& r);

// A case runs if it passes the filter and its scene is built in (a note otherwise).
bool runnable(const SuiteRequest& r, const std::string& name, const std::string& scene);

// A number for a table; NaN (missing, unstable) is an empty cell.
std::string num(double v);
double number_of(const nlohmann::json& j, const char* key);
double error_of(const RunResult& r, const std::string& key);
std::string int_text(const nlohmann::json& j, const char* key);

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  void write(const std::filesystem::path& path) const;  // atomically
};

// A case's scene overrides: dimension, cells and --set values.
Overrides overrides_for(int dim, int cells, const std::vector<std::string>& sets);

RunSpec make_spec(const std::string& case_name, const std::string& scene, int dim, const Method& m,
                  int cells, double t_end, const std::vector<std::string>& sets);

// One refinement series: a method on a case at one CFL, grid or time-step study.
struct Series {
  std::string case_name, study, error_key;
  Method method;
  double cfl = 0;                 // the grid study's CFL
  std::vector<std::size_t> runs;  // indices into the spec list, coarse to fine
  std::vector<double> h, dt;
};

// The grid study of `methods` on a case at `cfl` (and the time-step study when
// dt_study); `timed`: every run also times its stepping, alone (speed-accuracy).
// `levels`: the grids; `folder`: the series' folder below runs/<case>/<method>/
// (empty: the method's folder itself).
void plan_refinement(const SuiteRequest& r, const ConvergenceCase& c,
                     const std::vector<Method>& methods, const Levels& levels, double cfl,
                     bool dt_study, bool timed, const std::string& folder,
                     std::vector<RunSpec>& specs, std::vector<Series>& series);

}  // namespace mpmtb::suite
