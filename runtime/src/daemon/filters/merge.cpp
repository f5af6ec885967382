// merge and gather: one message from every input, joined.
#include "merge.hpp"

#include "filters.hpp"

namespace vrflow::daemon::filters {

void MergeFilter::process(FilterContext& context) {
  const std::size_t n = context.inputCount();
  if (n == 0) return;  // nothing will ever arrive
  for (;;) {
    for (std::size_t i = 0; i < n; ++i) {
      if (context.input(i).empty()) return;
    }
    if (!context.canEmit(0)) return;
    parts_.clear();
    for (std::size_t i = 0; i < n; ++i) {
      parts_.push_back(std::move(context.input(i).front()));
      context.input(i).pop_front();
    }
    if (n == 1) {
      if (keepLast_) last_ = parts_.front();
      context.emit(0, std::move(parts_.front()));
      continue;
    }
    auto merged = join(context, parts_, rules_);
    if (!merged) {
      context.warn(merged.error().message);
      continue;
    }
    if (keepLast_) last_ = *merged;
    context.emit(0, std::move(*merged));
  }
}

namespace {

Result<std::unique_ptr<Filter>> makeMerge(const FilterContext& context) {
  std::string problem;
  auto rules = app::parseStampRules(context.params().getString("stamps"), problem);
  if (!rules) return makeError("filter '" + context.name() + "': " + problem);
  return std::unique_ptr<Filter>(std::make_unique<MergeFilter>(std::move(*rules)));
}

/// merge and gather: one message from each of in0..in{N-1}, chunks concatenated in input
/// order; the two differ only in their words.
FilterType concatenatingType(std::string name, std::string doc, const char* inputDoc,
                             const char* outputDoc) {
  FilterType type;
  type.name = std::move(name);
  type.doc = std::move(doc);
  declareNumberedInputs(type, inputDoc, outputDoc);
  type.params.push_back(stampsParam());
  type.check = checkStamps;
  return type;
}

FilterType mergeType() {
  return concatenatingType(
      "merge",
      "Waits for one message on each of in0..in{N-1} and emits their concatenation on out.",
      "one of the merged inputs", "the merged messages");
}

FilterType gatherType() {
  return concatenatingType("gather",
                           "Joins the parts made by a scatter: one message from each of "
                           "in0..in{N-1}, chunks concatenated in input order (the semantics of "
                           "merge).",
                           "one part", "the joined messages");
}

}  // namespace

void registerMerge(FilterRegistry& registry) {
  addBuiltin(registry, {mergeType(), makeMerge});
  addBuiltin(registry, {gatherType(), makeMerge});
}

}  // namespace vrflow::daemon::filters
