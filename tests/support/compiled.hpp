// Tests that name a transfer x kernel combination: a reduced build
// (MPMTB_COMBINATIONS=reduced, the sanitizer tree; methods/core/combinations.hpp)
// compiles only some, and such a test skips when its combination is not one.
#pragma once

#include <gtest/gtest.h>

#include "core/registry.hpp"

// Skips the test (from its body) when this build does not compile the
// combination (transfer, kernel); a no-op in the default build.
#define MPMTB_SKIP_UNLESS_COMPILED(transfer, kernel)                                          \
  if (::mpmtb::compiled_combination(transfer, kernel)) {                                      \
  } else                                                                                      \
    GTEST_SKIP() << "not compiled in this build (MPMTB_COMBINATIONS=reduced): " << (transfer) \
                 << " with " << (kernel)
