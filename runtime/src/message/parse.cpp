// MessageView::parse: the one place that checks a message. Every size field is compared with
// the bytes that remain before it is used, all offset arithmetic is done in 64 bits on values
// that cannot overflow (or with an overflow check), and nothing is allocated from a size field.

#include <bit>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <string>

#include "vrflow/message/packed.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::msg {
namespace {

using Bytes = std::span<const std::byte>;

std::string num(std::uint64_t value) {
  return std::to_string(value);
}

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%" PRIx64, value);
  return text;
}

bool allZero(Bytes bytes) {
  for (const std::byte b : bytes) {
    if (b != std::byte{0}) return false;
  }
  return true;
}

// Index of the first value in `bytes` (packed T) that is NaN or infinite, or -1.
template <typename T>
std::int64_t firstNonFinite(Bytes bytes) {
  const std::size_t count = bytes.size() / sizeof(T);
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(loadRaw<T>(bytes.data() + i * sizeof(T)))) {
      return static_cast<std::int64_t>(i);
    }
  }
  return -1;
}

// Checks one message; offsets in errors count from the message start.
class Checker {
 public:
  Checker(Bytes message, const ObjectTypeRegistry& types) : m_(message), types_(types) {}

  Status run() {
    if (Status s = header(); !s) return s;
    if (Status s = stamps(); !s) return s;
    return chunks();
  }

 private:
  template <typename T>
  T at(std::uint64_t offset) const {
    return loadAt<T>(m_, offset);  // callers have checked the range
  }

  Status header() {
    if (m_.size() < kMessageHeaderSize) {
      return makeError("message of " + num(m_.size()) + " bytes is shorter than the " +
                       num(kMessageHeaderSize) + "-byte header");
    }
    const auto magic = at<std::uint32_t>(HeaderLayout::kMagic);
    if (magic != kMagic) {
      return makeError("offset 0: magic " + hex(magic) + " is not 'VRFM' (" + hex(kMagic) +
                       "): not a vrflow message");
    }
    const auto version = at<std::uint16_t>(HeaderLayout::kVersion);
    if (version != kLayoutVersion) {
      return makeError("offset 4: layout version " + num(version) +
                       " is not supported (this reader reads version " + num(kLayoutVersion) + ")");
    }
    const auto flags = at<std::uint16_t>(HeaderLayout::kFlags);
    if ((flags & ~kKnownFlags) != 0) {
      return makeError("offset 6: unknown flags " + hex(flags & ~kKnownFlags));
    }
    const auto totalSize = at<std::uint64_t>(HeaderLayout::kTotalSize);
    if (totalSize != m_.size()) {
      return makeError("offset 8: totalSize " + num(totalSize) + " differs from the " +
                       num(m_.size()) + " bytes received");
    }
    const double simTime = at<double>(HeaderLayout::kSimTime);
    if (!std::isfinite(simTime)) return makeError("offset 32: simTime is not a finite number");
    const double timeStep = at<double>(HeaderLayout::kTimeStep);
    if (!std::isfinite(timeStep) || timeStep < 0.0) {
      return makeError("offset 40: timeStep is not a finite number >= 0");
    }
    if ((flags & kFlagStampsOnly) != 0 && at<std::uint32_t>(HeaderLayout::kChunkCount) != 0) {
      return makeError("offset 20: a stamps-only message declares " +
                       num(at<std::uint32_t>(HeaderLayout::kChunkCount)) + " chunks");
    }
    return {};
  }

