// One updating progress line on a terminal: label, percent, steps per second
// and the estimated time left, redrawn in place (carriage return) at most ten
// times a second and cleared at the end. It draws nothing unless enabled, and
// `Progress::wanted(quiet)` enables it only when stderr is a terminal and not
// quiet, so logs and pipes (CI) stay clean.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace mpmtb {

class Progress {
 public:
  // True when stderr is a terminal and the user did not ask for quiet.
  static bool wanted(bool quiet);

  Progress(std::string label, bool enabled, std::FILE* stream = stderr);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // fraction: of the work done, in [0, 1]; steps: done so far.
  void update(double fraction, long steps);
  // Clears the line (once); later updates draw nothing.
  void finish();
  // The line as it would be drawn, without control characters.
  static std::string format_line(const std::string& label, double fraction, double steps_per_second,
                                 double seconds_left);

 private:
  using Clock = std::chrono::steady_clock;
  std::string label_;
  bool enabled_;
  std::FILE* stream_;
  Clock::time_point start_, last_draw_;
  bool drawn_ = false;
};

}  // namespace mpmtb
