// VTK XML writers for particle and grid frames (ParaView reads them directly).
//
// Format (VTK file formats, "XML File Formats", Kitware): every data array is
// stored in one <AppendedData encoding="raw"> block after the XML header, as a
// UInt64 byte count followed by the values, little-endian
// (byte_order="LittleEndian", header_type="UInt64"). Raw appended data is the
// smallest and fastest choice; it makes the file not well-formed XML after the
// `_` marker, which every VTK reader (and analysis/render.py) expects.
// Floating-point fields are Float64 so that frames match the run's diagnostics
// to round-off.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mpmtb::vtk {

// One named array of `components` values per point (or per grid node).
struct DataArray {
  std::string name;
  std::string type;  // Float64 | Int32 | UInt8
  int components = 1;
  std::string bytes;  // raw little-endian values

  static DataArray float64(std::string name, const std::vector<double>& values, int components = 1);
  static DataArray int32(std::string name, const std::vector<std::int32_t>& values);
  static DataArray uint8(std::string name, const std::vector<std::uint8_t>& values);
};

// Particles as PolyData: points (3 components, z = 0 in 2D and y = z = 0 in
// 1D), one vertex cell per point so that ParaView shows them, point data.
struct PointCloud {
  double time = 0;
  long step = 0;
  std::vector<double> points;  // 3 per point
  std::vector<DataArray> point_data;
  std::size_t size() const { return points.size() / 3; }
};

// A uniform grid as ImageData with node (point) data; 2D and 1D grids have
// one node along the missing axes.
struct ImageGrid {
  double time = 0;
  long step = 0;
  double origin[3] = {0, 0, 0};
  double spacing = 1;
  int nodes[3] = {1, 1, 1};
  std::vector<DataArray> point_data;
};

std::string render_vtp(const PointCloud& cloud);
std::string render_vti(const ImageGrid& grid);
// A ParaView collection: (time, file relative to the .pvd) per dataset.
std::string render_pvd(const std::vector<std::pair<double, std::string>>& datasets);

}  // namespace mpmtb::vtk
