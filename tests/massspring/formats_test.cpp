// Net files, the spring records, the node-force events, object chunks, and bad input.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>

#include "process_helpers.hpp"
#include "vrflow/massspring/events.hpp"
#include "vrflow/massspring/objects.hpp"
#include "vrflow/massspring/solver.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/shape.hpp"

namespace vrflow::massspring {
namespace {

void expectError(const Result<Net>& result, const std::string& part) {
  ASSERT_FALSE(result) << "expected an error containing '" << part << "'";
  EXPECT_NE(result.error().message.find(part), std::string::npos) << result.error().message;
}

TEST(MassSpringFormats, GridHasTheStatedSpringsSurfaceAndPins) {
  GridParams p;
  p.n = 4;
  p.m = 3;
  p.mass = 1.2;
  auto net = generateGrid(p);
  ASSERT_TRUE(net) << net.error().message;
  EXPECT_EQ(net->nodeCount(), 12u);
  // structural 3*3 + 4*2 = 17, shear 2 * 3*2 = 12, bend 2*3 + 4*1 = 10
  EXPECT_EQ(net->springs.size(), 17u + 12u + 10u);
  EXPECT_EQ(net->surface.size(), 3u * 2u * 6u);
  EXPECT_EQ(net->pinned, (std::vector<std::uint8_t>{1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1}));
  EXPECT_DOUBLE_EQ(net->masses[5], 0.1);
  for (const auto& s : net->springs) {
    const auto a = net->position(s.a), b = net->position(s.b);
    EXPECT_NEAR(std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]), s.restLength, 1e-12);
  }
  EXPECT_NEAR(maxStretchRatio(*net), 1.0, 1e-12);
  const auto box = bounds(*net);
  EXPECT_NEAR(box.min[0], -0.15, 1e-12);
  EXPECT_NEAR(box.max[2], 0.1, 1e-12);
  // Rotated a quarter turn about x, placed at the origin given: the net stands in the x-y plane.
  p.origin = {1, 2, 3};
  p.orientation = {std::sin(M_PI / 4), 0, 0, std::cos(M_PI / 4)};
  auto standing = generateGrid(p);
  ASSERT_TRUE(standing);
  const auto b2 = bounds(*standing);
  EXPECT_NEAR(b2.max[2] - b2.min[2], 0, 1e-12);
  EXPECT_NEAR(b2.max[1] - b2.min[1], 0.2, 1e-12);
  EXPECT_NEAR(0.5 * (b2.min[0] + b2.max[0]), 1, 1e-12);
}

TEST(MassSpringFormats, NetFileRoundTripIsExact) {
  GridParams p;
  p.n = 5;
  p.m = 4;
  p.orientation = {0.1, 0.2, 0.3, std::sqrt(1 - 0.14)};
  auto net = generateGrid(p);
  ASSERT_TRUE(net);
  StepOptions options;
  options.gravity = {0, -9.81, 0};
  for (int s = 0; s < 10; ++s) step(*net, {}, options);  // velocities and odd doubles
  testing::TempDir dir;
  ASSERT_TRUE(saveNet(*net, dir.file("net.txt")));
  auto loaded = loadNet(dir.file("net.txt"));
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(*loaded == *net);
}

TEST(MassSpringFormats, HandWrittenFileWithDefaultRestLengths) {
  const std::string text =
      "# a triangle of three nodes\n"
      "massspring 1\n"
      "nodes 3\n"
      "0 0 0 1 1\n"
      "1 0 0 0.5 0   # free\n"
      "0 0 2 0.5 0 0 1 0\n"
      "springs 2\n"
      "0 1 -1 100 0.1 1.2\n"
      "0 2 1.5 100 0 0\n"
      "triangles 1\n"
      "0 2 1\n";
  auto net = parseNet(text);
  ASSERT_TRUE(net) << net.error().message;
  EXPECT_EQ(net->springs[0].restLength, 1.0);
  EXPECT_EQ(net->springs[1].restLength, 1.5);
  EXPECT_EQ(net->velocities[7], 1.0);
  EXPECT_EQ(net->surface, (std::vector<std::uint32_t>{0, 2, 1}));
}

