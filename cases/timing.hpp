// Timings worth plotting (issue 22): the stepping of a run measured again,
// without output, on a fresh state each pass.
//
// One repetition repeats the whole run (set-up excluded: build the state, then
// time every step to t_end) until its stepping has lasted at least
// `min_seconds` of wall time, so that a run of a few milliseconds is timed over
// many passes and the clock's resolution and start-up effects vanish. It keeps
// the seconds per pass (wall and CPU) and the particle-steps per second. The
// summary's `timing` holds every repetition and their median, min and max: the
// median is the point of a work-precision diagram, min and max its error bar.
// Run the repetitions alone (a suite runs its timed runs one at a time): two
// runs side by side on the same cores time each other's contention.
#pragma once

#include <nlohmann/json.hpp>

#include "scene.hpp"

namespace mpmtb {

struct TimingOptions {
  int repeats = 0;           // 0: no timing pass
  double min_seconds = 0.5;  // stepping time of each repetition, at least
};

// Times `scene` as described above; the run must have been stable (a pass that
// fails throws std::runtime_error). Threads: the caller's OpenMP setting.
nlohmann::json time_stepping(const Scene& scene, const TimingOptions& options);

// The median of values (the mean of the middle two for an even count); NaN if empty.
double median(std::vector<double> values);

}  // namespace mpmtb
