// Granular column collapse (Lube, Huppert, Sparks & Hallworth 2004, J. Fluid
// Mech. 508; Lajeunesse, Mangeney-Castelnau & Vilotte 2004, Phys. Fluids 16;
// Lube et al. 2005, Phys. Rev. E 72, for the two-dimensional case): a column
// of width w0 and height h0 (aspect ratio a = h0 / w0) released on a floor
// against a wall spreads to a deposit whose normalised run-out
// (L_final - w0) / w0 grows about linearly with a for a below about 2 and
// like a^(2/3) beyond. There is no exact solution, so this reference only
// measures: the column is bodies[0], a box from x0 = min[0] to x0 + w0 (the
// wall or symmetry plane at x0), resting on the floor at min[1].
//   front_x: the largest particle x (the front of the deposit);
//   runout:  (front_x(t) - front_x(0)) / w0, which equals (L - w0) / w0 with
//            the material's edge half a particle spacing beyond the last particle;
//   height:  the largest particle y above the floor, over h0.
// summary.json gets them at the end time under "measured", with a, w0 and h0.
#pragma once

#include "references/reference.hpp"

namespace mpmtb {

template <int Dim>
class ColumnCollapse final : public Reference<Dim> {
 public:
  // Reads no parameters; bodies[0] must be a box. Needs Dim >= 2 (a height).
  explicit ColumnCollapse(const Scene& scene);

  void initialize(State<Dim>& s) override;
  std::vector<std::string> columns() const override { return {"front_x", "runout", "height"}; }
  std::vector<Real> sample(const State<Dim>& s, const Diagnostics& d) override;
  nlohmann::json errors() const override { return nlohmann::json::object(); }
  nlohmann::json measured() const override;
  std::vector<Real> saved() const override { return {front0_, front_, runout_, height_}; }
  void restore(const std::vector<Real>& v) override;

 private:
  Real w0_ = 0, h0_ = 0, floor_y_ = 0;
  Real front0_ = 0;                           // front_x at t = 0
  Real front_ = 0, runout_ = 0, height_ = 0;  // at the latest sample
};

}  // namespace mpmtb
