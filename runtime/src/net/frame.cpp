#include "vrflow/net/frame.hpp"

#include <algorithm>
#include <cstring>

namespace vrflow::net {
namespace {

void put32(std::byte* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}

uint32_t get32(const std::byte* in) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(in[i]) << (8 * i);
  return v;
}

}  // namespace

void encodeHeader(const FrameHeader& header, std::byte* out) {
  put32(out, kFrameMagic);
  out[4] = static_cast<std::byte>(header.type);
  out[5] = std::byte{0};
  out[6] = std::byte{0};
  out[7] = std::byte{0};
  put32(out + 8, header.channel);
  put32(out + 12, header.length);
}

std::size_t controlPayloadBytes(FrameType type) {
  switch (type) {
    case FrameType::Hello:
      return 16 + kNonceBytes;
    case FrameType::Challenge:
      return kNonceBytes + kMacBytes;
    case FrameType::Auth:
      return kMacBytes;
    case FrameType::Message:
      return 0;
    case FrameType::Close:
      return 0;
    case FrameType::Credit:
      return 4;
    case FrameType::Heartbeat:
      return 8;
    case FrameType::Bye:
      return 0;
  }
  return 0;
}

const char* frameTypeName(FrameType type) {
  switch (type) {
    case FrameType::Hello:
      return "hello";
    case FrameType::Challenge:
      return "challenge";
    case FrameType::Auth:
      return "auth";
    case FrameType::Message:
      return "message";
    case FrameType::Close:
      return "close";
    case FrameType::Credit:
      return "credit";
    case FrameType::Heartbeat:
      return "heartbeat";
    case FrameType::Bye:
      return "bye";
  }
  return "unknown";
}

Status FrameReader::startPayload() {
  const std::byte* h = header_.data();
  if (get32(h) != kFrameMagic) return makeError("malformed frame: bad magic number");
  if (h[5] != std::byte{0} || h[6] != std::byte{0} || h[7] != std::byte{0}) {
    return makeError("malformed frame: reserved header bytes are not zero");
  }
  const auto type = static_cast<uint8_t>(h[4]);
  if (type < 1 || type > 8) {
    return makeError("malformed frame: unknown frame type " + std::to_string(type));
  }
  current_.type = static_cast<FrameType>(type);
  current_.channel = get32(h + 8);
  current_.length = get32(h + 12);
  const bool handshake = current_.type == FrameType::Hello ||
                         current_.type == FrameType::Challenge || current_.type == FrameType::Auth;
  if (!authenticated_ && !handshake) {
    return makeError(std::string("unauthenticated peer sent a '") + frameTypeName(current_.type) +
                     "' frame before completing the challenge-response");
  }
  if (authenticated_ && handshake) {
    return makeError(std::string("malformed frame: '") + frameTypeName(current_.type) +
                     "' after authentication");
  }
  filled_ = 0;
  inPayload_ = true;
  if (current_.type == FrameType::Message) {
    if (current_.length > maxFrameBytes_) {
      return makeError("frame of " + std::to_string(current_.length) +
                       " bytes exceeds the limit of " + std::to_string(maxFrameBytes_) + " bytes");
    }
    if (current_.length == 0) return makeError("malformed frame: empty message");
    target_ = allocate_(current_);
    if (target_.size() != current_.length) {
      return makeError("cannot take a message of " + std::to_string(current_.length) +
                       " bytes (shared memory exhausted?)");
    }
  } else {
    const std::size_t expected = controlPayloadBytes(current_.type);
    if (current_.length != expected) {
      return makeError(std::string("malformed frame: '") + frameTypeName(current_.type) + "' of " +
                       std::to_string(current_.length) + " bytes (expected " +
                       std::to_string(expected) + ")");
    }
    target_ = std::span<std::byte>(control_.data(), expected);
  }
  if (target_.empty()) return finishPayload();
  return {};
}

Status FrameReader::finishPayload() {
  inPayload_ = false;
  headerFill_ = 0;
  const auto payload = std::span<const std::byte>(target_.data(), target_.size());
  target_ = {};
  return deliver_(current_, payload);
}

Status FrameReader::feed(std::span<const std::byte> data) {
  while (!data.empty()) {
    if (!inPayload_) {
      const std::size_t take = std::min(kFrameHeaderBytes - headerFill_, data.size());
      std::memcpy(header_.data() + headerFill_, data.data(), take);
      headerFill_ += take;
      data = data.subspan(take);
      if (headerFill_ < kFrameHeaderBytes) break;
      if (auto status = startPayload(); !status) return status;
      continue;
    }
    const std::size_t take = std::min(target_.size() - filled_, data.size());
    std::memcpy(target_.data() + filled_, data.data(), take);
    filled_ += take;
    data = data.subspan(take);
    if (filled_ == target_.size()) {
      if (auto status = finishPayload(); !status) return status;
    }
  }
  return {};
}

std::span<std::byte> FrameReader::directTarget() {
  if (!inPayload_) return {};
  return target_.subspan(filled_);
}

Status FrameReader::advanceDirect(std::size_t bytes) {
  if (!inPayload_ || bytes > target_.size() - filled_) {
    return makeError("frame reader: direct read past the payload");
  }
  filled_ += bytes;
  if (filled_ == target_.size()) return finishPayload();
  return {};
}

}  // namespace vrflow::net
