// Colliding elastic disks (Sulsky, Chen & Schreyer 1994): the energy each
// transfer keeps after the collision follows the published ordering
// PIC << APIC < FLIP (alpha = 1), and APIC keeps more under refinement
// (shared/REFERENCE.md).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "run.hpp"
#include "support/csv.hpp"

namespace mpmtb {
namespace disks_test {

// Total energy at the end over total energy at the start.
Real energy_kept(const std::string& transfer, int cells) {
  const Scene scene = load_scene("disks", {.cells = cells, .transfer = transfer});
  const auto dir =
      std::filesystem::temp_directory_path() / ("mpmtb_disks_" + transfer + std::to_string(cells));
  const RunOutcome r = run_scene(scene, dir);
  EXPECT_EQ(r.status, "ok") << r.reason;
  return testing::series_ratio(dir / "series.csv", {"total"});
}

TEST(Disks, EnergyKeptFollowsThePublishedOrdering) {
  const Real pic = energy_kept("pic", 20), apic = energy_kept("apic", 20);
  const Real flip = energy_kept("flip", 20);
  EXPECT_LT(pic, 0.25 * apic) << "PIC << APIC";
  EXPECT_LT(apic, flip) << "APIC < FLIP";
  EXPECT_LE(flip, 1.02) << "FLIP must not gain energy";
  EXPECT_GT(energy_kept("apic", 40), apic) << "APIC approaches FLIP under refinement";
}

}  // namespace disks_test
}  // namespace mpmtb
