#include "references/crack.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

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
  connected_ = params.optional("connected", 0,
                               Range{[](Real c) { return c == 0 || c == 1; }, "0 or 1"}) == 1;
  params.reject_unknown();
  const BodySpec& body = scene.bodies.front();
  Vec3 lo, hi;
  body.bounds(lo, hi);
  center_ = (lo + hi) / 2;
  if (Dim == 3) thickness_ = hi[2] - lo[2];
  // The seed region: the cut-out (or the centre) and two cells round it, which
  // the stretched plate's damage next to the cut reaches.
  h_ = scene.dx();
  const bool cut = (body.cut_max.array() > body.cut_min.array()).head<2>().all();
  seed_lo_ = ((cut ? body.cut_min : center_).head<2>().array() - 2 * h_).matrix().cast<double>();
  seed_hi_ = ((cut ? body.cut_max : center_).head<2>().array() + 2 * h_).matrix().cast<double>();
}

// Keeps in `in` only the particles in cells of size h_ (x-y) joined, through
// cells sharing a side or a corner, to a cell that meets the seed box.
template <int Dim>
void CrackGeometry<Dim>::keep_connected(const std::vector<Eigen::Vector2d>& x,
                                        std::vector<char>& in) const {
  Eigen::Vector2d lo = seed_lo_, hi = seed_hi_;
  for (std::size_t i = 0; i < x.size(); ++i) lo = lo.cwiseMin(x[i]), hi = hi.cwiseMax(x[i]);
  const auto cell = [&](const Eigen::Vector2d& y) {
    return Eigen::Vector2i(static_cast<int>(std::floor((y[0] - lo[0]) / h_)),
                           static_cast<int>(std::floor((y[1] - lo[1]) / h_)));
  };
  const Eigen::Vector2i n = cell(hi) + Eigen::Vector2i::Ones();
  const auto at = [&](const Eigen::Vector2i& c) {
    return static_cast<std::size_t>(c[1]) * n[0] + c[0];
  };
  const std::size_t cells = static_cast<std::size_t>(n[0]) * n[1];
  std::vector<char> occupied(cells, 0), reached(cells, 0);
  for (const auto& y : x) occupied[at(cell(y))] = 1;
  std::vector<Eigen::Vector2i> todo;
  const Eigen::Vector2i s0 = cell(seed_lo_), s1 = cell(seed_hi_);
  for (int j = s0[1]; j <= s1[1]; ++j)
    for (int i = s0[0]; i <= s1[0]; ++i)
      if (occupied[at({i, j})]) reached[at({i, j})] = 1, todo.push_back({i, j});
  while (!todo.empty()) {
    const Eigen::Vector2i c = todo.back();
    todo.pop_back();
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const Eigen::Vector2i m = c + Eigen::Vector2i(di, dj);
        if (m.minCoeff() < 0 || m[0] >= n[0] || m[1] >= n[1]) continue;
        if (occupied[at(m)] && !reached[at(m)]) reached[at(m)] = 1, todo.push_back(m);
      }
  }
  for (std::size_t i = 0; i < x.size(); ++i) in[i] = reached[at(cell(x[i]))];
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
    std::vector<std::size_t> crack;
    std::vector<Eigen::Vector2d> x;
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (!counts(P, p)) continue;
      crack.push_back(p);
      x.emplace_back(P.x[p][0], P.x[p][1]);
    }
    std::vector<char> in(crack.size(), 1);
    if (connected_ && !crack.empty()) keep_connected(x, in);
    Real V = 0, count = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < crack.size(); ++i) {
      if (!in[i]) continue;
      V += P.V0[crack[i]], count += 1;
      mean += P.V0[crack[i]] * x[i];
    }
    count_ = count;
    if (count < 2) {
      angle_ = length_ = width_ = 0;
      return {angle_, length_, width_};
    }
    mean /= V;
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < crack.size(); ++i) {
      if (!in[i]) continue;
      const Eigen::Vector2d r = x[i] - mean;
      M += P.V0[crack[i]] * r * r.transpose();
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
  return {{"crack_angle_deg", angle_}, {"crack_length", length_},        {"band_width", width_},
          {"dissipated", dissipated_}, {"damaged_particles", count_},    {"threshold", threshold_},
          {"radius", radius_},         {"connected", connected_ ? 1 : 0}};
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
