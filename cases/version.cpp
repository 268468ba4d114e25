// The only file compiled with the version, revision and build-flag definitions
// (cases/CMakeLists.txt), so a new revision recompiles this file alone.
#include "version.hpp"

#include <fmt/format.h>

#include "core/types.hpp"
#include "git_revision.hpp"  // MPMTB_GIT_REV, written at every build (revision.cmake)

#ifndef MPMTB_VERSION
#define MPMTB_VERSION "unknown"
#endif
#ifndef MPMTB_BUILD_TYPE
#define MPMTB_BUILD_TYPE "unknown"
#endif
#ifndef MPMTB_COMPILER
#define MPMTB_COMPILER "unknown"
#endif
#ifndef MPMTB_MARCH_FLAG
#define MPMTB_MARCH_FLAG ""
#endif
#ifndef MPMTB_FP_CONTRACT
#define MPMTB_FP_CONTRACT "unknown"
#endif

namespace mpmtb {

const BuildInfo& build_info() {
  static const BuildInfo info = [] {
    BuildInfo b;
    b.version = MPMTB_VERSION;
    b.git_revision = MPMTB_GIT_REV;
    b.build_type = MPMTB_BUILD_TYPE;
    b.compiler = MPMTB_COMPILER;
    b.precision = sizeof(Real) == sizeof(double) ? "double" : "float";
    b.march = MPMTB_MARCH_FLAG;
#ifdef __FMA__
    b.target_fma = true;
#endif
    b.fp_contract = MPMTB_FP_CONTRACT;
    return b;
  }();
  return info;
}

nlohmann::json version_json() {
  const BuildInfo& b = build_info();
  return {{"version", b.version},       {"git_revision", b.git_revision},
          {"build_type", b.build_type}, {"compiler", b.compiler},
          {"precision", b.precision},   {"march", b.march.empty() ? "default" : b.march},
          {"target_fma", b.target_fma}, {"fp_contract", b.fp_contract}};
}

std::string version_text() {
  const BuildInfo& b = build_info();
  return fmt::format(
      "mpmtb {} (git {})\n"
      "precision {}, -march={}, FMA in the target {}, -ffp-contract={}, {} build, {}",
      b.version, b.git_revision, b.precision, b.march.empty() ? "default" : b.march,
      b.target_fma ? "yes" : "no", b.fp_contract, b.build_type, b.compiler);
}

}  // namespace mpmtb
