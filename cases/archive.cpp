#include "archive.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace mpmtb {
namespace {

// Format tag and version: a reader refuses anything else.
constexpr std::string_view kMagic = "mpmtb-archive-1\n";

template <class T>
void append_raw(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

ArchiveWriter::ArchiveWriter() : data_(kMagic) {}

void ArchiveWriter::put_bytes(std::string_view name, const void* data, std::size_t bytes) {
  append_raw(data_, static_cast<std::uint32_t>(name.size()));
  data_ += name;
  append_raw(data_, static_cast<std::uint64_t>(bytes));
  data_.append(static_cast<const char*>(data), bytes);
}

ArchiveReader::ArchiveReader(std::string data, std::string source)
    : data_(std::move(data)), source_(std::move(source)) {
  if (data_.compare(0, kMagic.size(), kMagic) != 0) {
    throw InputError(fmt::format("{}: not an mpmtb checkpoint (expected the header `{}`)", source_,
                                 kMagic.substr(0, kMagic.size() - 1)));
  }
  at_ = kMagic.size();
}

ArchiveReader ArchiveReader::from_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read the checkpoint '{}'", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return ArchiveReader(std::move(text).str(), path.string());
}

std::string_view ArchiveReader::next(std::string_view name, std::size_t size, std::size_t unit) {
  auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}: field `{}`: {} (a checkpoint of another build, or damaged)",
                                 source_, name, what));
  };
  auto take = [&](std::size_t n) {
    if (data_.size() - at_ < n) fail("the file ends early");
    const std::string_view v(data_.data() + at_, n);
    at_ += n;
    return v;
  };
  std::uint32_t name_size = 0;
  std::memcpy(&name_size, take(sizeof name_size).data(), sizeof name_size);
  const std::string_view found = take(name_size);
  if (found != name) fail(fmt::format("found `{}` in its place", found));
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, take(sizeof bytes).data(), sizeof bytes);
  if (size != kAnySize ? bytes != size : bytes % unit != 0) {
    fail(fmt::format(
        "{} bytes, expected {}", bytes,
        size != kAnySize ? std::to_string(size) : fmt::format("a multiple of {}", unit)));
  }
  return take(bytes);
}

}  // namespace mpmtb
