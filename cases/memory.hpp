// Resource limits: the memory a run will need, estimated from the scene
// before anything is allocated, against what the machine has free, so that a
// request too large for the machine is refused with both figures instead of
// ending in std::bad_alloc (or the kernel's OOM killer) part way.
#pragma once

#include <optional>
#include <string>

#include "scene.hpp"
#include "vtk/frame_options.hpp"

namespace mpmtb {

struct MemoryEstimate {
  double particles = 0;  // how many the bodies will seed (lattice points inside them)
  double nodes = 0;      // grid nodes, ghost layers included
  double particle_bytes = 0, grid_bytes = 0, frame_bytes = 0;
  double total() const { return particle_bytes + grid_bytes + frame_bytes; }
};

MemoryEstimate estimate_memory(const Scene& scene, const FrameOptions& frames);

// MemAvailable of /proc/meminfo in bytes, or nothing where it cannot be read.
std::optional<double> available_memory();

// Throws InputError naming the estimate and the limit (max_memory bytes, or
// MemAvailable when max_memory is 0) when the run would not fit.
void check_memory(const Scene& scene, const FrameOptions& frames, double max_memory);

// "2000000", "512M", "64G", "1.5T" (powers of 1024) as bytes; throws
// InputError naming `option` for anything else.
double parse_bytes(const std::string& text, const std::string& option);

// 1.2 GiB, 340 MiB, ...
std::string format_bytes(double bytes);

}  // namespace mpmtb