TEST(MassSpringFormats, BadFilesGiveClearErrors) {
  expectError(loadNet("/nonexistent/net.txt"),
              "/nonexistent/net.txt: net file: cannot read file (No such file or directory)");
  expectError(parseNet("springy 1\n"), "<text>:1: expected the header 'massspring 1'");
  expectError(parseNet("massspring 1\nnodes 2\n0 0 0 1 0\n"),
              "<text>:3: the file ends after 1 of 2 nodes");
  expectError(parseNet("massspring 1\nnodes 1\n0 0 zero 1 0\nsprings 0\n"),
              "<text>:3: 'zero' is not a number");
  expectError(parseNet("massspring 1\nnodes 1\n0 0 0 1 2\nsprings 0\n"), "pinned must be 0 or 1");
  expectError(parseNet("massspring 1\nnodes 1\n0 0 0 -1 0\nsprings 0\n"), "node 0 has mass -1");
  expectError(parseNet("massspring 1\nnodes 2\n0 0 0 1 0\n1 0 0 1 0\nsprings 1\n0 2 1 1 0 0\n"),
              "<text>:6: spring node indices must be integers below 2");
  expectError(parseNet("massspring 1\nnodes 2\n0 0 0 1 0\n1 0 0 1 0\nsprings 1\n0 0 1 1 0 0\n"),
              "joins node 0 to itself");
  expectError(parseNet("massspring 1\nnodes 2\n0 0 0 1 0\n1 0 0 1 0\nsprings 1\n0 1 1 1 0 0.5\n"),
              "maxStretch must be 0");
  expectError(parseNet("massspring 1\nnodes 2\n0 0 0 1 0\n1 0 0 1 0\nsprings 1\n0 1 1 -5 0 0\n"),
              "stiffness must be");
  expectError(parseNet("massspring 1\nnodes 1\nnan 0 0 1 0\nsprings 0\n"), "non-finite");
  expectError(parseNet("massspring 1\nnodes 1\n0 0 0 1 0\nsprings 0\nextra 3\n"),
              "<text>:5: expected 'triangles T'");
}

// A net is read only from a regular file of at most 256 MiB: a device, a FIFO (without
// blocking) or a folder is refused with one error naming the file and what it is.
TEST(MassSpringFormats, NetFromADeviceFifoFolderOrHugeFileIsRefusedWithoutReadingIt) {
  expectError(loadNet("/dev/zero"),
              "/dev/zero: net file: cannot read file (it is a character device, not a regular "
              "file)");
  testing::TempDir dir;
  const std::string fifo = dir.file("net.txt");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // Hang guard: a reader that blocks in open() is released by a writer after 20 s.
  auto fromFifo = std::async(std::launch::async, [&] { return loadNet(fifo); });
  if (fromFifo.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
    const int writer = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (writer >= 0) close(writer);
    ADD_FAILURE() << "loadNet blocked on a FIFO for 20 s";
  }
  expectError(fromFifo.get(),
              fifo + ": net file: cannot read file (it is a FIFO, not a regular file)");
  expectError(loadNet(dir.path()), "it is a directory, not a regular file");
  const std::string huge = dir.file("huge.txt");
  std::ofstream(huge) << "massspring 1\n";
  std::filesystem::resize_file(huge, std::uintmax_t{1} << 30);  // 1 GiB, sparse
  expectError(loadNet(huge), huge +
                                 ": net file: cannot read file (it is 1073741824 bytes, above the "
                                 "limit of 268435456 bytes (256 MiB))");
}

TEST(MassSpringFormats, BadGeneratorParametersGiveClearErrors) {
  GridParams p;
  p.n = 1;
  expectError(generateGrid(p), "n and m must be in [2, 4096]");
  p = {};
  p.spacing = 0;
  expectError(generateGrid(p), "spacing must be > 0");
  p = {};
  p.mass = -1;
  expectError(generateGrid(p), "mass must be > 0");
  p = {};
  p.maxStretch = 0.9;
  expectError(generateGrid(p), "max stretch must be 0 or >= 1");
  p = {};
  p.orientation = {0, 0, 0, 2};
  expectError(generateGrid(p), "unit quaternion");
  StepOptions o;
  o.substeps = 0;
  EXPECT_FALSE(validateStepOptions(o));
  o = {};
  o.dt = -1;
  EXPECT_FALSE(validateStepOptions(o));
  ContactParams c;
  c.thickness = 0;
  EXPECT_FALSE(validateContactParams(c));
}

