#pragma once

#include <cstddef>
#include <vector>

// Where a MessageBuilder writes: any growable byte buffer (a vector here, a shared-memory block
// in the runtime).

namespace vrflow::msg {

/// A growable byte buffer that a MessageBuilder writes into.
class ByteSink {
 public:
  virtual ~ByteSink();
  /// Returns the base of a buffer of at least `newCapacity` bytes that starts with the previous
  /// content, or nullptr when it cannot (the builder then reports failure from finish()).
  virtual std::byte* grow(std::size_t newCapacity) = 0;
  /// The base of the buffer (nullptr before the first grow()).
  virtual std::byte* data() = 0;
  /// Bytes available from data().
  virtual std::size_t capacity() const = 0;
};

/// A ByteSink backed by a std::vector (tests, tools, the TCP transport's staging buffer).
class VectorSink final : public ByteSink {
 public:
  /// Starts with `initialCapacity` bytes ready.
  explicit VectorSink(std::size_t initialCapacity = 0);
  std::byte* grow(std::size_t newCapacity) override;
  std::byte* data() override { return buffer_.data(); }
  std::size_t capacity() const override { return buffer_.size(); }
  /// The whole buffer; a finished message is its first MessageBuilder::finish() bytes.
  const std::vector<std::byte>& buffer() const { return buffer_; }

 private:
  std::vector<std::byte> buffer_;
};

}  // namespace vrflow::msg
