// Turns a validated scene into the initial simulation state.
#pragma once

#include "core/state.hpp"
#include "scene.hpp"

namespace mpmtb {

// The grid covering the domain: dx = length / cells, each axis rounded up to a
// whole number of cells from domain.min.
template <int Dim>
GridGeometry<Dim> scene_grid(const Scene& scene);

// Seeds ppc^Dim particles per cell on a regular lattice inside each body (a
// point belongs to the first body that contains it), with m_p = rho V0_p and
// v_p = v + omega x (x_p - c); builds materials, walls, gravity and pins.
template <int Dim>
State<Dim> build_state(const Scene& scene);

// Largest wave speed c_p of the scene's materials, in its own dimension (the
// CFL time step of the suites' fixed-dt studies and their cost estimates).
double max_wave_speed(const Scene& scene);

}  // namespace mpmtb
