#include "memory.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/errors.hpp"
#include "core/grid.hpp"

namespace mpmtb {
namespace {

// Volume (length, area) of the unit ball in `dim` dimensions.
double unit_ball(int dim) {
  return dim == 1 ? 2 : dim == 2 ? std::numbers::pi : 4 * std::numbers::pi / 3;
}

// The body's measure inside the domain (boxes are clipped to it; a sphere is
// taken whole: an estimate, and bodies must lie inside the domain anyway).
double body_measure(const BodySpec& b, const Scene& scene) {
  if (b.shape == "box") {
    double v = 1;
    for (int a = 0; a < scene.dim; ++a) {
      const double lo = std::max<double>(b.min[a], scene.domain_min[a]);
      const double hi = std::min<double>(b.max[a], scene.domain_max[a]);
      v *= std::max(0.0, hi - lo);
    }
    return v;
  }
  const double outer = unit_ball(scene.dim) * std::pow(b.radius, scene.dim);
  const double inner =
      b.shape == "ring" ? unit_ball(scene.dim) * std::pow(b.inner_radius, scene.dim) : 0;
  return outer - inner;
}

}  // namespace

MemoryEstimate estimate_memory(const Scene& scene, const FrameOptions& frames) {
  const int d = scene.dim;
  const double dx = scene.dx(), h = dx / scene.ppc;
  MemoryEstimate e;
  for (const auto& b : scene.bodies) e.particles += body_measure(b, scene) / std::pow(h, d);
  e.nodes = 1;
  for (int a = 0; a < d; ++a) {
    const double cells = std::ceil((scene.domain_max[a] - scene.domain_min[a]) / dx - 1e-9);
    e.nodes *= std::max(1.0, cells) + 1 + 2 * GridGeometry<3>::pad;
  }
  const double real = sizeof(Real), vec = d * real, mat = d * d * real;
  // Per particle: x, v, C, F, m, V0, material, pinned (Particles), up to four
  // internal variables of a model, the stress V0 tau the solver keeps, its
  // block indices and the material index list.
  const double per_particle = 2 * vec + 2 * mat + 2 * real + 5 + 4 * real + mat + 4 * 4;
  // Per node: m, p, f, v, v_old, pinned (Grid), and the solver's sums and rows
  // (mass, momentum and force per node, twice) and velocity rows.
  const double per_node = real + 4 * vec + 1 + 2 * (real + 2 * vec) + vec;
  e.particle_bytes = e.particles * per_particle;
  e.grid_bytes = e.nodes * per_node;
  // A frame in flight: the point arrays (about 16 values per particle) and the
  // rendered file (about 110 bytes per particle), plus the grid image.
  if (frames.enabled()) {
    e.frame_bytes = e.particles * (16 * 8 + 110);
    if (frames.grid) e.frame_bytes += e.nodes * 2 * 4 * 8;
  }
  return e;
}

std::optional<double> available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  double value = 0;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemAvailable:") return value * 1024;  // the file counts kB (KiB)
  }
  return std::nullopt;
}

void check_memory(const Scene& scene, const FrameOptions& frames, double max_memory) {
  const MemoryEstimate e = estimate_memory(scene, frames);
  const std::optional<double> limit =
      max_memory > 0 ? std::optional<double>(max_memory) : available_memory();
  if (!limit || e.total() <= *limit) return;
  throw InputError(fmt::format(
      "the run needs about {} of memory ({:.3g} particles: {}, grid of {:.3g} nodes: {}{}) but "
      "{} {}; reduce grid.cells, grid.ppc or the domain, or give --max-memory SIZE to allow "
      "more",
      format_bytes(e.total()), e.particles, format_bytes(e.particle_bytes), e.nodes,
      format_bytes(e.grid_bytes),
      e.frame_bytes > 0 ? fmt::format(", frames: {}", format_bytes(e.frame_bytes)) : "",
      format_bytes(*limit),
      max_memory > 0 ? "is the limit set by --max-memory" : "is available (MemAvailable)"));
}

double parse_bytes(const std::string& text, const std::string& option) {
  std::istringstream in(text);
  double value = 0;
  std::string suffix;
  in >> value >> suffix;
  const std::string units = "KMGT";
  const auto at = suffix.size() == 1 ? units.find(suffix[0]) : std::string::npos;
  const bool ok = !in.fail() || in.eof();
  if (!ok || !std::isfinite(value) || value <= 0 || (!suffix.empty() && at == std::string::npos)) {
    throw InputError(fmt::format(
        "{} '{}': expected a size > 0 in bytes, optionally with K, M, G or T (powers of 1024), "
        "e.g. 512M or 64G",
        option, text));
  }
  return suffix.empty() ? value : value * std::pow(1024.0, static_cast<double>(at + 1));
}

std::string format_bytes(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024 && u < 6) bytes /= 1024, ++u;
  return fmt::format("{:.3g} {}", bytes, units[u]);
}

}  // namespace mpmtb
