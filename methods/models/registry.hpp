// Constitutive models by name. Adding a model: its header + one line in registry.cpp.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/parameters.hpp"
#include "models/model.hpp"

namespace mpmtb {

struct ModelInfo {
  std::string name;
  std::string description;
  std::string bibtex = {};  // the papers behind it (BibTeX entries), from its header
};

const std::vector<ModelInfo>& model_list();

// Builds the named model from its parameters; unknown names and unknown or
// out-of-range parameters throw InputError naming the field and what is allowed.
template <int Dim>
std::unique_ptr<ConstitutiveModel<Dim>> make_model(std::string_view name, Parameters& params);

}  // namespace mpmtb
