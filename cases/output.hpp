// Result files. Every file is written atomically: to a temporary file in the
// same folder, then renamed, so a crash never leaves half a file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mpmtb {

void write_atomically(const std::filesystem::path& path, const std::string& content);

// A numeric table rendered as CSV with full precision ({:.17g}).
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::string render() const;
  // The header line and one row line, each ending in a newline: render() is
  // the header followed by every row, so a table streamed line by line
  // (SeriesStream) has the same bytes as one rendered at the end.
  static std::string render_header(const std::vector<std::string>& header);
  static std::string render_row(const std::vector<double>& row);
};

// A text cell for a CSV table: quoted (with doubled quotes) when it holds a
// comma, a quote or a newline (RFC 4180).
std::string csv_field(const std::string& s);

}  // namespace mpmtb
