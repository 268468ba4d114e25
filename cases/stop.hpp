// Clean stops: SIGINT (Ctrl-C) and SIGTERM (what a batch system sends at its
// time limit) and an optional wall-clock limit end a run at the next step
// boundary, so that the run can flush its series, write a checkpoint and a
// summary with `status: interrupted` before it exits.
#pragma once

#include <optional>
#include <string>

namespace mpmtb {

struct StopRequest {
  std::string reason;  // e.g. "SIGTERM received"
  int exit_status;     // 128 + the signal (130, 143), or kWallLimitExit
};

// Exit status of a run stopped by --wall-limit: timeout(1)'s, so a batch script
// can tell it from a signal and from a finished run.
inline constexpr int kWallLimitExit = 124;

class StopWatch {
 public:
  // Installs the handlers of SIGINT and SIGTERM for the watch's lifetime;
  // wall_limit_seconds <= 0: no wall limit. Counts from construction.
  explicit StopWatch(double wall_limit_seconds = 0);
  ~StopWatch();
  StopWatch(const StopWatch&) = delete;
  StopWatch& operator=(const StopWatch&) = delete;

  // Why the run should stop now, or nothing. Cheap: a flag and a clock read.
  std::optional<StopRequest> due() const;

 private:
  double wall_limit_;
  double start_;  // steady-clock seconds at construction
};

// A stop asked by a signal since the last StopWatch was built (for a sweep:
// a stopped run stops the sweep too).
bool stop_signalled();

}  // namespace mpmtb
