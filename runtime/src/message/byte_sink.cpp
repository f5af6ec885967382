#include "vrflow/message/byte_sink.hpp"

namespace vrflow::msg {

ByteSink::~ByteSink() = default;

VectorSink::VectorSink(std::size_t initialCapacity) : buffer_(initialCapacity) {}

std::byte* VectorSink::grow(std::size_t newCapacity) {
  if (newCapacity > buffer_.size()) buffer_.resize(newCapacity);
  return buffer_.data();
}

}  // namespace vrflow::msg
