// series.csv columns that a scene has only when it needs them: what the
// colliders and pinned nodes did to the material, and how much of it is damaged.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "core/state.hpp"

namespace mpmtb {

template <int Dim>
class ExtraColumns {
 public:
  explicit ExtraColumns(const State<Dim>& s) {
    boundary_ =
        !s.colliders.empty() || std::any_of(s.particles.pinned.begin(), s.particles.pinned.end(),
                                            [](auto p) { return p != 0; });
    for (const auto& m : s.materials) {
      const auto names = m->state_names();
      const auto it = std::find(names.begin(), names.end(), "damage");
      damage_slot_.push_back(it == names.end() ? -1 : static_cast<int>(it - names.begin()));
      damage_ = damage_ || it != names.end();
    }
  }

  std::vector<std::string> names() const {
    std::vector<std::string> n;
    if (boundary_) {
      n = {"collider_impulse_x", "collider_impulse_y", "collider_impulse_z", "pin_impulse_x",
           "pin_impulse_y",      "pin_impulse_z",      "collider_work",      "penetration"};
    }
    if (damage_) n.push_back("damaged_fraction");
    return n;
  }

  std::vector<double> values(const State<Dim>& s) const {
    std::vector<double> v;
    if (boundary_) {
      for (int a = 0; a < 3; ++a) v.push_back(s.collider_impulse[a]);
      for (int a = 0; a < 3; ++a) v.push_back(s.pin_impulse[a]);
      v.push_back(s.collider_work);
      v.push_back(s.colliders.max_penetration(s.particles.x, s.time));
    }
    if (damage_) v.push_back(damaged_fraction(s));
    return v;
  }

 private:
  // Volume fraction of particles with damage >= 1/2.
  double damaged_fraction(const State<Dim>& s) const {
    const auto& P = s.particles;
    double damaged = 0, total = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      total += P.V0[p];
      const int slot = damage_slot_[P.material[p]];
      if (slot >= 0 && P.state_of(p)[slot] >= 0.5) damaged += P.V0[p];
    }
    return total > 0 ? damaged / total : 0;
  }

  bool boundary_ = false, damage_ = false;
  std::vector<int> damage_slot_;
};

}  // namespace mpmtb
