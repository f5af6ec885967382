#include "vrflow/message/input_events.hpp"

#include <array>

#include "vrflow/message/packed.hpp"

namespace vrflow::msg {

// Pointer body: action u32 @0, button u32 @4, buttons u32 @8, modifiers u32 @12, x f64 @16,
// y f64 @24, scroll f64 @32, ray origin 3 f64 @40, ray direction 3 f64 @64, time f64 @88.
void addPointerEvent(MessageBuilder& builder, std::uint64_t source, const PointerEvent& event) {
  std::array<std::byte, kPointerEventSize> body{};
  storeRaw(body.data() + 0, static_cast<std::uint32_t>(event.action));
  storeRaw(body.data() + 4, static_cast<std::uint32_t>(event.button));
  storeRaw(body.data() + 8, event.buttons);
  storeRaw(body.data() + 12, event.modifiers);
  storeRaw(body.data() + 16, event.x);
  storeRaw(body.data() + 24, event.y);
  storeRaw(body.data() + 32, event.scroll);
  storeRaw(body.data() + 40, event.rayOrigin);
  storeRaw(body.data() + 64, event.rayDirection);
  storeRaw(body.data() + 88, event.time);
  builder.addEvent(source, kPointerEventKind, body);
}

// Key body: key i32 @0, action u32 @4, modifiers u32 @8, 4 bytes of zero, time f64 @16.
void addKeyEvent(MessageBuilder& builder, std::uint64_t source, const KeyEvent& event) {
  std::array<std::byte, kKeyEventSize> body{};
  storeRaw(body.data() + 0, event.key);
  storeRaw(body.data() + 4, static_cast<std::uint32_t>(event.action));
  storeRaw(body.data() + 8, event.modifiers);
  storeRaw(body.data() + 16, event.time);
  builder.addEvent(source, kKeyEventKind, body);
}

std::optional<PointerEvent> pointerEvent(const EventView& event) {
  const auto body = event.payload();
  if (event.kind() != kPointerEventKind || body.size() != kPointerEventSize) return std::nullopt;
  const auto action = loadRaw<std::uint32_t>(body.data() + 0);
  const auto button = loadRaw<std::uint32_t>(body.data() + 4);
  if (action > static_cast<std::uint32_t>(PointerAction::Scroll) ||
      button > static_cast<std::uint32_t>(PointerButton::Middle))
    return std::nullopt;
  PointerEvent out;
  out.action = static_cast<PointerAction>(action);
  out.button = static_cast<PointerButton>(button);
  out.buttons = loadRaw<std::uint32_t>(body.data() + 8);
  out.modifiers = loadRaw<std::uint32_t>(body.data() + 12);
  out.x = loadRaw<double>(body.data() + 16);
  out.y = loadRaw<double>(body.data() + 24);
  out.scroll = loadRaw<double>(body.data() + 32);
  out.rayOrigin = loadRaw<Vec3>(body.data() + 40);
  out.rayDirection = loadRaw<Vec3>(body.data() + 64);
  out.time = loadRaw<double>(body.data() + 88);
  return out;
}

std::optional<KeyEvent> keyEvent(const EventView& event) {
  const auto body = event.payload();
  if (event.kind() != kKeyEventKind || body.size() != kKeyEventSize) return std::nullopt;
  const auto action = loadRaw<std::uint32_t>(body.data() + 4);
  if (action > static_cast<std::uint32_t>(KeyAction::Repeat)) return std::nullopt;
  KeyEvent out;
  out.key = loadRaw<std::int32_t>(body.data() + 0);
  out.action = static_cast<KeyAction>(action);
  out.modifiers = loadRaw<std::uint32_t>(body.data() + 8);
  out.time = loadRaw<double>(body.data() + 16);
  return out;
}

}  // namespace vrflow::msg
