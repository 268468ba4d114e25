// Crack geometry of a damage run (no exact solution: this reference only
// measures). The crack is the set of particles whose `damage` is at least
// `threshold` (0.5), and, with `radius` > 0, whose current position lies within
// `radius` of bodies[0]'s centre in the x-y plane (so that damage where a grip
// holds the plate does not count as the crack), and, with `connected` = 1, that
// are joined to the cut-out of bodies[0] (or to its centre) through cells of
// size dx in the x-y plane that hold such particles and share a side or a
// corner (so that cracks started elsewhere, at a grip's corner, do not count as
// the crack the cut starts; the seed is the cut's box and two cells round it).
// From their initial volumes V0
// and positions in the x-y plane it takes the weighted covariance M and reports
//   crack_angle_deg: the angle of M's principal axis (largest eigenvalue) from
//                    the x axis, in (-90, 90]: the direction the crack runs;
//   crack_length:    sqrt(12 lambda_max) (a uniform segment of length L has
//                    variance L^2 / 12);
//   band_width:      damaged area / crack_length, the area being sum V0 (2D) or
//                    sum V0 over the thickness of bodies[0] in z (3D): the
//                    width of the damaged band;
//   dissipated:      the energy the damage has dissipated (the budget's column).
// summary.json gets them at the end time under "measured", with the count.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "references/reference.hpp"

namespace mpmtb {

template <int Dim>
class CrackGeometry final : public Reference<Dim> {
 public:
  // Reads `threshold` in (0, 1] (0.5), `radius` >= 0 (0: everywhere) and
  // `connected`, 0 or 1 (0). Needs Dim >= 2.
  explicit CrackGeometry(const Scene& scene);

  void initialize(State<Dim>& s) override;
  std::vector<std::string> columns() const override {
    return {"crack_angle_deg", "crack_length", "band_width"};
  }
  std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) override;
  nlohmann::json errors() const override { return nlohmann::json::object(); }
  nlohmann::json measured() const override;
  std::vector<Real> saved() const override {
    return {angle_, length_, width_, dissipated_, count_};
  }
  void restore(const std::vector<Real>& v) override;

 private:
  Real threshold_ = 0.5, radius_ = 0, thickness_ = 1, h_ = 1;
  bool connected_ = false;
  Vec3 center_ = Vec3::Zero();
  Eigen::Vector2d seed_lo_ = Eigen::Vector2d::Zero(), seed_hi_ = Eigen::Vector2d::Zero();
  void keep_connected(const std::vector<Eigen::Vector2d>& x, std::vector<char>& in) const;
  template <class P>
  bool counts(const P& particles, std::size_t p) const;
  std::vector<int> slot_;  // where each material keeps `damage` (-1: nowhere)
  Real angle_ = 0, length_ = 0, width_ = 0, dissipated_ = 0, count_ = 0;
};

}  // namespace mpmtb
