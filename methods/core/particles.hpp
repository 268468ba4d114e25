// Particles as a structure of arrays, fields named as in the MPM papers.
#pragma once

#include <cstdint>
#include <vector>

#include "types.hpp"

namespace mpmtb {

template <int Dim>
struct Particles {
  std::vector<Vec<Dim>> x;           // x_p  position
  std::vector<Vec<Dim>> v;           // v_p  velocity
  std::vector<Mat<Dim>> C;           // C_p  affine velocity matrix (APIC / MLS-MPM)
  std::vector<Mat<Dim>> F;           // F_p  deformation gradient
  std::vector<Real> m;               // m_p  mass
  std::vector<Real> V0;              // V0_p initial volume
  std::vector<int> material;         // index into the scene's materials
  std::vector<std::uint8_t> pinned;  // 1: the particle holds its grid nodes at rest
  // Per-model internal state (plastic J, damage, ...): state_size values per particle.
  int state_size = 0;
  std::vector<Real> state;
  // Per-transfer state (e.g. PolyPIC's higher velocity modes): transfer_state_size
  // values per particle, sized by the solver for its transfer, zero at the start.
  int transfer_state_size = 0;
  std::vector<Real> transfer_state;

  std::size_t size() const { return x.size(); }

  Real* state_of(std::size_t p) { return state_size ? &state[p * state_size] : nullptr; }
  const Real* state_of(std::size_t p) const {
    return state_size ? &state[p * state_size] : nullptr;
  }

  Real* transfer_state_of(std::size_t p) {
    return transfer_state_size ? &transfer_state[p * transfer_state_size] : nullptr;
  }
  const Real* transfer_state_of(std::size_t p) const {
    return transfer_state_size ? &transfer_state[p * transfer_state_size] : nullptr;
  }
  // The solver's transfer needs n values per particle: a different size starts
  // from zeros (a transfer's state means nothing to another one).
  void use_transfer_state(int n) {
    if (n != transfer_state_size) {
      transfer_state_size = n;
      transfer_state.assign(size() * n, Real(0));
    }
  }

  // Appends one particle at rest with F = I, C = 0.
  void add(const Vec<Dim>& xp, const Vec<Dim>& vp, Real mass, Real volume, int mat,
           bool pin = false) {
    x.push_back(xp);
    v.push_back(vp);
    C.push_back(Mat<Dim>::Zero());
    F.push_back(Mat<Dim>::Identity());
    m.push_back(mass);
    V0.push_back(volume);
    material.push_back(mat);
    pinned.push_back(pin ? 1 : 0);
    state.resize(state.size() + state_size, Real(0));
    transfer_state.resize(transfer_state.size() + transfer_state_size, Real(0));
  }
};

}  // namespace mpmtb
