// A binary archive of named fields, for checkpoints: each field is its name,
// its size in bytes and its raw bytes, so that every floating-point value
// comes back with the same bits, and a reader that expects another field or
// another size (a checkpoint of another build or layout) stops with a message
// naming the field instead of reading garbage.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace mpmtb {

// Values stored as their raw bytes: trivially copyable types, and aggregates
// of fixed-size Eigen matrices (standard layout and trivially destructible:
// their hand-written copy constructors copy the array, as memcpy does).
template <class T>
concept RawValue = std::is_trivially_copyable_v<T> ||
    (std::is_standard_layout_v<T>&& std::is_trivially_destructible_v<T>);

class ArchiveWriter {
 public:
  ArchiveWriter();
  void put_bytes(std::string_view name, const void* data, std::size_t bytes);
  template <RawValue T>
  void put(std::string_view name, const T& value) {
    put_bytes(name, &value, sizeof(T));
  }
  template <RawValue T>
  void put_vector(std::string_view name, const std::vector<T>& values) {
    put_bytes(name, values.data(), values.size() * sizeof(T));
  }
  void put_string(std::string_view name, const std::string& text) {
    put_bytes(name, text.data(), text.size());
  }
  const std::string& bytes() const { return data_; }

 private:
  std::string data_;
};

class ArchiveReader {
 public:
  // Throws InputError naming `source` when the data is not an archive.
  ArchiveReader(std::string data, std::string source);
  // Reads the read-only file at `path` (InputError when it cannot).
  static ArchiveReader from_file(const std::filesystem::path& path);

  template <RawValue T>
  void get(std::string_view name, T& value) {
    const std::string_view b = next(name, sizeof(T));
    std::memcpy(static_cast<void*>(&value), b.data(), sizeof(T));
  }
  template <RawValue T>
  void get_vector(std::string_view name, std::vector<T>& values) {
    const std::string_view b = next(name, kAnySize, sizeof(T));
    values.resize(b.size() / sizeof(T));
    if (!b.empty()) std::memcpy(static_cast<void*>(values.data()), b.data(), b.size());
  }
  std::string get_string(std::string_view name) { return std::string(next(name, kAnySize)); }
  const std::string& source() const { return source_; }

 private:
  static constexpr std::size_t kAnySize = ~std::size_t(0);
  // The next field's bytes; it must be `name` with `size` bytes (or any
  // multiple of `unit` for kAnySize).
  std::string_view next(std::string_view name, std::size_t size, std::size_t unit = 1);

  std::string data_, source_;
  std::size_t at_ = 0;
};

}  // namespace mpmtb