TEST(MassSpringFormats, SpringRecordsAreFortyBytes) {
  const std::vector<Spring> springs{{3, 7, 0.5, 100, 0.25, 1.1}, {0, 1, 1, 2, 3, 0}};
  const auto bytes = encodeSprings(springs);
  ASSERT_EQ(bytes.size(), 80u);
  std::uint32_t b = 0;
  double stiffness = 0;
  std::memcpy(&b, bytes.data() + 4, 4);
  std::memcpy(&stiffness, bytes.data() + 16, 8);
  EXPECT_EQ(b, 7u);
  EXPECT_EQ(stiffness, 100.0);
  auto decoded = decodeSprings(bytes);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(*decoded, springs);
  EXPECT_FALSE(decodeSprings(std::span<const std::byte>(bytes).first(79)));
}

TEST(MassSpringFormats, NodeForceEvents) {
  const std::vector<NodeForce> forces{{2, {1, 2, 3}}, {0, {-1, 0, 0.5}}};
  const auto payload = encodeNodeForces(forces);
  ASSERT_EQ(payload.size(), 8u + 64u);
  std::uint32_t count = 0;
  double fy = 0;
  std::memcpy(&count, payload.data(), 4);
  std::memcpy(&fy, payload.data() + 8 + 16, 8);
  EXPECT_EQ(count, 2u);
  EXPECT_EQ(fy, 2.0);
  auto decoded = decodeNodeForces(payload);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(*decoded, forces);
  EXPECT_FALSE(decodeNodeForces(std::span<const std::byte>(payload).first(40)));
  auto bad = payload;
  bad[0] = std::byte{3};
  EXPECT_FALSE(decodeNodeForces(bad));
  EXPECT_EQ(sparseForces(std::vector<double>{0, 0, 0, 1, 0, 0}),
            (std::vector<NodeForce>{{1, {1, 0, 0}}}));
}

// A 3 x 3 grid with the generator's defaults.
Result<Net> smallGrid() {
  GridParams p;
  p.n = 3;
  p.m = 3;
  return generateGrid(p);
}

TEST(MassSpringFormats, NetsTravelAsObjectChunksIntoASceneCopy) {
  auto net = smallGrid();
  ASSERT_TRUE(net);
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  writeNet(builder, 42, *net, true);
  builder.finish();
  auto view = msg::MessageView::parse(builder.bytes());
  ASSERT_TRUE(view) << view.error().message;
  SceneCopy scene;
  ASSERT_TRUE(scene.apply(*view));
  ASSERT_EQ(scene.nets().count(42), 1u);
  EXPECT_TRUE(scene.nets().at(42) == *net);
  // An update carries positions and velocities only.
  Net moved = *net;
  moved.positions[4] = 0.5;
  msg::VectorSink updateSink;
  msg::MessageBuilder update(updateSink);
  writeNet(update, 42, moved, false);
  update.finish();
  auto updateView = msg::MessageView::parse(update.bytes());
  ASSERT_TRUE(updateView);
  ASSERT_TRUE(scene.apply(*updateView));
  EXPECT_TRUE(scene.nets().at(42) == moved);
}

