// On-screen tiles under a real X server (Xvfb, Mesa's GLX): the same renderer draws into a
// window as into OSMesa, and the window's pointer and keys come out as input events.
#include "vrflow/viewer/window.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "vrflow/viewer/renderer.hpp"
#include "wall_scene.hpp"
#include "xvfb.hpp"

namespace vrflow::viewer {
namespace {

using testing::Xvfb;

// Display :33 (this test's own number among the wall tests' 33-39), two screens of different
// sizes so a window on screen 1 is told apart from one on screen 0.
constexpr int kDisplay = 33;

class OnScreen : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    auto started = Xvfb::start(kDisplay, {{320, 240}, {400, 300}}, why);
    if (!started) GTEST_SKIP() << "no X server for on-screen tests: " << why;
    server_.emplace(std::move(*started));
  }
  std::optional<Xvfb> server_;
};

RenderSettings tileSettings() {
  RenderSettings settings;
  settings.width = 160;
  settings.height = 100;
  settings.supersample = 1;  // on screen, one sample per pixel
  settings.tile = Tile{1, 0, 2, 2};
  return settings;
}

// The same scene, camera and tile, drawn on screen (pixels read back before the swap) and
// headless: both contexts are Mesa's llvmpipe, and only the context differs.
TEST_F(OnScreen, AWindowTileShowsTheSamePixelsAsTheHeadlessTile) {
  const SceneCache scene = testing::wallScene();
  const RenderSettings settings = tileSettings();
  auto headless = Renderer::create(settings);
  ASSERT_TRUE(headless.ok()) << headless.error().message;
  const auto expected = headless->render(scene, testing::wallCamera());
  ASSERT_TRUE(expected.ok()) << expected.error().message;

  auto window = Window::open(
      {server_->display(1), settings.width, settings.height, false, 30, 40, "window-test"});
  ASSERT_TRUE(window.ok()) << window.error().message;
  auto onScreen = Renderer::create(settings, *window);
  ASSERT_TRUE(onScreen.ok()) << onScreen.error().message;
  EXPECT_NE(onScreen->description().find("llvmpipe"), std::string::npos) << onScreen->description();
  const auto shown = onScreen->render(scene, testing::wallCamera());
  ASSERT_TRUE(shown.ok()) << shown.error().message;
  window->swap();
  ASSERT_EQ(shown->width, expected->width);
  ASSERT_EQ(shown->height, expected->height);
  int differing = 0, inside = 0, coloured = 0;
  for (int y = 0; y < settings.height; ++y) {
    for (int x = 0; x < settings.width; ++x) {
      const auto a = shown->at(x, y), b = expected->at(x, y);
      if (std::max({a[0], a[1], a[2]}) - std::min({a[0], a[1], a[2]}) > 60) ++coloured;
      if (a == b) continue;
      ++differing;
      if (!testing::onAnEdge(*expected, x, y)) ++inside;
    }
  }
  RecordProperty("differing_pixels", differing);
  // Allowed: edge pixels only, at most 0.1% of the tile (measured: see the README).
  EXPECT_EQ(inside, 0) << differing << " pixels differ";
  EXPECT_LE(differing, settings.width * settings.height / 1000) << differing << " pixels differ";
  EXPECT_GT(coloured, 500);  // the objects are there, not two empty pictures
  // Drawing again in the headless context after the window's still works (two contexts, one
  // process, one set of GL entry points).
  const auto again = headless->render(scene, testing::wallCamera());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->rgb, expected->rgb);
}