  Status stamps() {
    const std::uint64_t stampsSize = at<std::uint32_t>(HeaderLayout::kStampsSize);
    if (stampsSize % kAlignment != 0) {
      return makeError("offset 16: stampsSize " + num(stampsSize) + " is not a multiple of 8");
    }
    if (stampsSize > m_.size() - kMessageHeaderSize) {
      return makeError("offset 16: stamps section of " + num(stampsSize) +
                       " bytes runs past the end of the message (" + num(m_.size()) + " bytes)");
    }
    const Bytes section = m_.subspan(kMessageHeaderSize, static_cast<std::size_t>(stampsSize));
    const std::uint64_t sourceLen = at<std::uint32_t>(HeaderLayout::kSourceLen);
    if (sourceLen > stampsSize) {
      return makeError("offset 56: source name of " + num(sourceLen) +
                       " bytes is longer than the stamps section (" + num(stampsSize) + " bytes)");
    }
    std::uint64_t pos = sourceLen;  // within the section
    const std::uint32_t count = at<std::uint32_t>(HeaderLayout::kUserStampCount);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint64_t offset = kMessageHeaderSize + pos;
      const auto where = [&] {
        return "user stamp " + num(i) + " at offset " + num(offset) + ": ";
      };
      if (stampsSize - pos < kUserStampHeaderSize) {
        return makeError(where() +
                         "its header runs past the stamps section (which ends at offset " +
                         num(kMessageHeaderSize + stampsSize) + ")");
      }
      const std::uint64_t nameLen = loadAt<std::uint16_t>(section, pos + UserStampLayout::kNameLen);
      const auto type = loadAt<std::uint8_t>(section, pos + UserStampLayout::kType);
      const auto pad = loadAt<std::uint8_t>(section, pos + UserStampLayout::kPad);
      const std::uint64_t valueLen =
          loadAt<std::uint32_t>(section, pos + UserStampLayout::kValueLen);
      if (nameLen == 0) return makeError(where() + "empty name");
      if (pad != 0) return makeError(where() + "reserved byte is not zero");
      if (nameLen + valueLen > stampsSize - pos - kUserStampHeaderSize) {
        return makeError(where() + "name of " + num(nameLen) + " bytes and value of " +
                         num(valueLen) + " bytes run past the stamps section");
      }
      const std::uint64_t valueAt = pos + kUserStampHeaderSize + nameLen;
      switch (static_cast<StampType>(type)) {
        case StampType::Int64:
        case StampType::Double:
          if (valueLen != 8) {
            return makeError(where() + "a number stamp has 8 bytes, not " + num(valueLen));
          }
          if (static_cast<StampType>(type) == StampType::Double &&
              !std::isfinite(loadAt<double>(section, valueAt))) {
            return makeError(where() + "value is not a finite number");
          }
          break;
        case StampType::String:
          break;
        default:
          return makeError(where() + "unknown stamp type " + num(type));
      }
      pos = valueAt + valueLen;
    }
    if (padTo8(pos) != stampsSize) {
      return makeError("offset 16: stampsSize " + num(stampsSize) + " differs from the " +
                       num(padTo8(pos)) + " bytes its source and user stamps take (padded to 8)");
    }
    if (!allZero(section.subspan(static_cast<std::size_t>(pos)))) {
      return makeError("offset " + num(kMessageHeaderSize + pos) +
                       ": padding after the stamps is not zero");
    }
    return {};
  }

  Status chunks() {
    const std::uint32_t count = at<std::uint32_t>(HeaderLayout::kChunkCount);
    std::uint64_t offset = kMessageHeaderSize + at<std::uint32_t>(HeaderLayout::kStampsSize);
    for (std::uint32_t i = 0; i < count; ++i) {
      chunkIndex_ = i;
      chunkOffset_ = offset;
      const std::uint64_t left = m_.size() - offset;
      if (left < kChunkHeaderSize) {
        return makeError(where() + "its " + num(kChunkHeaderSize) +
                         "-byte header runs past the end of the message (" + num(m_.size()) +
                         " bytes)");
      }
      const std::uint64_t size = at<std::uint32_t>(offset + ChunkLayout::kSize);
      if (size > left) {
        return makeError(where() + "size " + num(size) + " runs past the end of the message (" +
                         num(m_.size()) + " bytes)");
      }
      if (size < kChunkHeaderSize) {
        return makeError(where() + "size " + num(size) + " is smaller than the " +
                         num(kChunkHeaderSize) + "-byte chunk header");
      }
      if (size % kAlignment != 0) {
        return makeError(where() + "size " + num(size) + " is not a multiple of 8");
      }
      const Bytes chunk =
          m_.subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(size));
      const std::uint64_t bodySize = loadAt<std::uint32_t>(chunk, ChunkLayout::kBodySize);
      if (padTo8(kChunkHeaderSize + bodySize) != size) {
        return makeError(where() + "bodySize " + num(bodySize) + " does not fill the chunk's " +
                         num(size) + " bytes (header 24 + body, padded to 8)");
      }
      const std::uint64_t end = kChunkHeaderSize + bodySize;
      if (!allZero(chunk.subspan(static_cast<std::size_t>(end)))) {
        return makeError(where() + "padding at offset " + num(offset + end) + " is not zero");
      }
      const Bytes body = chunk.subspan(kChunkHeaderSize, static_cast<std::size_t>(bodySize));
      const auto op = loadAt<std::uint8_t>(chunk, ChunkLayout::kOp);
      const auto subkind = loadAt<std::uint16_t>(chunk, ChunkLayout::kSubkind);
      const auto typeId = loadAt<std::uint32_t>(chunk, ChunkLayout::kTypeId);
      const auto kind = loadAt<std::uint8_t>(chunk, ChunkLayout::kKind);
      Status s;
      switch (static_cast<ChunkKind>(kind)) {
        case ChunkKind::Object:
          s = object(op, subkind, typeId, body);
          break;
        case ChunkKind::Resource:
          s = resource(op, subkind, typeId, body);
          break;
        case ChunkKind::Event:
          s = event(op, subkind, typeId, body);
          break;
        default:
          return makeError(where() + "unknown chunk kind " + num(kind) + " (offset " +
                           num(offset + ChunkLayout::kKind) + ")");
      }
      if (!s) return s;
      offset += size;
    }
    if (offset != m_.size()) {
      return makeError("offset " + num(offset) + ": " + num(m_.size() - offset) +
                       " bytes follow the last of the " + num(count) + " chunks");
    }
    return {};
  }

  // Names the chunk being checked, to open an error message.
  std::string where() const {
    return "chunk " + num(chunkIndex_) + " at offset " + num(chunkOffset_) + ": ";
  }

  // Offset of a body byte from the message start.
  std::uint64_t bodyOffset(std::uint64_t inBody) const {
    return chunkOffset_ + kChunkHeaderSize + inBody;
  }

  Status object(std::uint8_t op, std::uint16_t subkind, std::uint32_t typeId, Bytes body) {
    if (op < static_cast<std::uint8_t>(ObjectOp::Add) ||
        op > static_cast<std::uint8_t>(ObjectOp::Delete)) {
      return makeError(where() + "unknown object op " + num(op));
    }
    if (subkind != 0) return makeError(where() + "object subkind " + num(subkind) + " is not 0");
    if (op == static_cast<std::uint8_t>(ObjectOp::Delete)) {
      if (!body.empty()) {
        return makeError(where() + "a delete has an empty body, not " + num(body.size()) +
                         " bytes");
      }
      return {};
    }
    if (body.size() < BodyLayout::kObjectMask) {
      return makeError(where() + "object body of " + num(body.size()) +
                       " bytes has no room for its 8-byte parameter mask");
    }
    const auto mask = loadRaw<std::uint64_t>(body.data());
    if (lastTypeId_ != typeId || !typeLooked_) {
      lastType_ = types_.find(typeId);
      lastTypeId_ = typeId;
      typeLooked_ = true;
    }
    const ObjectType* type = lastType_;
    if (type != nullptr && type->paramCount() < kMaxParams && (mask >> type->paramCount()) != 0) {
      const std::uint64_t beyond =
          type->paramCount() +
          static_cast<std::uint64_t>(std::countr_zero(mask >> type->paramCount()));
      return makeError(where() + "mask " + hex(mask) + " names parameter " + num(beyond) +
                       " but type '" + type->name() + "' has " + num(type->paramCount()) +
                       " parameters");
    }
    std::uint64_t pending = mask;
    std::uint64_t pos = BodyLayout::kObjectMask;
    while (pos < body.size()) {
      const auto entryAt = [&] { return "parameter entry at offset " + num(bodyOffset(pos)); };
      if (body.size() - pos < BodyLayout::kParamEntryHeader) {
        return makeError(where() + entryAt() + " is cut short by the end of the chunk");
      }
      const std::uint64_t index = loadAt<std::uint32_t>(body, pos);
      const std::uint64_t length = loadAt<std::uint32_t>(body, pos + 4);
      if (pending == 0) {
        return makeError(where() + entryAt() + " is for parameter " + num(index) +
                         ", which the mask " + hex(mask) + " does not name");
      }
      const auto expected = static_cast<std::uint64_t>(std::countr_zero(pending));
      if (index != expected) {
        return makeError(where() + entryAt() + " is for parameter " + num(index) +
                         " but the mask " + hex(mask) + " names parameter " + num(expected) +
                         " next");
      }
      const std::uint64_t padded = padTo8(length);
      if (padded > body.size() - pos - BodyLayout::kParamEntryHeader) {
        return makeError(where() + entryAt() + ": length " + num(length) +
                         " runs past the end of the chunk");
      }
      const Bytes value =
          body.subspan(static_cast<std::size_t>(pos + BodyLayout::kParamEntryHeader),
                       static_cast<std::size_t>(length));
      const Bytes padding =
          body.subspan(static_cast<std::size_t>(pos + BodyLayout::kParamEntryHeader + length),
                       static_cast<std::size_t>(padded - length));
      if (!allZero(padding)) return makeError(where() + entryAt() + ": padding is not zero");
      if (type != nullptr) {
        if (Status s = knownParam(*type, static_cast<std::size_t>(index), value, bodyOffset(pos));
            !s) {
          return s;
        }
      }
      pending &= pending - 1;
      pos += BodyLayout::kParamEntryHeader + padded;
    }
    if (pending != 0) {
      return makeError(where() + "mask " + hex(mask) + " names parameter " +
                       num(static_cast<std::uint64_t>(std::countr_zero(pending))) +
                       " but the chunk has no entry for it");
    }
    return {};
  }

  Status knownParam(const ObjectType& type, std::size_t index, Bytes value,
                    std::uint64_t entryOffset) const {
    const ParamDecl& decl = type.param(index);
    const auto what = [&] {
      return where() + "parameter entry at offset " + num(entryOffset) + ": parameter '" +
             decl.name + "' (" + num(index) + ") of type '" + type.name() + "' ";
    };
    if (!validSizeFor(decl.kind, value.size())) {
      const std::size_t fixed = fixedSizeOf(decl.kind);
      if (fixed != 0) {
        return makeError(what() + "has " + num(value.size()) + " bytes; a " +
                         std::string(nameOf(decl.kind)) + " has " + num(fixed));
      }
      return makeError(what() + "has " + num(value.size()) + " bytes, not a multiple of " +
                       num(elementSizeOf(decl.kind)));
    }
    if (holdsFloats(decl.kind)) {
      const std::int64_t bad = decl.kind == ParamKind::FloatArray ? firstNonFinite<float>(value)
                                                                  : firstNonFinite<double>(value);
      if (bad >= 0) {
        return makeError(what() + "holds a NaN or infinite number (element " +
                         num(static_cast<std::uint64_t>(bad)) + ")");
      }
    }
    return {};
  }

  Status resource(std::uint8_t op, std::uint16_t subkind, std::uint32_t typeId, Bytes body) const {
    if ((op & ~kResourceDynamic) != 0) {
      return makeError(where() + "unknown resource op bits " + hex(op & ~kResourceDynamic));
    }
    if (typeId != 0) return makeError(where() + "typeId of a resource must be 0");
    switch (static_cast<ResourceKind>(subkind)) {
      case ResourceKind::Raw:
        return {};
      case ResourceKind::Mesh:
        return mesh(body);
      case ResourceKind::ScalarField:
        return field(body, 1);
      case ResourceKind::VectorField:
        return field(body, 3);
    }
    return makeError(where() + "unknown resource kind " + num(subkind));
  }

  Status mesh(Bytes body) const {
    if (body.size() < BodyLayout::kMeshHeader) {
      return makeError(where() + "mesh body of " + num(body.size()) +
                       " bytes has no room for its 8-byte header");
    }
    const std::uint64_t vertexCount = loadRaw<std::uint32_t>(body.data());
    const std::uint64_t indexCount = loadRaw<std::uint32_t>(body.data() + 4);
    if (indexCount % 3 != 0) {
      return makeError(where() + "mesh index count " + num(indexCount) + " is not a multiple of 3");
    }
    const std::uint64_t needed = BodyLayout::kMeshHeader + vertexCount * 12 + indexCount * 4;
    if (needed != body.size()) {
      return makeError(where() + "a mesh of " + num(vertexCount) + " vertices and " +
                       num(indexCount) + " indices takes " + num(needed) +
                       " bytes, but the body has " + num(body.size()));
    }
    const Bytes xyz =
        body.subspan(BodyLayout::kMeshHeader, static_cast<std::size_t>(vertexCount * 12));
    if (const std::int64_t bad = firstNonFinite<float>(xyz); bad >= 0) {
      return makeError(where() + "mesh vertex " + num(static_cast<std::uint64_t>(bad) / 3) +
                       " has a NaN or infinite coordinate");
    }
    const std::uint64_t indicesAt = BodyLayout::kMeshHeader + vertexCount * 12;
    for (std::uint64_t i = 0; i < indexCount; ++i) {
      const std::uint32_t index = loadRaw<std::uint32_t>(body.data() + indicesAt + i * 4);
      if (index >= vertexCount) {
        return makeError(where() + "mesh index " + num(i) + " (offset " +
                         num(bodyOffset(indicesAt + i * 4)) + ") is " + num(index) +
                         ", not below the vertex count " + num(vertexCount));
      }
    }
    return {};
  }

  Status field(Bytes body, std::uint32_t expectedComponents) const {
    if (body.size() < BodyLayout::kFieldHeader) {
      return makeError(where() + "field body of " + num(body.size()) +
                       " bytes has no room for its " + num(BodyLayout::kFieldHeader) +
                       "-byte header");
    }
    const std::uint32_t nx = loadRaw<std::uint32_t>(body.data());
    const std::uint32_t ny = loadRaw<std::uint32_t>(body.data() + 4);
    const std::uint32_t nz = loadRaw<std::uint32_t>(body.data() + 8);
    const std::uint32_t components = loadRaw<std::uint32_t>(body.data() + 12);
    if (components != expectedComponents) {
      return makeError(where() + "a " + (expectedComponents == 1 ? "scalar" : "vector") +
                       " field has " + num(expectedComponents) + " components, not " +
                       num(components));
    }
    if (firstNonFinite<double>(body.subspan(16, 24)) >= 0) {
      return makeError(where() + "field origin is not finite");
    }
    const double spacing = loadRaw<double>(body.data() + 40);
    if (!std::isfinite(spacing) || spacing <= 0.0) {
      return makeError(where() + "field spacing is not a finite number > 0");
    }
    std::uint64_t bytes = 0;
    if (__builtin_mul_overflow(std::uint64_t{nx}, std::uint64_t{ny}, &bytes) ||
        __builtin_mul_overflow(bytes, std::uint64_t{nz}, &bytes) ||
        __builtin_mul_overflow(bytes, std::uint64_t{components}, &bytes) ||
        __builtin_mul_overflow(bytes, std::uint64_t{sizeof(float)}, &bytes) ||
        __builtin_add_overflow(bytes, std::uint64_t{BodyLayout::kFieldHeader}, &bytes)) {
      return makeError(where() + "field of " + num(nx) + " x " + num(ny) + " x " + num(nz) + " x " +
                       num(components) + " floats overflows 64 bits");
    }
    if (bytes != body.size()) {
      return makeError(where() + "a field of " + num(nx) + " x " + num(ny) + " x " + num(nz) +
                       " x " + num(components) + " floats takes " + num(bytes) +
                       " bytes, but the body has " + num(body.size()));
    }
    if (const std::int64_t bad = firstNonFinite<float>(body.subspan(BodyLayout::kFieldHeader));
        bad >= 0) {
      return makeError(where() + "field value " + num(static_cast<std::uint64_t>(bad)) +
                       " is NaN or infinite");
    }
    return {};
  }

  Status event(std::uint8_t op, std::uint16_t subkind, std::uint32_t typeId, Bytes body) const {
    if (op != 0) return makeError(where() + "event op " + num(op) + " is not 0");
    if (typeId != 0) return makeError(where() + "typeId of an event must be 0");
    if (subkind >= kFirstUserEventKind) return {};
    if (subkind != static_cast<std::uint16_t>(EventKind::Force)) {
      return makeError(where() + "unknown event kind " + num(subkind) + " (user kinds start at " +
                       num(kFirstUserEventKind) + ")");
    }
    if (body.size() != BodyLayout::kForce) {
      return makeError(where() + "a force event has " + num(BodyLayout::kForce) + " bytes, not " +
                       num(body.size()));
    }
    if (firstNonFinite<double>(body) >= 0) {
      return makeError(where() + "force event holds a NaN or infinite number");
    }
    if (loadRaw<double>(body.data() + 72) < 0.0) {
      return makeError(where() + "force event duration is negative");
    }
    return {};
  }

  Bytes m_;
  const ObjectTypeRegistry& types_;
  std::uint32_t chunkIndex_ = 0;
  std::uint64_t chunkOffset_ = 0;
  const ObjectType* lastType_ = nullptr;
  std::uint32_t lastTypeId_ = 0;
  bool typeLooked_ = false;
};

}  // namespace

