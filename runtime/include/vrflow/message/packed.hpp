#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <span>
#include <type_traits>

#include "vrflow/base/assert.hpp"

// Reading and writing little-endian values at any byte offset without undefined behaviour:
// every access goes through memcpy, which compilers turn into a plain (unaligned) load.

namespace vrflow::msg {

/// Reads a T stored at p (any alignment).
template <typename T>
T loadRaw(const std::byte* p) {
  static_assert(std::is_trivially_copyable_v<T>);
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

/// Writes value at p (any alignment).
template <typename T>
void storeRaw(std::byte* p, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  std::memcpy(p, &value, sizeof(T));
}

/// Reads a T at `offset` of `bytes`, or T{} when it would not fit: views never read outside
/// their span, whatever the bytes say.
template <typename T>
T loadAt(std::span<const std::byte> bytes, std::uint64_t offset) {
  if (offset > bytes.size() || bytes.size() - offset < sizeof(T)) return T{};
  return loadRaw<T>(bytes.data() + offset);
}

/// The part [offset, offset + length) of `bytes`, or an empty span when it does not fit.
inline std::span<const std::byte> sliceAt(std::span<const std::byte> bytes, std::uint64_t offset,
                                          std::uint64_t length) {
  if (offset > bytes.size() || bytes.size() - offset < length) return {};
  return bytes.subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
}

/// A read-only array of T packed in message bytes at any alignment. Elements are copied out
/// one by one (zero-copy view, no aliasing of the bytes as T).
template <typename T>
class PackedArray {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  /// Iterates over element values.
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = T;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = T;
    Iterator() = default;
    explicit Iterator(const std::byte* p) : p_(p) {}
    T operator*() const { return loadRaw<T>(p_); }
    Iterator& operator++() {
      p_ += sizeof(T);
      return *this;
    }
    Iterator operator++(int) {
      Iterator before = *this;
      p_ += sizeof(T);
      return before;
    }
    bool operator==(const Iterator& other) const { return p_ == other.p_; }

   private:
    const std::byte* p_ = nullptr;
  };

  PackedArray() = default;
  /// Views `bytes` as elements; a trailing partial element is ignored.
  explicit PackedArray(std::span<const std::byte> bytes)
      : bytes_(bytes.first(bytes.size() - bytes.size() % sizeof(T))) {}

  /// Number of elements.
  std::size_t size() const { return bytes_.size() / sizeof(T); }
  bool empty() const { return bytes_.empty(); }
  /// Element i; i must be below size().
  T operator[](std::size_t i) const {
    VRFLOW_ASSERT(i < size(), "PackedArray index out of range");
    return loadRaw<T>(bytes_.data() + i * sizeof(T));
  }
  /// Copies every element into `out`, which must hold at least size() elements.
  void copyTo(std::span<T> out) const {
    VRFLOW_ASSERT(out.size() >= size(), "PackedArray::copyTo: output too small");
    if (!bytes_.empty()) std::memcpy(out.data(), bytes_.data(), bytes_.size());
  }
  /// The raw little-endian bytes.
  std::span<const std::byte> bytes() const { return bytes_; }
  Iterator begin() const { return Iterator(bytes_.data()); }
  Iterator end() const { return Iterator(bytes_.data() + bytes_.size()); }

 private:
  std::span<const std::byte> bytes_;
};

}  // namespace vrflow::msg
