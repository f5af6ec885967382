// libFuzzer target: the validating message reader on arbitrary bytes.
//   clang++ -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -I runtime/include \
//     tests/fuzz/fuzz_message_reader.cpp runtime/src/message/*.cpp runtime/src/base/assert.cpp \
//     -lxxhash -o fuzz_message_reader
//   ./fuzz_message_reader tests/fuzz/corpus/message
// Beyond "no crash, no sanitizer report", it checks what parse promises: every accessor of an
// accepted message reads consistent values, and an accepted message is canonical (rebuilding it
// from its stamps and chunks gives the same bytes).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/digest.hpp"
#include "vrflow/message/reader.hpp"

namespace {

using namespace vrflow::msg;

void check(bool condition) {
  if (!condition) __builtin_trap();
}

// Folds values into a sink so the reads are not optimised away.
volatile std::uint64_t gSink = 0;
template <typename T>
void use(const T& value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof value < sizeof bits ? sizeof value : sizeof bits);
  gSink = gSink + bits;
}

void walkObject(const ObjectView& object) {
  use(object.mask());
  std::uint64_t seen = 0;
  for (const ParamEntry entry : object.params()) {
    check(entry.index < kMaxParams);
    seen |= std::uint64_t{1} << entry.index;
    if (const ObjectType* type = object.type()) {
      check(entry.index < type->paramCount());
      check(validSizeFor(type->param(entry.index).kind, entry.bytes.size()));
    }
    for (const std::byte b : entry.bytes) use(b);
  }
  check(seen == object.mask());
  for (std::size_t i = 0; i < kMaxParams; ++i) {
    use(object.scalar(i));
    use(object.vec3(i).value_or(Vec3{}));
    use(object.quat(i).value_or(Quat{}));
    use(object.mat3(i).value_or(Mat3{}));
    use(object.aabb(i).value_or(Aabb{}));
    use(object.idParam(i));
    use(object.int64(i));
    if (const auto floats = object.floatArray(i)) {
      for (const float f : *floats) use(f);
    }
    if (const auto doubles = object.doubleArray(i)) {
      for (const double d : *doubles) use(d);
    }
  }
}

void walkResource(const ResourceView& resource) {
  use(resource.raw().size());
  if (const auto mesh = resource.mesh()) {
    check(mesh->xyz().size() == std::size_t{mesh->vertexCount()} * 3);
    check(mesh->indices().size() == mesh->indexCount());
    for (const std::uint32_t index : mesh->indices()) check(index < mesh->vertexCount());
    for (std::size_t v = 0; v < mesh->vertexCount(); ++v) use(mesh->vertex(v));
  }
  if (const auto field = resource.field()) {
    const auto dims = field->dims();
    check(field->data().size() == std::uint64_t{dims[0]} * dims[1] * dims[2] * field->components());
    check(field->spacing() > 0.0);
    for (const float f : field->data()) use(f);
  }
}

void walkEvent(const EventView& event) {
  if (const auto force = event.force()) {
    use(force->force);
    use(force->duration);
    check(force->duration >= 0.0);
  }
  for (const std::byte b : event.payload()) use(b);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  (void)MessageView::peekTotalSize(bytes);
  const auto parsed = MessageView::parse(bytes);
  if (!parsed.ok()) return 0;
  const MessageView& view = *parsed;

  const StampsView stamps = view.stamps();
  use(stamps.source.size());
  std::uint32_t userStamps = 0;
  for (const UserStampView stamp : stamps.user) {
    use(stamp.name().size());
    use(stamp.asInt64());
    use(stamp.asDouble());
    use(stamp.asString().value_or("").size());
    ++userStamps;
  }
  check(userStamps == stamps.user.size());

  std::uint32_t chunks = 0;
  for (const ChunkView chunk : view) {
    check(chunk.offset() % kAlignment == 0);
    check(chunk.bytes().size() >= kChunkHeaderSize);
    if (const auto object = chunk.asObject()) walkObject(*object);
    if (const auto resource = chunk.asResource()) walkResource(*resource);
    if (const auto event = chunk.asEvent()) walkEvent(*event);
    ++chunks;
  }
  check(chunks == view.chunkCount());
  use(digest(view));

  // Canonical form: the same stamps and chunks rebuilt give the same bytes.
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setStamps(stamps.toStamps());
  builder.setStampsOnly(view.stampsOnly());
  if (!view.stampsOnly()) builder.appendChunks(view);
  const std::size_t rebuilt = builder.finish();
  check(rebuilt == size);
  check(std::memcmp(builder.bytes().data(), data, size) == 0);
  return 0;
}
