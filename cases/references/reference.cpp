#include "references/reference.hpp"

#include "models/registry.hpp"
#include "references/column.hpp"
#include "references/crack.hpp"
#include "references/manufactured.hpp"
#include "references/vibrating_bar.hpp"
#include "scene.hpp"

namespace mpmtb {

std::vector<std::string> reference_kinds() {
  return {"vibrating-bar", "mms-bar", "mms-axis", "column", "crack"};
}

template <int Dim>
std::unique_ptr<Reference<Dim>> make_reference(const Scene& scene) {
  if (scene.reference.empty()) return nullptr;
  if (scene.reference == "vibrating-bar") {
    const MaterialSpec& m = scene.materials[scene.bodies.front().material];
    Parameters params = m.params;
    const Real c = make_model<Dim>(m.model, params)->wave_speed();
    return std::make_unique<VibratingBar<Dim>>(scene, c);
  }
  if (scene.reference == "mms-bar" || scene.reference == "mms-axis") {
    return std::make_unique<ManufacturedReference<Dim>>(scene, scene.reference);
  }
  if (scene.reference == "column") return std::make_unique<ColumnCollapse<Dim>>(scene);
  if (scene.reference == "crack") return std::make_unique<CrackGeometry<Dim>>(scene);
  return nullptr;  // unreachable: read_scene accepts only reference_kinds()
}

template std::unique_ptr<Reference<1>> make_reference<1>(const Scene&);
template std::unique_ptr<Reference<2>> make_reference<2>(const Scene&);
template std::unique_ptr<Reference<3>> make_reference<3>(const Scene&);

}  // namespace mpmtb