Result<MessageView> MessageView::parse(std::span<const std::byte> bytes) {
  return parse(bytes, ObjectTypeRegistry::global());
}

Result<MessageView> MessageView::parse(std::span<const std::byte> bytes,
                                       const ObjectTypeRegistry& types) {
  Checker checker(bytes, types);
  if (Status s = checker.run(); !s) return s.error();
  return MessageView(bytes, &types);
}

Result<std::uint64_t> MessageView::peekTotalSize(std::span<const std::byte> bytes) {
  constexpr std::size_t kNeeded = HeaderLayout::kTotalSize + sizeof(std::uint64_t);
  if (bytes.size() < kNeeded) {
    return makeError("need " + num(kNeeded) + " bytes to read a message size, got " +
                     num(bytes.size()));
  }
  const auto magic = loadRaw<std::uint32_t>(bytes.data() + HeaderLayout::kMagic);
  if (magic != kMagic) {
    return makeError("offset 0: magic " + hex(magic) + " is not 'VRFM': not a vrflow message");
  }
  const auto version = loadRaw<std::uint16_t>(bytes.data() + HeaderLayout::kVersion);
  if (version != kLayoutVersion) {
    return makeError("offset 4: layout version " + num(version) + " is not supported");
  }
  const auto totalSize = loadRaw<std::uint64_t>(bytes.data() + HeaderLayout::kTotalSize);
  if (totalSize < kMessageHeaderSize || totalSize % kAlignment != 0) {
    return makeError("offset 8: totalSize " + num(totalSize) + " cannot be a message size");
  }
  return totalSize;
}

}  // namespace vrflow::msg
