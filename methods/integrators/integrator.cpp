#include "integrators/integrator.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/errors.hpp"

namespace mpmtb {

Integrator parse_integrator(std::string_view name) {
  for (std::size_t i = 0; i < kIntegratorNames.size(); ++i) {
    if (kIntegratorNames[i] == name) return static_cast<Integrator>(i);
  }
  throw InputError(fmt::format("method.integrator: unknown integrator '{}'; allowed: {}", name,
                               fmt::join(kIntegratorNames, ", ")));
}

}  // namespace mpmtb
