#pragma once
// The capture stamps a frame carries from the camera to the interactors: its capture time and
// its capture iteration (the frame's number at the capture module), copied by the silhouette,
// hull and user animator modules onto what they derive from it, and the capture iteration of the
// user an interactor used, on the interactor's output. They measure the capture-to-interactor
// latency in frames (nodes/camera/README.md, "Latency"). Needs no OpenCV (vrflow::camera_user).

#include <cstdint>
#include <optional>
#include <string_view>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::camera {

/// Int64 user stamp: the capture time (ns; the capture host's steady clock, or frame / fps).
inline constexpr std::string_view kCaptureStamp = "capture-ns";
/// Int64 user stamp: the capture module's iteration that took the frame.
inline constexpr std::string_view kCaptureIterationStamp = "capture-iteration";
/// Int64 user stamp on an interactor's output: the capture iteration of the user it used.
inline constexpr std::string_view kUsedCaptureIterationStamp = "user-capture-iteration";

/// The message's Int64 user stamp `name`, nullopt when it has none.
std::optional<std::int64_t> int64Stamp(const msg::MessageView& message, std::string_view name);

/// Stamps `to` with the capture time and capture iteration `from` carries (those it has).
void copyCaptureStamps(const msg::MessageView& from, msg::MessageBuilder& to);

}  // namespace vrflow::camera
