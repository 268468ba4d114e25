#include "series_stream.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "core/errors.hpp"
#include "output.hpp"

namespace mpmtb {

SeriesStream::~SeriesStream() {
  if (fd_ >= 0) ::close(fd_);
}

void SeriesStream::start(const std::filesystem::path& path, const std::string& header) {
  path_ = path;
  write_atomically(path_, header);  // never a half header, nor an old run's rows
  bytes_ = header.size();
  open_for_append();
}

void SeriesStream::resume(const std::filesystem::path& path, const std::string& header,
                          std::uint64_t bytes) {
  path_ = path;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path_, ec);
  std::string head(header.size(), '\0');
  std::ifstream(path_, std::ios::binary).read(head.data(), static_cast<long>(head.size()));
  if (ec || size < bytes || head != header) {
    throw InputError(fmt::format(
        "--resume: '{}' is not the series the checkpoint continues ({}; expected at least {} "
        "bytes starting with the header `{}`)",
        path_.string(), ec ? ec.message() : fmt::format("{} bytes", size), bytes,
        header.substr(0, 40) + "..."));
  }
  // The rows after the checkpoint are written again by the resumed run.
  std::filesystem::resize_file(path_, bytes);
  bytes_ = bytes;
  open_for_append();
}

void SeriesStream::open_for_append() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) {
    throw std::runtime_error(
        fmt::format("cannot open {} for appending: {}", path_.string(), std::strerror(errno)));
  }
}

void SeriesStream::append(const std::string& lines) {
  std::size_t done = 0;
  while (done < lines.size()) {
    const ssize_t n = ::write(fd_, lines.data() + done, lines.size() - done);
    if (n < 0 && errno == EINTR) continue;  // a stop signal arrived mid-call
    if (n <= 0) {
      const int err = errno;
      // Drop the partial row: what stays on disk is whole rows.
      if (::ftruncate(fd_, static_cast<off_t>(bytes_)) != 0) {
        // Nothing better to do: the error below names the first failure.
      }
      throw std::runtime_error(
          fmt::format("cannot append to {}: {}", path_.string(), std::strerror(err)));
    }
    done += static_cast<std::size_t>(n);
  }
  bytes_ += lines.size();
}

}  // namespace mpmtb
