#include "vrflow/message/input_events.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "sample_messages.hpp"

namespace vrflow::msg {
namespace {

using testing::finished;

TEST(InputEvents, PointerAndKeyEventsRoundTripThroughAMessage) {
  VectorSink sink;
  MessageBuilder builder(sink);
  PointerEvent pointer;
  pointer.action = PointerAction::Press;
  pointer.button = PointerButton::Right;
  pointer.buttons = buttonBit(PointerButton::Right) | buttonBit(PointerButton::Left);
  pointer.modifiers = 2;
  pointer.x = 320.5;
  pointer.y = 17.25;
  pointer.scroll = -1.0;
  pointer.rayOrigin = {1, 2, 3};
  pointer.rayDirection = {0, 0, -1};
  pointer.time = 1795000000.125;
  KeyEvent key{'W', KeyAction::Repeat, 1, 1795000000.5};
  addPointerEvent(builder, 7, pointer);
  addKeyEvent(builder, 8, key);
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  std::vector<ChunkView> chunks(view->begin(), view->end());
  ASSERT_EQ(chunks.size(), 2u);
  const auto first = chunks[0].asEvent();
  const auto second = chunks[1].asEvent();
  ASSERT_TRUE(first && second);
  EXPECT_EQ(first->id(), 7u);
  EXPECT_EQ(second->id(), 8u);
  EXPECT_EQ(pointerEvent(*first), pointer);
  EXPECT_EQ(keyEvent(*second), key);
  // Each reader refuses the other's chunk.
  EXPECT_FALSE(keyEvent(*first));
  EXPECT_FALSE(pointerEvent(*second));
}

TEST(InputEvents, MalformedBodiesAreRefused) {
  const std::array<std::byte, kPointerEventSize - 8> shortBody{};
  EXPECT_FALSE(pointerEvent(EventView(1, kPointerEventKind, shortBody)));
  std::array<std::byte, kPointerEventSize> badAction{};
  badAction[0] = std::byte{9};
  EXPECT_FALSE(pointerEvent(EventView(1, kPointerEventKind, badAction)));
  std::array<std::byte, kKeyEventSize> badKey{};
  badKey[4] = std::byte{3};
  EXPECT_FALSE(keyEvent(EventView(1, kKeyEventKind, badKey)));
  const std::array<std::byte, kKeyEventSize> goodKey{};
  EXPECT_TRUE(keyEvent(EventView(1, kKeyEventKind, goodKey)));
}

}  // namespace
}  // namespace vrflow::msg
