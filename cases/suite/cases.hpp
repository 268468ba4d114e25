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
