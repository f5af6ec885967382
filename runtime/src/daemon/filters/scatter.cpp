// scatter: one message split into N parts by chunk position, object id, object type or
// bounding volume.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "filters.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr uint32_t kEveryOutput = UINT32_MAX;
constexpr uint32_t kNoOutput = UINT32_MAX - 1;

enum class SplitBy { Chunk, Id, Type, Bounds, Size };

// by=size: the header in front of each part's bytes (docs/filters.md).
constexpr std::size_t kPartHeaderSize = 16;

// The finalizer of splitmix64: spreads consecutive ids (a host's counter) evenly.
uint64_t mixId(uint64_t id) {
  id += 0x9e3779b97f4a7c15ULL;
  id = (id ^ (id >> 30)) * 0xbf58476d1ce4e5b9ULL;
  id = (id ^ (id >> 27)) * 0x94d049bb133111ebULL;
  return id ^ (id >> 31);
}

class ScatterFilter final : public Filter {
 public:
  ScatterFilter(SplitBy by, std::vector<uint32_t> typeIds, bool othersToAll, int axis = 0,
                std::vector<double> cuts = {}, uint64_t elementSize = 1)
      : by_(by),
        elementSize_(elementSize == 0 ? 1 : elementSize),
        typeIds_(std::move(typeIds)),
        othersToAll_(othersToAll),
        axis_(axis),
        cuts_(std::move(cuts)) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    const std::size_t n = context.outputCount();
    while (!in.empty()) {
      for (std::size_t o = 0; o < n; ++o) {
        if (!context.canEmit(o)) return;  // every part leaves together
      }
      MessageRef message = std::move(in.front());
      in.pop_front();
      if (const auto view = viewOrWarn(context, message)) split(context, message, *view);
    }
  }

 private:
  // The slab [cuts[k-1], cuts[k]) holding coordinate v (slab 0 below the first cut).
  uint32_t slabOf(double v) const {
    uint32_t k = 0;
    while (k < cuts_.size() && v >= cuts_[k]) ++k;
    return k;
  }

  // The extent of an object along the axis, if this chunk carries its bounds (or, for a point,
  // its position as a degenerate box).
  std::optional<std::pair<double, double>> extentOf(const msg::ObjectView& object) const {
    const uint32_t type = object.typeId();
    std::optional<uint32_t> boundsParam;
    if (type == msg::rigidType().id()) boundsParam = msg::RigidParam::kBounds;
    if (type == msg::massSpringType().id()) boundsParam = msg::MassSpringParam::kBounds;
    if (type == msg::fluidType().id()) boundsParam = msg::FluidParam::kBounds;
    if (type == msg::userType().id()) boundsParam = msg::UserParam::kBounds;
    if (boundsParam) {
      const auto box = object.aabb(*boundsParam);
      if (!box) return std::nullopt;
      const double lo = axisOf(box->min), hi = axisOf(box->max);
      if (!std::isfinite(lo) || !std::isfinite(hi)) return std::nullopt;
      return std::pair{std::min(lo, hi), std::max(lo, hi)};
    }
    if (type == msg::pointType().id()) {
      const auto position = object.vec3(msg::PointParam::kPosition);
      if (!position) return std::nullopt;
      const double v = axisOf(*position);
      if (!std::isfinite(v)) return std::nullopt;
      return std::pair{v, v};
    }
    return std::nullopt;
  }

  double axisOf(const msg::Vec3& v) const { return v[static_cast<std::size_t>(axis_)]; }

  // by=bounds: the outputs [first, last] an object chunk goes to; updates the latest bounds.
  std::pair<uint32_t, uint32_t> boundsTargets(const msg::ChunkView& chunk, uint32_t n) {
    const std::pair<uint32_t, uint32_t> others = othersToAll_
                                                     ? std::pair<uint32_t, uint32_t>{0, n - 1}
                                                     : std::pair<uint32_t, uint32_t>{1, 0};
    if (chunk.kind() != msg::ChunkKind::Object) return others;
    const auto object = chunk.asObject();
    if (!object) return others;
    const uint64_t id = chunk.id();
    if (object->op() == msg::ObjectOp::Delete) {
      const auto it = latest_.find(id);
      if (it == latest_.end()) return others;
      const auto range = it->second;
      latest_.erase(it);
      return range;
    }
    if (const auto extent = extentOf(*object)) {
      const std::pair<uint32_t, uint32_t> range{std::min(slabOf(extent->first), n - 1),
                                                std::min(slabOf(extent->second), n - 1)};
      latest_[id] = range;
      return range;
    }
    const auto it = latest_.find(id);
    return it == latest_.end() ? others : it->second;
  }

  // Which output chunk `index` (of `count`) goes to.
  uint32_t outputOf(const msg::ChunkView& chunk, uint32_t count, uint32_t n) const {
    switch (by_) {
      case SplitBy::Chunk: {
        // N contiguous runs; the first count % N runs hold one chunk more.
        const uint32_t base = count / n, extra = count % n, index = chunk.index();
        const uint32_t longRuns = extra * (base + 1);
        return index < longRuns ? index / (base + 1) : extra + (index - longRuns) / base;
      }
      case SplitBy::Id:
        return static_cast<uint32_t>(mixId(chunk.id()) % n);
      case SplitBy::Type:
        if (chunk.kind() == msg::ChunkKind::Object) {
          for (uint32_t k = 0; k < typeIds_.size() && k < n; ++k) {
            if (typeIds_[k] == chunk.typeId()) return k;
          }
        }
        return othersToAll_ ? kEveryOutput : kNoOutput;
      case SplitBy::Bounds:
      case SplitBy::Size:
        break;
    }
    return kNoOutput;
  }

  void split(FilterContext& context, const MessageRef& message, const msg::MessageView& view) {
    const auto n = static_cast<uint32_t>(context.outputCount());
    if (by_ == SplitBy::Size) {
      splitBySize(context, message, view);
      return;
    }
    if (n == 1 && by_ != SplitBy::Type && by_ != SplitBy::Bounds) {
      context.emit(0, message);
      return;
    }
    targets_.clear();
    std::vector<std::size_t> bytes(n, 0);
    std::vector<uint32_t> chunks(n, 0);
    const std::size_t fixed = message.size() - view.chunkBytes().size();
    for (const msg::ChunkView chunk : view) {
      std::pair<uint32_t, uint32_t> target;
      if (by_ == SplitBy::Bounds) {
        target = boundsTargets(chunk, n);
      } else {
        const uint32_t one = outputOf(chunk, view.chunkCount(), n);
        target = one == kEveryOutput ? std::pair<uint32_t, uint32_t>{0, n - 1}
                 : one == kNoOutput  ? std::pair<uint32_t, uint32_t>{1, 0}
                                     : std::pair<uint32_t, uint32_t>{one, one};
      }
      targets_.push_back(target);
      for (uint32_t o = target.first; o <= target.second && o < n; ++o) {
        bytes[o] += chunk.bytes().size();
        ++chunks[o];
      }
    }
    const msg::Stamps stamps = view.stamps().toStamps();
    for (uint32_t o = 0; o < n; ++o) {
      if (chunks[o] == view.chunkCount()) {
        context.emit(o, message);  // the whole message: by reference
        continue;
      }
      auto part = context.compose(fixed + bytes[o], [&](msg::MessageBuilder& builder) {
        builder.setStamps(stamps);
        builder.setStampsOnly(view.stampsOnly());
        for (const msg::ChunkView chunk : view) {
          const auto target = targets_[chunk.index()];
          if (target.first <= o && o <= target.second) builder.appendChunk(chunk);
        }
      });
      if (!part) {
        context.warn(part.error().message);
        continue;
      }
      context.emit(o, std::move(*part));
    }
  }

  // by=size: every raw resource cut into N parts of whole elements, each a raw resource with
  // the same id whose bytes are a header (u64 offset, u64 total size, little-endian) and the
  // part; other chunks follow `others`.
  void splitBySize(FilterContext& context, const MessageRef& message,
                   const msg::MessageView& view) {
    const auto n = static_cast<uint32_t>(context.outputCount());
    const msg::Stamps stamps = view.stamps().toStamps();
    for (uint32_t o = 0; o < n; ++o) {
      auto part = context.compose(
          message.size() + n * (msg::kChunkHeaderSize + kPartHeaderSize + 8),
          [&](msg::MessageBuilder& builder) {
            builder.setStamps(stamps);
            builder.setStampsOnly(view.stampsOnly());
            for (const msg::ChunkView chunk : view) {
              const auto resource = chunk.asResource();
              if (!resource || resource->kind() != msg::ResourceKind::Raw) {
                if (othersToAll_) builder.appendChunk(chunk);
                continue;
              }
              const auto bytes = resource->raw();
              const uint64_t total = bytes.size(), elements = total / elementSize_;
              const uint64_t first = elements * o / n * elementSize_;
              const uint64_t last = o + 1 == n ? total : elements * (o + 1) / n * elementSize_;
              std::vector<std::byte> body(kPartHeaderSize + (last - first));
              for (int b = 0; b < 8; ++b) {
                body[b] = static_cast<std::byte>((first >> (8 * b)) & 0xff);
                body[8 + b] = static_cast<std::byte>((total >> (8 * b)) & 0xff);
              }
              std::copy(bytes.begin() + static_cast<std::ptrdiff_t>(first),
                        bytes.begin() + static_cast<std::ptrdiff_t>(last),
                        body.begin() + kPartHeaderSize);
              builder.addRawResource(resource->id(), resource->dynamic(), body);
            }
          });
      if (!part) {
        context.warn(part.error().message);
        continue;
      }
      context.emit(o, std::move(*part));
    }
  }

  SplitBy by_;
  uint64_t elementSize_;
  std::vector<uint32_t> typeIds_;
  bool othersToAll_;
  int axis_;
  std::vector<double> cuts_;
  // by=bounds: the outputs each object's latest known bounds sent it to.
  std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> latest_;
  std::vector<std::pair<uint32_t, uint32_t>> targets_;
};

