// The hull's wire form: slabs carved apart and gathered give the grid back; bad slabs are named.
#include "vrflow/camera/hull_message.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::camera {
namespace {

std::vector<std::byte> slabMessage(const VoxelGrid& grid, int zBegin, int zEnd) {
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  addHullSlab(builder, 42, grid, zBegin, zEnd);
  const std::size_t size = builder.finish();
  return {sink.data(), sink.data() + size};
}

TEST(HullMessage, SlabsSentApartAreGatheredIntoTheSameGrid) {
  const GridSpec spec = GridSpec::cube({-0.5, 0.0, -0.5}, 1.0, 12);
  VoxelGrid grid(spec);
  for (std::size_t i = 0; i < grid.occupied.size(); ++i) grid.occupied[i] = (i * 7 % 5) == 0;
  VoxelGrid gathered(spec);
  for (const auto& [begin, end] : {std::pair{0, 5}, std::pair{5, 5}, std::pair{5, 12}}) {
    const auto bytes = slabMessage(grid, begin, end);
    const auto view = msg::MessageView::parse(bytes);
    ASSERT_TRUE(view.ok()) << view.error().message;
    const auto resource = view->begin()->asResource();
    ASSERT_TRUE(resource);
    const auto slab = readHullSlab(*resource);
    ASSERT_TRUE(slab.ok()) << slab.error().message;
    EXPECT_EQ(slab->zBegin, begin);
    EXPECT_EQ(slab->zEnd, end);
    ASSERT_TRUE(gatherHullSlab(*slab, gathered).ok());
  }
  EXPECT_EQ(gathered.occupied, grid.occupied);
  VoxelGrid other(GridSpec::cube({-0.5, 0.0, -0.5}, 1.0, 10));
  const auto bytes = slabMessage(grid, 0, 12);
  const auto view = msg::MessageView::parse(bytes);
  ASSERT_TRUE(view.ok());
  EXPECT_FALSE(gatherHullSlab(*readHullSlab(*view->begin()->asResource()), other).ok());
}

TEST(HullMessage, MalformedSlabsAreRefusedWithTheirCause) {
  VoxelGrid grid(GridSpec::cube({0, 0, 0}, 1.0, 4));
  auto bytes = slabMessage(grid, 0, 4);
  auto body = [&](std::vector<std::byte>& message) {
    const auto view = msg::MessageView::parse(message);
    EXPECT_TRUE(view.ok());
    return readHullSlab(*view->begin()->asResource());
  };
  ASSERT_TRUE(body(bytes).ok());
  // Find the body (its magic) and spoil the version, then the slab range.
  std::size_t at = 0;
  while (at + 4 <= bytes.size() && !(bytes[at] == std::byte{'V'} && bytes[at + 1] == std::byte{'X'}))
    ++at;
  auto versioned = bytes;
  versioned[at + 4] = std::byte{2};
  const auto version = body(versioned);
  ASSERT_FALSE(version.ok());
  EXPECT_NE(version.error().message.find("version 2"), std::string::npos)
      << version.error().message;
  auto ranged = bytes;
  ranged[at + 24] = std::byte{9};  // zEnd beyond nz
  EXPECT_FALSE(body(ranged).ok());
  auto magic = bytes;
  magic[at] = std::byte{'Q'};
  EXPECT_FALSE(body(magic).ok());
}

}  // namespace
}  // namespace vrflow::camera
