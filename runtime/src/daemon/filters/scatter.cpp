// scatter: one message split into N parts by chunk position, object id or object type.
#include <string>
#include <vector>

#include "filters.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr uint32_t kEveryOutput = UINT32_MAX;
constexpr uint32_t kNoOutput = UINT32_MAX - 1;

enum class SplitBy { Chunk, Id, Type };

// The finalizer of splitmix64: spreads consecutive ids (a host's counter) evenly.
uint64_t mixId(uint64_t id) {
  id += 0x9e3779b97f4a7c15ULL;
  id = (id ^ (id >> 30)) * 0xbf58476d1ce4e5b9ULL;
  id = (id ^ (id >> 27)) * 0x94d049bb133111ebULL;
  return id ^ (id >> 31);
}

class ScatterFilter final : public Filter {
 public:
  ScatterFilter(SplitBy by, std::vector<uint32_t> typeIds, bool othersToAll)
      : by_(by), typeIds_(std::move(typeIds)), othersToAll_(othersToAll) {}

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
    }
    return kNoOutput;
  }

  void split(FilterContext& context, const MessageRef& message, const msg::MessageView& view) {
    const auto n = static_cast<uint32_t>(context.outputCount());
    if (n == 1 && by_ != SplitBy::Type) {
      context.emit(0, message);
      return;
    }
    targets_.clear();
    std::vector<std::size_t> bytes(n, 0);
    std::vector<uint32_t> chunks(n, 0);
    const std::size_t fixed = message.size() - view.chunkBytes().size();
    for (const msg::ChunkView chunk : view) {
      const uint32_t target = outputOf(chunk, view.chunkCount(), n);
      targets_.push_back(target);
      for (uint32_t o = 0; o < n; ++o) {
        if (target != o && target != kEveryOutput) continue;
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
          const uint32_t target = targets_[chunk.index()];
          if (target == o || target == kEveryOutput) builder.appendChunk(chunk);
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
  std::vector<uint32_t> typeIds_;
  bool othersToAll_;
  std::vector<uint32_t> targets_;
};

}  // namespace

void registerScatter(FilterRegistry& registry) {
  registry.add("scatter", [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
    const std::string by = context.param("by", "chunk");
    const SplitBy split = by == "id" ? SplitBy::Id : by == "type" ? SplitBy::Type : SplitBy::Chunk;
    std::vector<uint32_t> typeIds;
    for (const auto& name : app::splitList(context.param("types", ""))) {
      typeIds.push_back(msg::fnv1a32(name));
    }
    if (split == SplitBy::Type && typeIds.size() != context.outputCount()) {
      return makeError("filter '" + context.name() + "': by=type needs one type name per output");
    }
    return std::unique_ptr<Filter>(std::make_unique<ScatterFilter>(
        split, std::move(typeIds), context.param("others", "all") != "drop"));
  });
}

}  // namespace vrflow::daemon::filters