// Motion updates are written into the copy in place; one whose sizes disagree with the net is
// still an error naming the net, and the copy keeps what it had.
TEST(MassSpringFormats, AMotionUpdateOfTheWrongSizeLeavesTheSceneCopyAsItWas) {
  auto net = smallGrid();
  ASSERT_TRUE(net);
  SceneCopy scene;
  auto apply = [&](auto write) {
    msg::VectorSink sink;
    msg::MessageBuilder builder(sink);
    write(builder);
    builder.finish();
    auto view = msg::MessageView::parse(builder.bytes());
    EXPECT_TRUE(view) << view.error().message;
    return scene.apply(*view);
  };
  ASSERT_TRUE(apply([&](msg::MessageBuilder& b) { writeNet(b, 42, *net, true); }));
  Net moved = *net;
  for (std::size_t i = 0; i < moved.positions.size(); ++i) moved.positions[i] += 0.25;
  moved.velocities[7] = -3;
  ASSERT_TRUE(apply([&](msg::MessageBuilder& b) { writeNet(b, 42, moved, false); }));
  EXPECT_TRUE(scene.nets().at(42) == moved);  // masses, springs and surface kept
  const std::vector<double> tooFew(moved.positions.size() - 3, 1.0);
  const auto status = apply([&](msg::MessageBuilder& b) {
    b.addObject(42, msg::massSpringType(), msg::ObjectOp::Update)
        .set(msg::MassSpringParam::kPositions, std::span<const double>(tooFew));
  });
  ASSERT_FALSE(status);
  EXPECT_NE(status.error().message.find("net 42: net: 9 masses but 24 position"), std::string::npos)
      << status.error().message;
  EXPECT_TRUE(scene.nets().at(42) == moved);
  // An update of a net the copy never received is an error too (it has no masses).
  EXPECT_FALSE(apply([&](msg::MessageBuilder& b) { writeNet(b, 43, moved, false); }));
}

TEST(MassSpringFormats, RigidsAndTheirShapeResourcesIntoASceneCopy) {
  const auto shape = msg::Shape::box({0.2, 0.3, 0.4});
  const auto shapeBytes = msg::encodeShape(shape);
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  using P = msg::RigidParam;
  builder.addObject(7, msg::rigidType(), msg::ObjectOp::Add)
      .set(P::kPosition, msg::Vec3{1, 2, 3})
      .set(P::kOrientation, msg::Quat{0, 0, 0, 1})
      .set(P::kLinearVelocity, msg::Vec3{0, -1, 0})
      .set(P::kAngularVelocity, msg::Vec3{0, 0, 0.5})
      .set(P::kMass, 2.5)
      .set(P::kShape, std::uint64_t{99});
  builder.addRawResource(99, false, shapeBytes);
  builder.addRawResource(100, false,
                         std::vector<std::byte>(5, std::byte{1}));  // not a shape: ignored
  builder.finish();
  auto view = msg::MessageView::parse(builder.bytes());
  ASSERT_TRUE(view) << view.error().message;
  SceneCopy scene;
  ASSERT_TRUE(scene.apply(*view));
  const auto rigids = scene.rigids();
  ASSERT_EQ(rigids.count(7), 1u);
  const auto& body = rigids.at(7);
  EXPECT_EQ(body.position, (msg::Vec3{1, 2, 3}));
  EXPECT_EQ(body.linearVelocity, (msg::Vec3{0, -1, 0}));
  EXPECT_EQ(body.angularVelocity, (msg::Vec3{0, 0, 0.5}));
  EXPECT_EQ(body.mass, 2.5);
  EXPECT_TRUE(body.shape == shape);
  // A rigid whose shape has not arrived is left out until it does.
  msg::VectorSink sink2;
  msg::MessageBuilder second(sink2);
  second.addObject(8, msg::rigidType(), msg::ObjectOp::Add)
      .set(P::kMass, 1.0)
      .set(P::kShape, std::uint64_t{101});
  second.finish();
  auto view2 = msg::MessageView::parse(second.bytes());
  ASSERT_TRUE(view2);
  ASSERT_TRUE(scene.apply(*view2));
  EXPECT_EQ(scene.rigids().count(8), 0u);
  // A net chunk with springs bytes of the wrong size is an error naming the net.
  msg::VectorSink sink3;
  msg::MessageBuilder third(sink3);
  const std::vector<std::byte> badSprings(41);
  third.addObject(9, msg::massSpringType(), msg::ObjectOp::Add)
      .set(msg::MassSpringParam::kSprings, std::span<const std::byte>(badSprings));
  third.finish();
  auto view3 = msg::MessageView::parse(third.bytes());
  ASSERT_TRUE(view3);
  const auto status = scene.apply(*view3);
  ASSERT_FALSE(status);
  EXPECT_NE(status.error().message.find("net 9: springs: 41 bytes"), std::string::npos)
      << status.error().message;
}

}  // namespace
}  // namespace vrflow::massspring
