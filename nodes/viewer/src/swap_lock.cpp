#include "swap_lock.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>

namespace vrflow::viewer {

void stampReady(msg::MessageBuilder& builder, std::uint64_t frame,
                std::optional<std::int64_t> readyNs) {
  builder.setStampsOnly(true);
  builder.addInt64Stamp("frame-min", static_cast<std::int64_t>(frame));
  builder.addInt64Stamp("frame-max", static_cast<std::int64_t>(frame));
  if (readyNs) builder.addInt64Stamp("ready-ns", *readyNs);
}

std::int64_t realtimeNs() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

std::optional<std::int64_t> swapTime(const msg::StampsView& stamps, std::int64_t marginNs) {
  const auto ready = stamps.user.find("ready-ns");
  const auto ns = ready ? ready->asInt64() : std::nullopt;
  if (!ns) return std::nullopt;
  return *ns + marginNs;
}

void sleepUntilRealtime(std::int64_t ns) {
  timespec until{};
  until.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  until.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  // Interrupted by a signal: sleep on for what is left (a stop ends the run through wait()).
  while (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

Result<std::optional<std::uint64_t>> releasedFrame(const msg::StampsView& stamps) {
  const auto low = stamps.user.find("frame-min");
  const auto high = stamps.user.find("frame-max");
  if (!low && !high) return std::optional<std::uint64_t>();
  const auto a = low ? low->asInt64() : std::nullopt;
  const auto b = high ? high->asInt64() : std::nullopt;
  if (!a || !b || *a < 0) {
    return makeError("the swap release carries no valid int stamps 'frame-min' and 'frame-max'");
  }
  if (*a != *b) {
    return makeError("the swap release joins frames " + std::to_string(*a) + " to " +
                     std::to_string(*b) +
                     ": the tiles are out of step (join every tile's 'ready' with merge filters "
                     "stamped 'frame-min:min, frame-max:max')");
  }
  return std::optional<std::uint64_t>(static_cast<std::uint64_t>(*a));
}

Result<SwapLog> SwapLog::open(const std::string& path) {
  if (path.empty()) return SwapLog(nullptr);
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return makeError("cannot write '" + path + "': " + std::strerror(errno));
  return SwapLog(file);
}

SwapLog::SwapLog(SwapLog&& other) noexcept : file_(other.file_) {
  other.file_ = nullptr;
}

SwapLog::~SwapLog() {
  if (file_) std::fclose(file_);
}

void SwapLog::shown(std::uint64_t frame) {
  if (!file_) return;
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  std::fprintf(file_, "%llu %lld.%09ld\n", static_cast<unsigned long long>(frame),
               static_cast<long long>(t.tv_sec), t.tv_nsec);
  std::fflush(file_);
}

}  // namespace vrflow::viewer
