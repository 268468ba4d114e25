// Reading the program's output files back in tests: text, JSON, CSV tables.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mpmtb::testing {

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

inline nlohmann::json read_json(const std::filesystem::path& path) {
  return nlohmann::json::parse(read_text(path));
}

// A CSV table of numbers with a header line. `ok` is false, with `problem`
// saying why, when a row has the wrong width or a cell is not a number.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  bool ok = true;
  std::string problem;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    return -1;
  }
};

inline Csv read_csv_text(const std::string& text) {
  Csv csv;
  std::istringstream in(text);
  std::string line;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::stringstream ss(l);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    return cells;
  };
  if (!std::getline(in, line)) return {{}, {}, false, "empty file"};
  csv.header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    if (cells.size() != csv.header.size()) {
      return {csv.header, csv.rows, false, "row of " + std::to_string(cells.size()) + " cells"};
    }
    std::vector<double> row;
    for (const auto& c : cells) {
      char* end = nullptr;
      row.push_back(std::strtod(c.c_str(), &end));
      if (c.empty() || *end != '\0') return {csv.header, csv.rows, false, "not a number: " + c};
    }
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

inline Csv read_csv(const std::filesystem::path& path) {
  return read_csv_text(read_text(path));
}

// The sum of `columns` in the last row of a series.csv over the same sum in the
// first row (e.g. the energy kept: {"kinetic", "strain"}); NaN if unreadable.
inline double series_ratio(const std::filesystem::path& series,
                           const std::vector<std::string>& columns) {
  const Csv csv = read_csv(series);
  if (!csv.ok || csv.rows.empty()) return std::nan("");
  double first = 0, last = 0;
  for (const auto& name : columns) {
    const int c = csv.column(name);
    if (c < 0) return std::nan("");
    first += csv.rows.front()[c];
    last += csv.rows.back()[c];
  }
  return last / first;
}

}  // namespace mpmtb::testing
