#include "models/registry.hpp"

#include <fmt/format.h>

#include <functional>

#include "core/errors.hpp"
#include "models/damage.hpp"
#include "models/fixed_corotated.hpp"
#include "models/linear_elastic.hpp"
#include "models/neo_hookean.hpp"
#include "models/sand.hpp"
#include "models/snow.hpp"

namespace mpmtb {
namespace {

template <int Dim>
using ModelFactory = std::function<std::unique_ptr<ConstitutiveModel<Dim>>(Parameters&)>;

struct ModelEntry {
  ModelInfo info;
  ModelFactory<1> make1;
  ModelFactory<2> make2;
  ModelFactory<3> make3;
};

template <template <int> class Model>
ModelEntry entry(std::string description) {
  return {{std::string(Model<1>::model_name), std::move(description)},
          [](Parameters& p) { return std::make_unique<Model<1>>(p); },
          [](Parameters& p) { return std::make_unique<Model<2>>(p); },
          [](Parameters& p) { return std::make_unique<Model<3>>(p); }};
}

const std::vector<ModelEntry>& entries() {
  static const std::vector<ModelEntry> list = {
      entry<NeoHookean>("compressible neo-Hookean, E nu density (Bonet & Wood 2008)"),
      entry<LinearElastic>("small-strain linear elastic, E nu density; not frame indifferent"),
      entry<FixedCorotated>("fixed-corotated, E nu density; invertible (Stomakhin et al. 2012)"),
      entry<Snow>("fixed-corotated snow plasticity, theta_c theta_s xi (Stomakhin et al. 2013)"),
      entry<Sand>("Drucker-Prager sand on Hencky StVK, friction_angle h1 h2 h3 (Klar et al. 2016)"),
      entry<Damage>("isotropic damage, neo-Hookean tension split (CD-MPM 2019, AnisoMPM 2020)"),
  };
  return list;
}

}  // namespace

const std::vector<ModelInfo>& model_list() {
  static const std::vector<ModelInfo> infos = [] {
    std::vector<ModelInfo> v;
    for (const auto& e : entries()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

template <int Dim>
std::unique_ptr<ConstitutiveModel<Dim>> make_model(std::string_view name, Parameters& params) {
  for (const auto& e : entries()) {
    if (e.info.name != name) continue;
    std::unique_ptr<ConstitutiveModel<Dim>> model;
    if constexpr (Dim == 1) model = e.make1(params);
    if constexpr (Dim == 2) model = e.make2(params);
    if constexpr (Dim == 3) model = e.make3(params);
    params.reject_unknown();
    return model;
  }
  std::string allowed;
  for (const auto& e : entries()) allowed += (allowed.empty() ? "" : ", ") + e.info.name;
  throw InputError(
      fmt::format("{}: unknown model '{}'; allowed: {}", params.context(), name, allowed));
}

template std::unique_ptr<ConstitutiveModel<1>> make_model<1>(std::string_view, Parameters&);
template std::unique_ptr<ConstitutiveModel<2>> make_model<2>(std::string_view, Parameters&);
template std::unique_ptr<ConstitutiveModel<3>> make_model<3>(std::string_view, Parameters&);

}  // namespace mpmtb
