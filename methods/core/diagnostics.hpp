// Conserved and monitored quantities of the particle state.
#pragma once

#include "core/stepper.hpp"

namespace mpmtb {

struct Diagnostics {
  Real mass = 0;
  Real kinetic = 0;                      // sum m_p |v_p|^2 / 2
  Real strain = 0;                       // sum V0_p psi(F_p)
  Real gravity = 0;                      // -sum m_p g . x_p
  Real total = 0;                        // kinetic + strain + gravity
  Vec3 momentum = Vec3::Zero();          // sum m_p v_p
  Vec3 angular_momentum = Vec3::Zero();  // sum x_p x m_p v_p + affine part
  Real volume = 0;                       // sum V0_p J_p
  Real J_min = 1, J_max = 1;
  Vec3 center_of_mass = Vec3::Zero();
  Vec3 center_of_mass_velocity = Vec3::Zero();
};

// Sums in particle order, so the result is deterministic.
template <int Dim>
Diagnostics measure(const State<Dim>& s, const Stepper<Dim>& stepper);

// Grid-side mass and momentum after P2G: sum_i m_i and sum_i p_i.
template <int Dim>
void grid_totals(const Grid<Dim>& g, Real& mass, Vec3& momentum);

}  // namespace mpmtb
