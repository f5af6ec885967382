// Keyframe files (the scripted device), picking, and opening devices by their spec: values,
// and one clear error per bad input.
#include "vrflow/input/keyframes.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "process_helpers.hpp"
#include "vrflow/input/evdev_device.hpp"
#include "vrflow/input/pick.hpp"

namespace vrflow::input {
namespace {

std::string errorOf(const std::string& text) {
  auto track = KeyframeTrack::parse(text, "moves.keys");
  return track ? std::string("(parsed)") : track.error().message;
}

TEST(Keyframes, InterpolatePositionsAndHoldButtonsOfTheLastKey) {
  auto track = KeyframeTrack::parse(
      "# a press and a drag\n0 0 0 0\n1 1 2 0 1  # pressed\n\n3 3 2 0 0 0 -1 0\n", "moves.keys");
  ASSERT_TRUE(track) << track.error().message;
  ASSERT_EQ(track->keys().size(), 3u);
  const auto half = track->at(0.5);
  EXPECT_EQ(half.position, (msg::Vec3{0.5, 1, 0}));
  EXPECT_EQ(half.velocity, (msg::Vec3{1, 2, 0}));
  EXPECT_EQ(half.buttons, 0u);
  const auto two = track->at(2.0);
  EXPECT_EQ(two.position, (msg::Vec3{2, 2, 0}));
  EXPECT_EQ(two.buttons, 1u);
  EXPECT_EQ(track->at(-1).position, (msg::Vec3{0, 0, 0}));  // before the first key
  const auto after = track->at(10);
  EXPECT_EQ(after.position, (msg::Vec3{3, 2, 0}));
  EXPECT_EQ(after.direction, (msg::Vec3{0, -1, 0}));
  EXPECT_EQ(after.velocity, (msg::Vec3{0, 0, 0}));
}

TEST(Keyframes, MalformedFilesGiveOneErrorNamingFileAndLine) {
  EXPECT_EQ(errorOf("0 0 0 0\n1 1 x 0\n"), "moves.keys:2: field 3 is not a finite number");
  EXPECT_EQ(errorOf("0 0 0 0\n1 1 nan 0\n"), "moves.keys:2: field 3 is not a finite number");
  EXPECT_EQ(errorOf("0 0 0\n"),
            "moves.keys:1: a key is TIME X Y Z [BUTTONS [DX DY DZ]], got 3 numbers");
  EXPECT_EQ(errorOf("0 0 0 0\n0 1 0 0\n"),
            "moves.keys:2: time 0.000000 is not after the previous key's");
  EXPECT_EQ(errorOf("0 0 0 0 9\n"),
            "moves.keys:1: BUTTONS must be a bit mask from 0 to 7 (1 left, 2 right, 4 middle)");
  EXPECT_EQ(errorOf("0 0 0 0 1 0 0 0\n"), "moves.keys:1: the direction is zero");
  EXPECT_EQ(errorOf("# nothing\n\n"), "moves.keys: no keyframe in the file");
  auto missing = KeyframeTrack::load("/nonexistent/moves.keys");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "/nonexistent/moves.keys: cannot read the keyframe file");
}

TEST(Devices, BadSpecsAndMissingNodesAreOneErrorNamingThem) {
  auto bad = openDevice("joystick");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("device 'joystick': give script:FILE"), std::string::npos);
  EXPECT_FALSE(openDevice("script:"));
  DeviceOptions strict;
  strict.hotplug = false;
  auto missing = openDevice("evdev:/dev/input/event-vrflow-missing", strict);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message,
            "evdev:/dev/input/event-vrflow-missing: cannot open the input device node (No such "
            "file or directory; set hotplug to wait for it)");
  testing::TempDir dir;
  const auto notDevice = dir.write("plain.txt", "not an input device\n");
  auto plain = openDevice("evdev:" + notDevice, strict);
  ASSERT_FALSE(plain);
  EXPECT_NE(plain.error().message.find("evdev:" + notDevice + ": not an input device"),
            std::string::npos)
      << plain.error().message;
  auto plugin = openDevice("plugin:" + notDevice);
  ASSERT_FALSE(plugin);
  EXPECT_NE(plugin.error().message.find("plugin:" + notDevice + ": cannot load it"),
            std::string::npos);
}

// With hot-plug on, a node that does not exist yet is waited for: the device reports itself
// absent, at its origin, and the module keeps running.
TEST(Devices, HotplugWaitsForAMissingNode) {
  DeviceOptions options;
  options.origin = {1, 2, 3};
  auto device = openDevice("evdev:/dev/input/event-vrflow-later", options);
  ASSERT_TRUE(device) << device.error().message;
  auto sample = (*device)->sample(0.0);
  ASSERT_TRUE(sample);
  EXPECT_FALSE(sample->present);
  EXPECT_EQ(sample->position, (msg::Vec3{1, 2, 3}));
}

TEST(Picking, RayHitsTheNearestBoundsAndAPointPicksWhatContainsIt) {
  const std::vector<PickTarget> targets{{7, {{2, -1, -1}, {3, 1, 1}}},
                                        {5, {{5, -1, -1}, {6, 1, 1}}}};
  auto hit = pick(targets, {0, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->id, 7u);
  EXPECT_DOUBLE_EQ(hit->distance, 2.0);
  EXPECT_EQ(hit->point, (msg::Vec3{2, 0, 0}));
  EXPECT_FALSE(pick(targets, {0, 0, 0}, {-1, 0, 0}));  // behind the origin
  EXPECT_FALSE(pick(targets, {0, 2, 0}, {1, 0, 0}));   // above both
  auto inside = pick(targets, {5.5, 0, 0}, {0, 0, 0});
  ASSERT_TRUE(inside);
  EXPECT_EQ(inside->id, 5u);
  EXPECT_EQ(inside->distance, 0.0);
}

TEST(Picking, GrabForceIsASpringDamperClampedToItsMaximum) {
  GrabSpring spring{100.0, 10.0, 50.0};
  const auto f = grabForce(spring, {0, 0, 0}, {0, 1, 0}, {0, 0.2, 0});
  EXPECT_DOUBLE_EQ(f[1], 100.0 * 0.2 - 10.0 * 1.0);
  const auto clamped = grabForce(spring, {0, 0, 0}, {0, 0, 0}, {0, 10, 0});
  EXPECT_DOUBLE_EQ(clamped[1], 50.0);
}

}  // namespace
}  // namespace vrflow::input

namespace vrflow::input {
namespace {

// The plugin backend loads a real shared library (the test plugin), drives it through the
// Device interface, and reports the plugin's own error for bad arguments.
TEST(Devices, PluginLibraryIsLoadedAndDrivenThroughTheDeviceInterface) {
  auto device = openDevice(std::string("plugin:") + VRFLOW_TEST_DEVICE_PLUGIN + ":1 2 3");
  ASSERT_TRUE(device) << device.error().message;
  EXPECT_TRUE((*device)->haptic());
  (*device)->render({2, 0, 0}, 0.5);
  auto sample = (*device)->sample(0.5);
  ASSERT_TRUE(sample);
  EXPECT_EQ(sample->position, (msg::Vec3{1.5, 2, 3}));
  auto bad = openDevice(std::string("plugin:") + VRFLOW_TEST_DEVICE_PLUGIN + ":one two");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, std::string("plugin:") + VRFLOW_TEST_DEVICE_PLUGIN +
                                     ": arguments 'one two' are not X Y Z");
}

}  // namespace
}  // namespace vrflow::input
