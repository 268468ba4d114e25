// Error types: bad input is reported with the field and what is allowed.
#pragma once

#include <stdexcept>
#include <string>

namespace mpmtb {

// Invalid user input (names, parameters, scene files). The message names the
// offending field and the allowed values; the CLI exits with status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace mpmtb
