// Conserved and monitored quantities of the particle state.
#pragma once

#include "core/stepper.hpp"

namespace mpmtb {

struct Diagnostics {
  Real mass = 0;
  Real kinetic = 0;              // sum m_p |v_p|^2 / 2
  Real strain = 0;               // sum V0_p psi(F_p)
  Real gravity = 0;              // -sum m_p g . x_p
  Real dissipated = 0;           // energy removed by plastic and damage return maps so far
  Real total = 0;                // kinetic + strain + gravity + dissipated: the conserved budget
  Vec3 momentum = Vec3::Zero();  // sum m_p v_p
  Vec3 angular_momentum = Vec3::Zero();  // sum x_p x m_p v_p + affine part
  Real volume = 0;                       // sum V0_p J_p
  Real J_min = 1, J_max = 1;
  Vec3 center_of_mass = Vec3::Zero();
  Vec3 center_of_mass_velocity = Vec3::Zero();
};

// Sums in particle order, so the result is deterministic.
template <int Dim>
Diagnostics measure(const State<Dim>& s, const Stepper<Dim>& stepper);

// The same quantities measured on the grid, to check each transfer direction:
// after P2G, mass sum m_i, momentum sum p_i and angular momentum sum x_i x p_i
// (before forces); after the grid update, kinetic energy sum m_i |v_i|^2 / 2.
struct GridDiagnostics {
  Real mass = 0;
  Vec3 momentum = Vec3::Zero();
  Vec3 angular_momentum = Vec3::Zero();
  Real kinetic = 0;
};
template <int Dim>
GridDiagnostics measure_grid(const Grid<Dim>& g);

}  // namespace mpmtb
