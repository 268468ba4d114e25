// Frame fields and the progress line: the von Mises stress of textbook stress
// states, the VTK XML layout of a frame, and a progress line that is drawn
// only when enabled.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "progress.hpp"
#include "vtk/frames.hpp"
#include "vtk/vtk_xml.hpp"

namespace mpmtb {
namespace frames_test {

// sigma_vm = sqrt(3/2 s:s): uniaxial stress s gives |s|, pure shear t gives
// sqrt(3) |t|, a hydrostatic state gives 0 (e.g. Hill 1950, ch. 2).
TEST(VonMises, TextbookStates) {
  Mat<3> uniaxial = Mat<3>::Zero();
  uniaxial(0, 0) = -7.5;
  EXPECT_NEAR(von_mises<3>(uniaxial), 7.5, 1e-14);
  Mat<3> shear = Mat<3>::Zero();
  shear(0, 1) = shear(1, 0) = 2;
  EXPECT_NEAR(von_mises<3>(shear), 2 * std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(von_mises<3>(4.0 * Mat<3>::Identity()), 0, 1e-14);
  // Lower dimensions: the missing components are zero.
  Mat<2> shear2 = Mat<2>::Zero();
  shear2(0, 1) = shear2(1, 0) = 2;
  EXPECT_NEAR(von_mises<2>(shear2), 2 * std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(von_mises<1>(Mat<1>::Constant(-3)), 3, 1e-14);
  // Invariant under a rotation of the stress.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Mat<3> sigma;
  sigma << 1, 2, 3, 2, -4, 5, 3, 5, 6;
  EXPECT_NEAR(von_mises<3>(R * sigma * R.transpose()), von_mises<3>(sigma), 1e-12);
}

// The appended block holds, per array, a UInt64 byte count then the values,
// at the offset its element names.
TEST(VtkXml, AppendedArraysSitAtTheirOffsets) {
  vtk::PointCloud c;
  c.points = {1, 2, 3, 4, 5, 6};
  c.point_data.push_back(vtk::DataArray::float64("J", {0.5, 1.5}));
  const std::string xml = vtk::render_vtp(c);
  EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"2\" NumberOfVerts=\"2\""), std::string::npos);
  const std::size_t data = xml.find('_', xml.find("<AppendedData")) + 1;
  auto offset_of = [&](const std::string& name) {
    const std::size_t at = xml.find("Name=\"" + name + "\"");
    const std::size_t o = xml.find("offset=\"", at) + 8;
    return std::stoul(xml.substr(o, xml.find('"', o) - o));
  };
  std::uint64_t count = 0;
  double values[6];
  std::memcpy(&count, xml.data() + data + offset_of("J"), 8);
  std::memcpy(values, xml.data() + data + offset_of("J") + 8, 16);
  EXPECT_EQ(count, 16u);
  EXPECT_EQ(values[0], 0.5);
  EXPECT_EQ(values[1], 1.5);
  std::memcpy(&count, xml.data() + data + offset_of("Points"), 8);
  std::memcpy(values, xml.data() + data + offset_of("Points") + 8, 48);
  EXPECT_EQ(count, 48u);
  EXPECT_EQ(values[5], 6.0);
  EXPECT_THROW(
      {
        vtk::PointCloud bad = c;
        bad.point_data.push_back(vtk::DataArray::float64("short", {1.0}));
        vtk::render_vtp(bad);
      },
      std::runtime_error);
}

std::string drawn(bool enabled) {
  std::FILE* f = std::tmpfile();
  {
    Progress p("run", enabled, f);
    p.update(0.25, 10);
    p.update(0.5, 20);  // within 0.1 s of the first: not drawn
  }
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s += static_cast<char>(c);
  std::fclose(f);
  return s;
}

TEST(Progress, DrawsOneLineOnlyWhenEnabled) {
  EXPECT_EQ(drawn(false), "");
  const std::string s = drawn(true);
  EXPECT_EQ(s.front(), '\r');
  EXPECT_NE(s.find(" 25.0%"), std::string::npos) << s;
  EXPECT_EQ(s.find('\n'), std::string::npos) << s;
  EXPECT_EQ(s.substr(s.size() - 4), "\r\x1b[K");  // cleared at the end
  EXPECT_EQ(Progress::format_line("bar", 0.5, 1234.4, 75), "bar  50.0%  1234 steps/s  01:15 left");
  EXPECT_EQ(Progress::format_line("bar", 0, 0, NAN), "bar   0.0%  0 steps/s  --:-- left");
}

}  // namespace frames_test
}  // namespace mpmtb
