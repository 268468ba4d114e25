// Isotropic elastic constants shared by the elastic models.
#pragma once

#include <cmath>

#include "core/parameters.hpp"

namespace mpmtb {

struct ElasticConstants {
  Real E = 0, nu = 0, density = 0;
  Real mu = 0, lambda = 0;  // Lame: mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2 nu))

  // Reads E > 0, nu in (-1, 0.5), density > 0.
  static ElasticConstants read(Parameters& params) {
    ElasticConstants c;
    c.E = params.required("E", Range::positive());
    c.nu = params.required("nu", Range::open(-1, 0.5));
    c.density = params.required("density", Range::positive());
    c.mu = c.E / (2 * (1 + c.nu));
    c.lambda = c.E * c.nu / ((1 + c.nu) * (1 - 2 * c.nu));
    return c;
  }
  Real wave_speed() const { return std::sqrt((lambda + 2 * mu) / density); }
};

}  // namespace mpmtb