// Pointer and keys injected through XTest (xdotool) into a window placed on screen 1.
TEST_F(OnScreen, PointerAndKeysOfTheWindowComeOutAsEventsInWindowPixels) {
  const RenderSettings settings = tileSettings();
  auto window = Window::open(
      {server_->display(1), settings.width, settings.height, false, 30, 40, "window-test"});
  ASSERT_TRUE(window.ok()) << window.error().message;
  auto renderer = Renderer::create(settings, *window);
  ASSERT_TRUE(renderer.ok());
  window->swap();
  (void)window->poll();
  // GLFW waits a tenth of a second at most for the window to be mapped: on a loaded machine
  // the clicks could otherwise land on the root window.
  ASSERT_EQ(testing::xdotool(server_->display(1),
                             {"search", "--sync", "--onlyvisible", "--name", "window-test"}),
            0);
  ASSERT_EQ(
      testing::xdotool(server_->display(1), {"mousemove", "--screen", "1", "--sync", "80", "65",
                                             "mousedown", "1", "mouseup", "1", "key", "a"}),
      0);
  std::vector<WindowEvent> events;
  for (int tries = 0; tries < 500 && events.size() < 5; ++tries) {
    auto more = window->poll();
    events.insert(events.end(), more.begin(), more.end());
    usleep(10000);
  }
  std::vector<msg::PointerEvent> presses, releases;
  std::vector<msg::KeyEvent> keys;
  for (const auto& e : events) {
    if (const auto* p = std::get_if<msg::PointerEvent>(&e)) {
      if (p->action == msg::PointerAction::Press) presses.push_back(*p);
      if (p->action == msg::PointerAction::Release) releases.push_back(*p);
    } else {
      keys.push_back(std::get<msg::KeyEvent>(e));
    }
  }
  ASSERT_EQ(presses.size(), 1u);
  ASSERT_EQ(releases.size(), 1u);
  // Screen (80, 65) is window (50, 25): the window's corner is at (30, 40).
  EXPECT_DOUBLE_EQ(presses[0].x, 50.0);
  EXPECT_DOUBLE_EQ(presses[0].y, 25.0);
  EXPECT_EQ(presses[0].button, msg::PointerButton::Left);
  EXPECT_EQ(presses[0].buttons, msg::buttonBit(msg::PointerButton::Left));
  EXPECT_EQ(releases[0].buttons, 0u);
  EXPECT_GT(presses[0].time, 1.7e9);  // CLOCK_REALTIME seconds
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_EQ(keys[0].key, 'A');
  EXPECT_EQ(keys[0].action, msg::KeyAction::Press);
  EXPECT_EQ(keys[1].action, msg::KeyAction::Release);
}

// Full screen on screen 0 (320 x 240): the window covers the screen and the renderer draws it.
TEST_F(OnScreen, AFullScreenWindowCoversItsScreen) {
  auto window = Window::open({server_->display(0), 320, 240, true, 0, 0, "full"});
  ASSERT_TRUE(window.ok()) << window.error().message;
  EXPECT_EQ(window->width(), 320);
  EXPECT_EQ(window->height(), 240);
  RenderSettings settings;
  settings.width = 320;
  settings.height = 240;
  settings.supersample = 1;
  auto renderer = Renderer::create(settings, *window);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const auto image = renderer->render(testing::wallScene(), testing::wallCamera());
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->width, 320);
}

TEST(Window, ADisplayThatDoesNotAnswerIsAnErrorNamingIt) {
  auto window = Window::open({":39.5", 64, 64, false, 0, 0, "nowhere"});
  ASSERT_FALSE(window.ok());
  EXPECT_NE(window.error().message.find(":39.5"), std::string::npos) << window.error().message;
}

TEST_F(OnScreen, ARendererRefusesAWindowOfAnotherSizeOrSupersampling) {
  auto window = Window::open({server_->display(0), 64, 48, false, 0, 0, "sizes"});
  ASSERT_TRUE(window.ok()) << window.error().message;
  RenderSettings settings;
  settings.width = 64;
  settings.height = 50;
  settings.supersample = 1;
  auto wrongSize = Renderer::create(settings, *window);
  ASSERT_FALSE(wrongSize.ok());
  EXPECT_NE(wrongSize.error().message.find("64x48"), std::string::npos);
  settings.height = 48;
  settings.supersample = 2;
  auto supersampled = Renderer::create(settings, *window);
  ASSERT_FALSE(supersampled.ok());
  EXPECT_NE(supersampled.error().message.find("supersample"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::viewer
