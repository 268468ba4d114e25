#include "output.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>

namespace mpmtb {

void write_atomically(const std::filesystem::path& path, const std::string& content) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  const auto tmp = path.string() + fmt::format(".tmp{}", ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << content;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

std::string CsvTable::render() const {
  std::string s = render_header(header);
  for (const auto& row : rows) s += render_row(row);
  return s;
}

std::string CsvTable::render_header(const std::vector<std::string>& header) {
  std::string s;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (i) s += ',';
    s += header[i];
  }
  return s + '\n';
}

std::string CsvTable::render_row(const std::vector<double>& row) {
  std::string s;
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (i) s += ',';
    s += fmt::format("{:.17g}", row[i]);
  }
  return s + '\n';
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    q += c;
    if (c == '"') q += c;
  }
  return q + '"';
}

}  // namespace mpmtb
