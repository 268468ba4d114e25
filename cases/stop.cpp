#include "stop.hpp"

#include <fmt/format.h>

#include <chrono>
#include <csignal>

namespace mpmtb {
namespace {

// The one place a signal handler can leave a note: a lock-free atomic flag
// (async-signal-safe). It holds the signal number, 0 for none.
volatile std::sig_atomic_t g_signal = 0;

extern "C" void note_signal(int sig) {
  g_signal = sig;
  // A second Ctrl-C while the run winds down ends the program at once, as
  // users expect; the files it writes are atomic, so nothing is left half done.
  std::signal(sig, SIG_DFL);
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

StopWatch::StopWatch(double wall_limit_seconds)
    : wall_limit_(wall_limit_seconds), start_(now_seconds()) {
  g_signal = 0;
  std::signal(SIGINT, note_signal);
  std::signal(SIGTERM, note_signal);
}

StopWatch::~StopWatch() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

std::optional<StopRequest> StopWatch::due() const {
  if (const int sig = g_signal) {
    return StopRequest{fmt::format("{} received", sig == SIGINT ? "SIGINT" : "SIGTERM"), 128 + sig};
  }
  if (wall_limit_ > 0 && now_seconds() - start_ >= wall_limit_) {
    return StopRequest{fmt::format("wall limit of {:g} s reached (--wall-limit)", wall_limit_),
                       kWallLimitExit};
  }
  return std::nullopt;
}

bool stop_signalled() {
  return g_signal != 0;
}

}  // namespace mpmtb
