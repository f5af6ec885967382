#include "vrflow/message/stamps.hpp"

#include "vrflow/message/packed.hpp"

namespace vrflow::msg {
namespace {

// Size of the packed user stamp at the front of `rest`, or rest.size() when it does not fit
// (iteration then ends instead of reading past the span).
std::size_t packedSize(std::span<const std::byte> rest) {
  const std::uint64_t nameLen = loadAt<std::uint16_t>(rest, UserStampLayout::kNameLen);
  const std::uint64_t valueLen = loadAt<std::uint32_t>(rest, UserStampLayout::kValueLen);
  const std::uint64_t size = kUserStampHeaderSize + nameLen + valueLen;
  return size <= rest.size() ? static_cast<std::size_t>(size) : rest.size();
}

}  // namespace

std::optional<std::int64_t> UserStampView::asInt64() const {
  if (type_ != StampType::Int64 || value_.size() != 8) return std::nullopt;
  return loadRaw<std::int64_t>(value_.data());
}

std::optional<double> UserStampView::asDouble() const {
  if (type_ != StampType::Double || value_.size() != 8) return std::nullopt;
  return loadRaw<double>(value_.data());
}

std::optional<std::string_view> UserStampView::asString() const {
  if (type_ != StampType::String) return std::nullopt;
  return std::string_view(reinterpret_cast<const char*>(value_.data()), value_.size());
}

UserStamp UserStampView::toUserStamp() const {
  UserStamp stamp{std::string(name_), std::int64_t{0}};
  if (const auto i = asInt64()) {
    stamp.value = *i;
  } else if (const auto d = asDouble()) {
    stamp.value = *d;
  } else if (const auto s = asString()) {
    stamp.value = std::string(*s);
  }
  return stamp;
}

UserStampView UserStampRange::Iterator::operator*() const {
  const std::uint64_t nameLen = loadAt<std::uint16_t>(rest_, UserStampLayout::kNameLen);
  const std::uint64_t valueLen = loadAt<std::uint32_t>(rest_, UserStampLayout::kValueLen);
  const auto type = static_cast<StampType>(loadAt<std::uint8_t>(rest_, UserStampLayout::kType));
  const auto name = sliceAt(rest_, kUserStampHeaderSize, nameLen);
  const auto value = sliceAt(rest_, kUserStampHeaderSize + nameLen, valueLen);
  return UserStampView(std::string_view(reinterpret_cast<const char*>(name.data()), name.size()),
                       type, value);
}

UserStampRange::Iterator& UserStampRange::Iterator::operator++() {
  const std::size_t size = packedSize(rest_);
  rest_ = rest_.subspan(size);
  left_ = rest_.empty() ? 0 : left_ - 1;
  return *this;
}

std::optional<UserStampView> UserStampRange::find(std::string_view name) const {
  for (const UserStampView stamp : *this) {
    if (stamp.name() == name) return stamp;
  }
  return std::nullopt;
}

Stamps StampsView::toStamps() const {
  Stamps stamps;
  stamps.source = std::string(source);
  stamps.iteration = iteration;
  stamps.simTime = simTime;
  stamps.timeStep = timeStep;
  stamps.sendTimeNs = sendTimeNs;
  stamps.user.reserve(user.size());
  for (const UserStampView stamp : user) stamps.user.push_back(stamp.toUserStamp());
  return stamps;
}

}  // namespace vrflow::msg
