// Every compiled (dimension, transfer, kernel): new variants join the
// parameterized tests automatically. A reduced build (MPMTB_COMBINATIONS=reduced,
// the sanitizer tree; methods/core/combinations.hpp) lists only the combinations
// it compiles (tests that name another one skip: support/compiled.hpp).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/registry.hpp"

namespace mpmtb::testing {

struct Combination {
  int dim;
  std::string transfer, kernel;
};
inline void PrintTo(const Combination& c, std::ostream* os) {
  *os << c.dim << "D " << c.transfer << " " << c.kernel;
}

// Which transfers: all, or those that claim angular momentum conservation
// (APIC-like: C_p in P2G and L to round-off both ways).
enum class Transfers { all, conserving_angular_momentum };

inline std::vector<Combination> all_combinations(std::vector<int> dims = {1, 2, 3},
                                                 Transfers which = Transfers::all) {
  std::vector<Combination> out;
  for (int dim : dims) {
    for (const auto& t : transfer_list()) {
      if (which == Transfers::conserving_angular_momentum && !t.conserves_angular_momentum)
        continue;
      for (const auto& k : kernel_list()) {
        if (unsupported_reason(t.name, k.name).empty() && compiled_combination(t.name, k.name))
          out.push_back({dim, t.name, k.name});
      }
    }
  }
  return out;
}

inline std::string combination_name(const ::testing::TestParamInfo<Combination>& info) {
  return std::to_string(info.param.dim) + "d_" + info.param.transfer + "_" + info.param.kernel;
}

// Calls f.template operator()<Dim>() for the runtime dimension.
template <class F>
void with_dim(int dim, F&& f) {
  switch (dim) {
    case 1:
      f.template operator()<1>();
      break;
    case 2:
      f.template operator()<2>();
      break;
    default:
      f.template operator()<3>();
  }
}

}  // namespace mpmtb::testing
