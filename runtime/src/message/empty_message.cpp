#include "vrflow/message/empty_message.hpp"

#include "vrflow/message/builder.hpp"

namespace vrflow::msg {

std::size_t writeEmptyMessage(ByteSink& sink, const Stamps& stamps, EmptyKind kind) {
  MessageBuilder builder(sink);
  builder.setStamps(stamps);
  builder.setStampsOnly(kind == EmptyKind::StampsOnly);
  return builder.finish();
}

std::vector<std::byte> makeEmptyMessage(const Stamps& stamps, EmptyKind kind) {
  VectorSink sink;
  const std::size_t size = writeEmptyMessage(sink, stamps, kind);
  std::vector<std::byte> bytes = sink.buffer();
  bytes.resize(size);
  return bytes;
}

}  // namespace vrflow::msg
