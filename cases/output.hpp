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
};

}  // namespace mpmtb
