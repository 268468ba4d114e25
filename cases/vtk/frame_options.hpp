// When a run writes particle frames (cases/vtk/frames.hpp).
#pragma once

namespace mpmtb {

struct FrameOptions {
  long every = 0;       // steps between frames; 0: off
  double interval = 0;  // time between frames; 0: off
  bool grid = false;    // also write the grid (mass, velocity) as .vti
  bool enabled() const { return every > 0 || interval > 0; }
};

}  // namespace mpmtb
