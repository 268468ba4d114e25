// series.csv written as the run goes: the header first (atomically), then each
// output time's row appended with one write(2), so that at any moment the file
// holds the header and complete rows only, and a stopped or killed run keeps
// every row up to its last output time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace mpmtb {

class SeriesStream {
 public:
  SeriesStream() = default;
  SeriesStream(const SeriesStream&) = delete;
  SeriesStream& operator=(const SeriesStream&) = delete;
  ~SeriesStream();

  // A new series: `header` (one line) replaces whatever the file held.
  void start(const std::filesystem::path& path, const std::string& header);
  // Continues a series of which the first `bytes` are kept (a checkpoint's
  // length; rows written after it are cut off). Throws InputError when the
  // file is shorter or does not start with `header`.
  void resume(const std::filesystem::path& path, const std::string& header, std::uint64_t bytes);
  // Appends complete lines; on a short write (disk full) the file is cut back
  // to its last complete row and std::runtime_error is thrown.
  void append(const std::string& lines);
  // Bytes on disk: the header and every complete row.
  std::uint64_t bytes() const { return bytes_; }

 private:
  void open_for_append();

  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t bytes_ = 0;
};

}  // namespace mpmtb
