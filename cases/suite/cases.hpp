// The cases each suite runs. Adding a case is one line in cases.cpp; a case
// whose scene is not built in is skipped with a note, so cases can be listed
// before their scene exists.
#pragma once

#include <string>
#include <vector>

namespace mpmtb::suite {

// Levels: cells = first * 2^k, k = 0 .. count-1.
struct Levels {
  int first = 8, count = 5;
  std::vector<int> cells() const;
};

// An implicit integrator (integrators/integrator.hpp) at a fixed CFL.
struct IntegratorStep {
  std::string integrator;  // backward-euler | newmark
  double cfl = 1;
};

// Convergence and speed-accuracy: refine grid and time step together at a
// fixed CFL; error = summary `error.<error_key>`.
struct ConvergenceCase {
  std::string name;   // table name, e.g. "bar", "mms_bar_large"
  std::string scene;  // built-in scene
  int dim = 1;
  std::string error_key;               // a key of the run summary's `error`
  std::vector<std::string> sets = {};  // --set overrides
  double cfl = 0.2;
  Levels quick = {}, full = {};
  double t_end_quick = 0, t_end_full = 0;  // 0: the scene's t_end
  // Time-step study at a fixed grid: cells (0: none) and the coarsest CFL.
  int dt_cells_quick = 0, dt_cells_full = 0;
  double dt_cfl = 0.5;
  // Speed-accuracy: the methods of the quick level (empty: every one); --full
  // runs every registered transfer x kernel.
  std::vector<std::string> quick_transfers = {}, quick_kernels = {};
  // Speed-accuracy, the implicit integrators (issue 19): each (integrator, CFL)
  // pair runs the quick level's grids for these transfers x kernels; --full adds
  // the full lists (the grids stay the quick ones: an implicit step on the full
  // level's finest grid costs minutes).
  std::vector<IntegratorStep> implicit_steps = {};
  std::vector<std::string> implicit_transfers = {}, implicit_kernels = {};
  std::vector<std::string> implicit_transfers_full = {}, implicit_kernels_full = {};
};

// Stability: a grid of CFL values for each particles-per-cell count.
struct StabilityCase {
  std::string name, scene;
  int dim = 1;
  std::vector<std::string> sets = {};
  int cells = 16;
  double t_end = 0;  // 0: the scene's
  std::vector<int> quick_ppc, full_ppc;
  double cfl_first = 0.1, cfl_last = 2.5, quick_step = 0.1, full_step = 0.025;
  // The implicit integrators (issue 19): their own CFL values, far beyond the
  // explicit limit, at implicit_ppc for these transfers x kernels (--full: at
  // every ppc of the full level, every method that takes the integrator).
  std::vector<std::string> implicit_transfers = {}, implicit_kernels = {};
  std::vector<double> implicit_cfl_quick = {}, implicit_cfl_full = {};
  int implicit_ppc = 2;
};

// Failure modes shown on purpose: one metric per case, every method.
//   strain_max_rel: max over time of the strain energy / initial energy
//                   (cell-crossing noise in rigid translation)
//   energy_kept:    total energy at the end / at the start (PIC dissipation)
//   L_change:       |L(end) - L(0)| / |L(0)| (PIC dissipation, FLIP noise)
struct FailureModeCase {
  std::string name, scene;
  int dim = 2;
  std::vector<std::string> sets = {};
  std::string metric;
  int cells = 0;     // 0: the scene's
  double t_end = 0;  // 0: the scene's
};

const std::vector<ConvergenceCase>& convergence_cases();
const std::vector<ConvergenceCase>& speed_accuracy_cases();
const std::vector<StabilityCase>& stability_cases();
const std::vector<FailureModeCase>& failure_mode_cases();

// The von Neumann estimate of the critical CFL in 1D for a kernel (lumped
// mass, symplectic Euler; shared/REFERENCE.md), divided by sqrt(dim).
struct CflEstimate {
  double low = 0, high = 0;
};
CflEstimate von_neumann_cfl(const std::string& kernel, int dim);

}  // namespace mpmtb::suite
