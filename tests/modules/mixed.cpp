// testing/mixed: per iteration, `points` point objects, `rigids` rigid objects, one raw
// resource whose first 8 bytes count iterations, and one force on the first point (or on
// object 0), in that order; ends after `count` iterations (0: never). For the filters that
// split or select chunks. Point k sits at (k, iteration, 0), rigid k at (k, iteration, 1).
// With `extent` > 0, rigid k carries bounds (k, iteration, 1) +- extent in the first
// iteration only (later updates have none). With `delete-at` > 0, the rigids are deleted at
// that iteration and sent no more. With `payload` > 8, the raw resource holds `payload`
// bytes: the counter, then byte i = (7 i + iteration) mod 256.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  std::vector<uint64_t> points(static_cast<std::size_t>(module.params().getInt("points")));
  std::vector<uint64_t> rigids(static_cast<std::size_t>(module.params().getInt("rigids")));
  for (auto& id : points) id = module.newId();
  for (auto& id : rigids) id = module.newId();
  const double extent = module.params().getFloat("extent");
  const auto deleteAt = static_cast<uint64_t>(module.params().getInt("delete-at"));
  const auto payload =
      static_cast<std::size_t>(std::max<int64_t>(8, module.params().getInt("payload")));
  const uint64_t resource = module.newId();
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; (count == 0 || done < count) && module.wait(); ++done) {
    const uint64_t it = module.iteration();
    auto message = module.newMessage(1024 + payload);
    auto& builder = message.builder();
    for (std::size_t k = 0; k < points.size(); ++k) {
      builder.addObject(points[k], msg::pointType())
          .set(msg::PointParam::kPosition,
               msg::Vec3{static_cast<double>(k), static_cast<double>(it), 0.0});
    }
    for (std::size_t k = 0; k < rigids.size() && (deleteAt == 0 || it <= deleteAt); ++k) {
      if (deleteAt != 0 && it == deleteAt) {
        builder.addDelete(rigids[k], msg::rigidType());
        continue;
      }
      const msg::Vec3 position{static_cast<double>(k), static_cast<double>(it), 1.0};
      auto object = builder.addObject(rigids[k], msg::rigidType());
      object.set(msg::RigidParam::kPosition, position);
      if (extent > 0 && it == 0) {
        object.set(msg::RigidParam::kBounds,
                   msg::Aabb{{position[0] - extent, position[1] - extent, position[2] - extent},
                             {position[0] + extent, position[1] + extent, position[2] + extent}});
      }
    }
    std::vector<std::byte> counter(payload);
    std::memcpy(counter.data(), &it, sizeof it);
    for (std::size_t i = 8; i < payload; ++i)
      counter[i] = static_cast<std::byte>((7 * i + it) & 0xff);
    builder.addRawResource(resource, true, counter);
    builder.addForce(points.empty() ? 0 : points.front(),
                     msg::ForceEvent{{0, 1, 0}, {0, 0, 0}, {0, 0, 0}, 0.01});
    if (!module.put(out, std::move(message))) break;
  }
  return 0;
}
