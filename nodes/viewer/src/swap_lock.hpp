#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/stamps.hpp"

// The viewer's side of the software swap-lock: after drawing frame k a tile sends a `ready`
// stamps-only message (int stamps frame-min = frame-max = k); a tree of `merge` filters
// (stamps "frame-min:min, frame-max:max") joins every tile's, broadcast filters bring the
// joined one back to every tile's `swap` input, and the tile shows frame k when it arrives (one
// iteration later). A release whose min and max differ, or name another frame, is an error.

namespace vrflow::viewer {

/// Stamps a `ready` message for frame `frame`; with `readyNs`, also the int stamp `ready-ns`:
/// when the frame was drawn (CLOCK_REALTIME, nanoseconds), for a release at an absolute time.
void stampReady(msg::MessageBuilder& builder, std::uint64_t frame,
                std::optional<std::int64_t> readyNs = std::nullopt);

/// CLOCK_REALTIME now, in nanoseconds (the clock the trace and the swap logs stamp).
std::int64_t realtimeNs();

/// When every tile swaps the frame a release lets through: the latest tile's `ready-ns` (the
/// merges join it with `ready-ns:max`) plus `marginNs`; nullopt when the release carries none.
std::optional<std::int64_t> swapTime(const msg::StampsView& stamps, std::int64_t marginNs);

/// Sleeps until CLOCK_REALTIME reaches `ns` (at once when it has passed).
void sleepUntilRealtime(std::int64_t ns);

/// The frame a release message lets through: its frame-min when it equals frame-max; nullopt
/// for a message without them (the initial message that starts the cycle); an error when they
/// differ.
Result<std::optional<std::uint64_t>> releasedFrame(const msg::StampsView& stamps);

/// One line per shown frame, `frame seconds` (CLOCK_REALTIME, as the trace stamps), for
/// measuring the skew between tiles.
class SwapLog {
 public:
  /// Opens `path` for writing (empty: no log).
  static Result<SwapLog> open(const std::string& path);
  SwapLog(SwapLog&& other) noexcept;
  SwapLog& operator=(SwapLog&&) = delete;
  ~SwapLog();
  /// Records that `frame` was shown now.
  void shown(std::uint64_t frame);

 private:
  explicit SwapLog(std::FILE* file) : file_(file) {}
  std::FILE* file_ = nullptr;
};

}  // namespace vrflow::viewer
