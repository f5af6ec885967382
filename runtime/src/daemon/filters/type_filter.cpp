// typefilter: drops the object chunks whose type is not listed (and, if asked, every
// resource and event chunk).
#include <algorithm>
#include <vector>

#include "filters.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::daemon::filters {
namespace {

class TypeFilter final : public Filter {
 public:
  TypeFilter(std::vector<uint32_t> typeIds, bool dropOthers)
      : typeIds_(std::move(typeIds)), dropOthers_(dropOthers) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty() && context.canEmit(0)) {
      MessageRef message = std::move(in.front());
      in.pop_front();
      const auto view = viewOrWarn(context, message);
      if (!view) continue;
      std::size_t keptBytes = 0;
      uint32_t kept = 0;
      for (const msg::ChunkView chunk : *view) {
        if (!keeps(chunk)) continue;
        keptBytes += chunk.bytes().size();
        ++kept;
      }
      if (kept == view->chunkCount()) {
        context.emit(0, std::move(message));  // nothing to drop: by reference
        continue;
      }
      const std::size_t fixed = message.size() - view->chunkBytes().size();
      auto filtered = context.compose(fixed + keptBytes, [&](msg::MessageBuilder& builder) {
        builder.setStamps(view->stamps().toStamps());
        for (const msg::ChunkView chunk : *view) {
          if (keeps(chunk)) builder.appendChunk(chunk);
        }
      });
      if (!filtered) {
        context.warn(filtered.error().message);
        continue;
      }
      context.emit(0, std::move(*filtered));
    }
  }

 private:
  bool keeps(const msg::ChunkView& chunk) const {
    if (chunk.kind() != msg::ChunkKind::Object) return !dropOthers_;
    return std::find(typeIds_.begin(), typeIds_.end(), chunk.typeId()) != typeIds_.end();
  }

  std::vector<uint32_t> typeIds_;
  bool dropOthers_;
};

app::FilterType typeFilterType() {
  FilterType type;
  type.name = "typefilter";
  type.doc =
      "Forwards in to out without the object chunks whose type is not listed in `types`; "
      "resource and event chunks pass unless drop-others. A message whose chunks all go "
      "still leaves (empty), so the consumer keeps its rate.";
  type.params.push_back(stringParam("types", "", "object type names to keep, comma-separated"));
  type.params.push_back(boolParam("drop-others", "false", "also drop resource and event chunks"));
  type.ports = inToOut;
  type.check = [](const std::vector<Param>& params) -> std::optional<std::string> {
    if (splitList(paramString(params, "types", "")).empty()) {
      return "parameter 'types' must list at least one object type name (e.g. \"rigid, "
             "point\")";
    }
    return std::nullopt;
  };
  return type;
}

}  // namespace

void registerTypeFilter(FilterRegistry& registry) {
  addBuiltin(
      registry,
      {typeFilterType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
         std::vector<uint32_t> typeIds;
         for (const auto& name : app::splitList(context.params().getString("types"))) {
           typeIds.push_back(msg::fnv1a32(name));
         }
         return std::unique_ptr<Filter>(std::make_unique<TypeFilter>(
             std::move(typeIds), context.params().getBool("drop-others")));
       }});
}

}  // namespace vrflow::daemon::filters
