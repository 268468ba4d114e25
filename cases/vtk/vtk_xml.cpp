#include "vtk_xml.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>

namespace mpmtb::vtk {
namespace {

// Appends the values' bytes in little-endian order.
template <class T>
void append_le(std::string& out, const std::vector<T>& values) {
  const std::size_t start = out.size();
  out.resize(start + values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(out.data() + start, values.data(), values.size() * sizeof(T));
  if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
    for (std::size_t i = start; i < out.size(); i += sizeof(T))
      std::reverse(out.begin() + i, out.begin() + i + sizeof(T));
  }
}

std::string le_uint64(std::uint64_t n) {
  std::string s;
  append_le(s, std::vector<std::uint64_t>{n});
  return s;
}

// Collects the appended block: each array is its UInt64 byte count, then the bytes.
class Appended {
 public:
  // The XML element of an array stored in the block.
  std::string element(const DataArray& a, const std::string& indent) {
    std::string xml = fmt::format(
        "{}<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" "
        "format=\"appended\" offset=\"{}\"/>\n",
        indent, a.type, a.name, a.components, data_.size());
    data_ += le_uint64(a.bytes.size());
    data_ += a.bytes;
    return xml;
  }
  std::string block() const {
    return "  <AppendedData encoding=\"raw\">\n   _" + data_ + "\n  </AppendedData>\n";
  }

 private:
  std::string data_;
};

std::string header(const char* type) {
  return fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"{}\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
      type);
}

// ParaView shows TimeValue as the dataset's time; step is for people.
std::string field_data(double time, long step) {
  return fmt::format(
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
      "format=\"ascii\">{:.17g}</DataArray>\n"
      "      <DataArray type=\"Int64\" Name=\"step\" NumberOfTuples=\"1\" "
      "format=\"ascii\">{}</DataArray>\n"
      "    </FieldData>\n",
      time, step);
}

std::string xml_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '&')
      r += "&amp;";
    else if (c == '"')
      r += "&quot;";
    else if (c == '<')
      r += "&lt;";
    else if (c == '>')
      r += "&gt;";
    else
      r += c;
  }
  return r;
}

}  // namespace

DataArray DataArray::float64(std::string name, const std::vector<double>& values, int components) {
  DataArray a{std::move(name), "Float64", components, {}};
  append_le(a.bytes, values);
  return a;
}

DataArray DataArray::int32(std::string name, const std::vector<std::int32_t>& values) {
  DataArray a{std::move(name), "Int32", 1, {}};
  append_le(a.bytes, values);
  return a;
}

DataArray DataArray::uint8(std::string name, const std::vector<std::uint8_t>& values) {
  DataArray a{std::move(name), "UInt8", 1, {}};
  append_le(a.bytes, values);
  return a;
}

std::string render_vtp(const PointCloud& cloud) {
  const std::size_t n = cloud.size();
  if (n > 0x7fffffffu) throw std::runtime_error("vtp: more than 2^31 points");
  Appended data;
  std::string xml = header("PolyData");
  xml += "  <PolyData>\n";
  xml += field_data(cloud.time, cloud.step);
  xml += fmt::format(
      "    <Piece NumberOfPoints=\"{0}\" NumberOfVerts=\"{0}\" NumberOfLines=\"0\" "
      "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
      n);
  xml += "      <PointData>\n";
  for (const auto& a : cloud.point_data) {
    if (a.bytes.size() != n * a.components * (a.type == "Float64" ? 8 : a.type == "Int32" ? 4 : 1))
      throw std::runtime_error("vtp: array '" + a.name + "' has the wrong length");
    xml += data.element(a, "        ");
  }
  xml += "      </PointData>\n      <Points>\n";
  xml += data.element(DataArray::float64("Points", cloud.points, 3), "        ");
  xml += "      </Points>\n      <Verts>\n";
  // One vertex cell per point: connectivity 0..n-1, offsets 1..n.
  std::vector<std::int32_t> connectivity(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int32_t>(i);
    offsets[i] = static_cast<std::int32_t>(i + 1);
  }
  xml += data.element(DataArray::int32("connectivity", connectivity), "        ");
  xml += data.element(DataArray::int32("offsets", offsets), "        ");
  xml += "      </Verts>\n    </Piece>\n  </PolyData>\n";
  xml += data.block();
  xml += "</VTKFile>\n";
  return xml;
}

std::string render_vti(const ImageGrid& g) {
  Appended data;
  const std::string extent =
      fmt::format("0 {} 0 {} 0 {}", g.nodes[0] - 1, g.nodes[1] - 1, g.nodes[2] - 1);
  std::string xml = header("ImageData");
  xml += fmt::format(
      "  <ImageData WholeExtent=\"{}\" Origin=\"{:.17g} {:.17g} {:.17g}\" "
      "Spacing=\"{:.17g} {:.17g} {:.17g}\">\n",
      extent, g.origin[0], g.origin[1], g.origin[2], g.spacing, g.spacing, g.spacing);
  xml += field_data(g.time, g.step);
  xml += fmt::format("    <Piece Extent=\"{}\">\n      <PointData>\n", extent);
  for (const auto& a : g.point_data) xml += data.element(a, "        ");
  xml += "      </PointData>\n      <CellData>\n      </CellData>\n    </Piece>\n  </ImageData>\n";
  xml += data.block();
  xml += "</VTKFile>\n";
  return xml;
}

std::string render_pvd(const std::vector<std::pair<double, std::string>>& datasets) {
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
      "byte_order=\"LittleEndian\">\n  <Collection>\n";
  for (const auto& [t, file] : datasets) {
    xml += fmt::format("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", t,
                       xml_escape(file));
  }
  xml += "  </Collection>\n</VTKFile>\n";
  return xml;
}

}  // namespace mpmtb::vtk
