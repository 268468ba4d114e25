#include "progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace mpmtb {

bool Progress::wanted(bool quiet) {
  return !quiet && ::isatty(::fileno(stderr)) == 1;
}

Progress::Progress(std::string label, bool enabled, std::FILE* stream)
    : label_(std::move(label)), enabled_(enabled), stream_(stream), start_(Clock::now()) {}

std::string Progress::format_line(const std::string& label, double fraction,
                                  double steps_per_second, double seconds_left) {
  std::string eta = "--:--";
  if (std::isfinite(seconds_left) && seconds_left >= 0) {
    const long s = std::lround(seconds_left);
    eta = s >= 3600 ? fmt::format("{}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60)
                    : fmt::format("{:02d}:{:02d}", s / 60, s % 60);
  }
  return fmt::format("{} {:5.1f}%  {:.0f} steps/s  {} left", label,
                     100 * std::clamp(fraction, 0.0, 1.0), steps_per_second, eta);
}

void Progress::update(double fraction, long steps) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? steps / elapsed : 0;
  const double left = fraction > 0 ? elapsed * (1 - fraction) / fraction : NAN;
  // \r returns to the line's start, ESC[K clears what an older, longer line left.
  fmt::print(stream_, "\r{}\x1b[K", format_line(label_, fraction, rate, left));
  std::fflush(stream_);
  drawn_ = true;
}

void Progress::finish() {
  if (enabled_ && drawn_) {
    fmt::print(stream_, "\r\x1b[K");
    std::fflush(stream_);
  }
  enabled_ = false;
}

}  // namespace mpmtb
