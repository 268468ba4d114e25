#include "references/column.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "core/errors.hpp"
#include "scene.hpp"

namespace mpmtb {
namespace {

template <int Dim>
Real max_coordinate(const State<Dim>& s, int axis) {
  Real m = -std::numeric_limits<Real>::infinity();
  for (const auto& x : s.particles.x) m = std::max(m, x[axis]);
  return m;
}

}  // namespace

template <int Dim>
ColumnCollapse<Dim>::ColumnCollapse(const Scene& scene) {
  if (Dim < 2) throw InputError("reference: the column collapse needs dim >= 2 (a height)");
  Parameters params = scene.reference_params;
  params.reject_unknown();
  const BodySpec& column = scene.bodies.front();
  if (column.shape != "box")
    throw InputError("reference: the column collapse needs bodies[0] to be a box");
  w0_ = column.max[0] - column.min[0];
  h0_ = column.max[1] - column.min[1];
  floor_y_ = column.min[1];
}

template <int Dim>
void ColumnCollapse<Dim>::initialize(State<Dim>& s) {
  front0_ = max_coordinate(s, 0);
}

template <int Dim>
std::vector<Real> ColumnCollapse<Dim>::sample(const State<Dim>& s, const Diagnostics&) {
  front_ = max_coordinate(s, 0);
  runout_ = (front_ - front0_) / w0_;
  if constexpr (Dim >= 2) height_ = (max_coordinate(s, 1) - floor_y_) / h0_;
  return {front_, runout_, height_};
}

template <int Dim>
nlohmann::json ColumnCollapse<Dim>::measured() const {
  return {{"aspect_ratio", h0_ / w0_}, {"w0", w0_},         {"h0", h0_},
          {"front_x", front_},         {"runout", runout_}, {"height", height_}};
}

template <int Dim>
void ColumnCollapse<Dim>::restore(const std::vector<Real>& v) {
  if (v.size() != 4) {
    throw InputError(
        fmt::format("checkpoint: the column reference keeps {} values, found {}", 4, v.size()));
  }
  front0_ = v[0], front_ = v[1], runout_ = v[2], height_ = v[3];
}

template class ColumnCollapse<1>;
template class ColumnCollapse<2>;
template class ColumnCollapse<3>;

}  // namespace mpmtb
