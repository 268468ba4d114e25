// Runs the mpmtb program from tests and reads back what it wrote.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mpmtb::testing {

struct CliResult {
  int status;       // exit status
  std::string err;  // everything written to stderr
};

// A path under the temporary folder unique to this process and `name`; removed if present.
inline std::filesystem::path scratch_path(const std::string& name) {
  const auto p = std::filesystem::temp_directory_path() /
                 ("mpmtb_test_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(p);
  return p;
}

// Runs `mpmtb ARGS` (ARGS is passed through the shell) and captures stderr.
inline CliResult run_cli(const std::string& args) {
  static int calls = 0;  // one capture file per call: ctest runs tests in parallel processes
  const auto log = scratch_path("stderr_" + std::to_string(calls++));
  const int rc = std::system((std::string(MPMTB_CLI) + " " + args + " 2>" + log.string()).c_str());
  std::ifstream in(log);
  std::string err((std::istreambuf_iterator<char>(in)), {});
  std::filesystem::remove(log);
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, err};
}

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

}  // namespace mpmtb::testing
