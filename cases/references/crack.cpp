#include "references/crack.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "scene.hpp"

namespace mpmtb {

template <int Dim>
CrackGeometry<Dim>::CrackGeometry(const Scene& scene) {
  if (Dim < 2) throw InputError("reference: the crack geometry needs dim >= 2 (an angle)");
  Parameters params = scene.reference_params;
  threshold_ =
      params.optional("threshold", 0.5, Range{[](Real t) { return t > 0 && t <= 1; }, "in (0, 1]"});
  radius_ = params.optional("radius", 0, Range::non_negative());
  params.reject_unknown();
  Vec3 lo, hi;
  scene.bodies.front().bounds(lo, hi);
  center_ = (lo + hi) / 2;
  if (Dim == 3) thickness_ = hi[2] - lo[2];
}

template <int Dim>
template <class P>
bool CrackGeometry<Dim>::counts(const P& particles, std::size_t p) const {
  const int at = slot_[particles.material[p]];
  if (at < 0 || particles.state_of(p)[at] < threshold_) return false;
  if (radius_ <= 0) return true;
  const Real dx = particles.x[p][0] - center_[0], dy = particles.x[p][1] - center_[1];
  return dx * dx + dy * dy <= radius_ * radius_;
}

template <int Dim>
void CrackGeometry<Dim>::initialize(State<Dim>& s) {
  slot_.clear();
  for (const auto& m : s.materials) {
    const auto names = m->state_names();
    const auto it = std::find(names.begin(), names.end(), "damage");
    slot_.push_back(it == names.end() ? -1 : static_cast<int>(it - names.begin()));
  }
}

template <int Dim>
std::vector<Real> CrackGeometry<Dim>::sample(const State<Dim>& s, const Diagnostics& d) {
  dissipated_ = d.dissipated;
  if constexpr (Dim >= 2) {
    const auto& P = s.particles;
    Real V = 0, count = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (!counts(P, p)) continue;
      V += P.V0[p], count += 1;
      mean += P.V0[p] * Eigen::Vector2d(P.x[p][0], P.x[p][1]);
    }
    count_ = count;
    if (count < 2) {
      angle_ = length_ = width_ = 0;
      return {angle_, length_, width_};
    }
    mean /= V;
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (!counts(P, p)) continue;
      const Eigen::Vector2d r = Eigen::Vector2d(P.x[p][0], P.x[p][1]) - mean;
      M += P.V0[p] * r * r.transpose();
    }
    M /= V;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M);  // ascending
    const Eigen::Vector2d axis = eig.eigenvectors().col(1);
    Real angle = std::atan2(axis[1], axis[0]) * 180 / std::numbers::pi;
    if (angle <= -90) angle += 180;
    if (angle > 90) angle -= 180;
    angle_ = angle;
    length_ = std::sqrt(12 * std::max(0.0, eig.eigenvalues()[1]));
    width_ = length_ > 0 ? V / thickness_ / length_ : 0;
  }
  return {angle_, length_, width_};
}

template <int Dim>
nlohmann::json CrackGeometry<Dim>::measured() const {
  return {{"crack_angle_deg", angle_}, {"crack_length", length_},     {"band_width", width_},
          {"dissipated", dissipated_}, {"damaged_particles", count_}, {"threshold", threshold_},
          {"radius", radius_}};
}

template <int Dim>
void CrackGeometry<Dim>::restore(const std::vector<Real>& v) {
  if (v.size() != 5) {
    throw InputError(
        fmt::format("checkpoint: the crack reference keeps {} values, found {}", 5, v.size()));
  }
  angle_ = v[0], length_ = v[1], width_ = v[2], dissipated_ = v[3], count_ = v[4];
}

template class CrackGeometry<1>;
template class CrackGeometry<2>;
template class CrackGeometry<3>;

}  // namespace mpmtb
