#pragma once

#include <cstdint>
#include <optional>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/chunk_views.hpp"
#include "vrflow/message/values.hpp"

// Events of people in the loop: a window's or a device's pointer, and keys. They travel as user
// event chunks (kinds below) whose chunk id names the source (a viewer tile, a device); the
// on-screen viewer publishes them on its `events` output and the `input` package reads them.
// The body layouts are fixed, little-endian (docs/message-layout.md, "Input events").

namespace vrflow::msg {

/// Event chunk kinds of input events (user kinds, >= kFirstUserEventKind).
inline constexpr std::uint16_t kPointerEventKind = 1100;
inline constexpr std::uint16_t kKeyEventKind = 1101;

/// What happened to a pointer.
enum class PointerAction : std::uint32_t { Move = 0, Press = 1, Release = 2, Scroll = 3 };

/// Buttons, as bits of PointerEvent::buttons and values of PointerEvent::button.
enum class PointerButton : std::uint32_t { Left = 0, Right = 1, Middle = 2 };
inline constexpr std::uint32_t buttonBit(PointerButton b) {
  return 1u << static_cast<std::uint32_t>(b);
}

/// A pointer event: a mouse over a window, or a device that points. The world ray through the
/// pointer is what picking needs; a window fills it from the camera of its tile, a 3D device
/// from its pose (origin = the device tip, direction = where it points).
struct PointerEvent {
  PointerAction action = PointerAction::Move;
  PointerButton button = PointerButton::Left;  ///< the button pressed or released
  std::uint32_t buttons = 0;                   ///< buttonBit()s held after the event
  std::uint32_t modifiers = 0;                 ///< GLFW's modifier bits (shift 1, ctrl 2, alt 4)
  double x = 0.0, y = 0.0;                     ///< window pixels from the top-left; 0 for devices
  double scroll = 0.0;                         ///< Scroll: vertical offset (lines)
  Vec3 rayOrigin{};                            ///< world point of the pointer (m)
  Vec3 rayDirection{};                         ///< unit world direction (0 0 0 when unknown)
  double time = 0.0;  ///< when it happened: seconds on CLOCK_REALTIME, as the trace stamps
  bool operator==(const PointerEvent&) const = default;
};

/// What happened to a key.
enum class KeyAction : std::uint32_t { Release = 0, Press = 1, Repeat = 2 };

/// A key event: `key` is GLFW's key code (printable keys are their upper-case ASCII code).
struct KeyEvent {
  std::int32_t key = 0;
  KeyAction action = KeyAction::Press;
  std::uint32_t modifiers = 0;
  double time = 0.0;
  bool operator==(const KeyEvent&) const = default;
};

/// Body sizes (bytes).
inline constexpr std::size_t kPointerEventSize = 96;
inline constexpr std::size_t kKeyEventSize = 24;

/// Appends an event chunk whose id is `source`.
void addPointerEvent(MessageBuilder& builder, std::uint64_t source, const PointerEvent& event);
void addKeyEvent(MessageBuilder& builder, std::uint64_t source, const KeyEvent& event);

/// The event an event chunk holds, or nullopt when it is of another kind or malformed.
std::optional<PointerEvent> pointerEvent(const EventView& event);
std::optional<KeyEvent> keyEvent(const EventView& event);

}  // namespace vrflow::msg