app::FilterType scatterType() {
  FilterType type;
  type.name = "scatter";
  type.doc =
      "Splits each message of in into N parts, one per output out0..out{N-1}, each with the "
      "message's stamps (a part may be empty). `chunk`: N contiguous runs of chunks of "
      "near-equal count; `id`: chunk to out{splitmix64(id) mod N}; `type`: objects of the "
      "k-th name of `types` to out{k}, other chunks by `others`; `bounds`: objects to every "
      "slab of `axis` cut at `cuts` that their bounds (a point: its position) meet, an object "
      "without bounds in a message where its latest bounds sent it, other chunks by `others`; "
      "`size`: every raw resource cut into N parts of whole `element-size` elements, each a "
      "raw resource of the same id prefixed by its u64 offset and u64 total size.";
  const app::ParamSpec outputCount = intParam("outputs", "2", 1, kMaxPorts, "number of outputs N");
  type.params.push_back(outputCount);
  const app::ParamSpec splitBy =
      enumParam("by", {"chunk", "id", "type", "bounds", "size"}, "how chunks are split");
  type.params.push_back(splitBy);
  type.params.push_back(intParam("element-size", "1", 1, 1 << 30,
                                 "by=size: bytes per element; parts hold whole elements"));
  type.params.push_back(
      stringParam("types", "", "by=type: N object type names, comma-separated, one per output"));
  type.params.push_back(
      enumParam("axis", {"x", "y", "z"}, "by=bounds: the axis the cuts are taken along"));
  type.params.push_back(
      stringParam("cuts", "",
                  "by=bounds: N-1 strictly increasing numbers, comma-separated; out{k} is the slab "
                  "[cut{k-1}, cut{k}), out0 unbounded below, out{N-1} unbounded above"));
  type.params.push_back(enumParam("others", {"all", "drop"},
                                  "chunks not split by type, bounds or size (by=type, bounds, "
                                  "size) go to every output (all) or nowhere (drop)"));
  type.ports = [outputCount](const std::vector<Param>& params) {
    std::vector<PortSpec> ports{filterPort("in", true, "messages to split")};
    for (auto& port : numberedPorts("out", clampedInt(outputCount, params), false,
                                    "one part of every message")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  type.check = [outputCount,
                splitBy](const std::vector<Param>& params) -> std::optional<std::string> {
    const std::string by = declaredText(splitBy, params);
    const bool byType = by == "type";
    const auto names = splitList(paramString(params, "types", ""));
    const auto cuts = splitList(paramString(params, "cuts", ""));
    if (by != "bounds" && !cuts.empty()) return "parameter 'cuts' applies only with by=\"bounds\"";
    if (by == "bounds") {
      const long long outputs = clampedInt(outputCount, params);
      if (static_cast<long long>(cuts.size()) + 1 != outputs) {
        return "by=\"bounds\" needs N-1 numbers in 'cuts' for N outputs: " +
               std::to_string(outputs) + " outputs, " + std::to_string(cuts.size()) + " cuts";
      }
      double previous = 0;
      for (std::size_t k = 0; k < cuts.size(); ++k) {
        char* end = nullptr;
        const double v = std::strtod(cuts[k].c_str(), &end);
        if (end == cuts[k].c_str() || *end != '\0' || !std::isfinite(v)) {
          return "'cuts': '" + cuts[k] + "' is not a finite number";
        }
        if (k > 0 && v <= previous) return "'cuts' must be strictly increasing";
        previous = v;
      }
    }
    if (!byType) {
      if (!names.empty()) return "parameter 'types' applies only with by=\"type\"";
      return std::nullopt;
    }
    const long long outputs = clampedInt(outputCount, params);
    if (static_cast<long long>(names.size()) != outputs) {
      return "by=\"type\" needs one type name in 'types' per output: " + std::to_string(outputs) +
             " outputs, " + std::to_string(names.size()) + " names";
    }
    return std::nullopt;
  };
  return type;
}

}  // namespace

void registerScatter(FilterRegistry& registry) {
  addBuiltin(
      registry,
      {scatterType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
         const std::string by = context.params().getString("by");
         const SplitBy split = by == "id"       ? SplitBy::Id
                               : by == "type"   ? SplitBy::Type
                               : by == "bounds" ? SplitBy::Bounds
                               : by == "size"   ? SplitBy::Size
                                                : SplitBy::Chunk;
         std::vector<uint32_t> typeIds;
         for (const auto& name : app::splitList(context.params().getString("types"))) {
           typeIds.push_back(msg::fnv1a32(name));
         }
         if (split == SplitBy::Type && typeIds.size() != context.outputCount()) {
           return makeError("filter '" + context.name() +
                            "': by=type needs one type name per output");
         }
         const std::string axisName = context.params().getString("axis");
         const int axis = axisName == "y" ? 1 : axisName == "z" ? 2 : 0;
         std::vector<double> cuts;
         for (const auto& text : app::splitList(context.params().getString("cuts"))) {
           char* end = nullptr;
           const double v = std::strtod(text.c_str(), &end);
           if (end == text.c_str() || *end != '\0' || !std::isfinite(v) ||
               (!cuts.empty() && v <= cuts.back())) {
             return makeError("filter '" + context.name() + "': bad 'cuts' value '" + text + "'");
           }
           cuts.push_back(v);
         }
         if (split == SplitBy::Bounds && cuts.size() + 1 != context.outputCount()) {
           return makeError("filter '" + context.name() +
                            "': by=bounds needs N-1 cuts for N outputs");
         }
         return std::unique_ptr<Filter>(std::make_unique<ScatterFilter>(
             split, std::move(typeIds), context.params().getString("others") != "drop", axis,
             std::move(cuts),
             static_cast<uint64_t>(
                 static_cast<uint64_t>(context.params().getInt("element-size")))));
       }});
}

}  // namespace vrflow::daemon::filters
