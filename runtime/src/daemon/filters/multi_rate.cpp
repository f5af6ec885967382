// repeat and decimate: run a module k times faster than its neighbours (multi-rate).
// repeat: each message of `in` leaves k times, the time step divided by k and the simulation
// time advancing by that sub-step; decimate: only the last message of every k leaves.
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "filters.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/object_type.hpp"

namespace vrflow::daemon::filters {
namespace {

class RepeatFilter final : public Filter {
 public:
  explicit RepeatFilter(uint64_t count) : count_(count == 0 ? 1 : count) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty() && context.canEmit(0)) {
      const auto view = viewOrWarn(context, in.front());
      if (!view) {
        in.pop_front();
        next_ = 0;
        continue;
      }
      const msg::StampsView stamps = view->stamps();
      const double subStep = stamps.timeStep / static_cast<double>(count_);
      auto copy = context.compose(view->bytes().size() + 64, [&](msg::MessageBuilder& builder) {
        builder.setStamps(stamps.toStamps());
        builder.setIteration(stamps.iteration * count_ + next_);
        builder.setSimTime(stamps.simTime + static_cast<double>(next_) * subStep);
        builder.setTimeStep(subStep);
        builder.setStampsOnly(view->stampsOnly());
        if (!view->stampsOnly()) builder.appendChunks(*view);
      });
      if (!copy) {
        context.warn("filter '" + context.name() + "': " + copy.error().message);
        return;  // shared memory is short: try again on the next pass
      }
      context.emit(0, std::move(*copy));
      if (++next_ == count_) {
        next_ = 0;
        in.pop_front();
      }
    }
  }

  // Ends once the last message has left all its copies.
  bool exhausted(FilterContext& context) const override {
    return context.inputClosed(0) && context.input(0).empty();
  }

 private:
  uint64_t count_;
  uint64_t next_ = 0;  // copies of in.front() already sent
};

// What the dropped messages of a decimate group said about objects and resources, folded so
// that the forwarded message brings a receiver to the same state as the whole group would.
class GroupState {
 public:
  bool empty() const { return order_.empty(); }
  void clear() {
    order_.clear();
    objects_.clear();
    resources_.clear();
  }

  // Folds the object and resource chunks of one message (events are not kept).
  void fold(const msg::MessageView& view) {
    for (const msg::ChunkView chunk : view) {
      if (chunk.kind() == msg::ChunkKind::Resource) {
        const auto bytes = chunk.bytes();
        Entry& entry = at(chunk.id(), true);
        entry.verbatim.assign(1, Bytes(bytes.begin(), bytes.end()));
        continue;
      }
      if (chunk.kind() != msg::ChunkKind::Object) continue;
      if (const auto object = chunk.asObject()) foldObject(chunk, *object);
    }
  }

  // Folds one object chunk into the object's entry.
  void foldObject(const msg::ChunkView& chunk, const msg::ObjectView& view) {
    const msg::ObjectView* object = &view;
    {
      Entry& entry = at(chunk.id(), false);
      const auto bytes = chunk.bytes();
      const bool add = object->op() == msg::ObjectOp::Add;
      if (object->op() == msg::ObjectOp::Delete || object->type() == nullptr ||
          (add == false && entry.type == nullptr && !entry.verbatim.empty())) {
        // A delete, a type this process does not know, or an update after one of those: kept
        // verbatim, in order (an add or a delete starts over).
        if (object->op() != msg::ObjectOp::Update) entry.verbatim.clear();
        entry.params.clear();
        entry.type = nullptr;
        entry.verbatim.emplace_back(bytes.begin(), bytes.end());
        return;
      }
      if (add || entry.type != object->type()) {
        entry.verbatim.clear();
        entry.params.clear();
        entry.op = object->op();
        entry.type = object->type();
      }
      for (const msg::ParamEntry param : object->params()) {
        entry.params[param.index].assign(param.bytes.begin(), param.bytes.end());
      }
    }
  }

  std::size_t bytes() const {
    std::size_t size = 0;
    for (const auto& [key, entry] : objects_) {
      size += 64;
      for (const auto& v : entry.verbatim) size += v.size() + 16;
      for (const auto& [index, value] : entry.params) size += 16 + value.size();
    }
    for (const auto& [key, entry] : resources_) {
      for (const auto& v : entry.verbatim) size += v.size() + 16;
    }
    return size;
  }

  // Drops what `last` (the message forwarded after the folded state) makes useless: a resource
  // it carries again, an object it adds or deletes again, an update whose every parameter it
  // updates again (so an animator that sends the same parameters every time forwards exactly
  // its last message, as without merge).
  void supersede(const msg::MessageView& last) {
    for (const msg::ChunkView chunk : last) {
      if (chunk.kind() == msg::ChunkKind::Resource) {
        resources_.erase(chunk.id());
        continue;
      }
      if (chunk.kind() != msg::ChunkKind::Object) continue;
      const auto object = chunk.asObject();
      const auto found = objects_.find(chunk.id());
      if (!object || found == objects_.end()) continue;
      const Entry& entry = found->second;
      bool covered = object->op() != msg::ObjectOp::Update;
      if (!covered && entry.type != nullptr && entry.type == object->type() &&
          entry.op == msg::ObjectOp::Update) {
        covered = true;
        for (const auto& [index, value] : entry.params) covered = covered && object->has(index);
      }
      if (covered) objects_.erase(found);
    }
    std::erase_if(order_, [&](const auto& key) {
      return (key.second ? resources_ : objects_).count(key.first) == 0;
    });
  }

  // Writes the folded state, then `last`'s chunks: an object of the group that `last` carries
  // too is written once, where `last` has it, with `last`'s parameters folded in; the others
  // (and the group's resources) come first, in the order they first appeared.
  void write(msg::MessageBuilder& builder, const msg::MessageView& last) {
    std::unordered_map<uint64_t, bool> inLast;  // object id -> written yet
    for (const msg::ChunkView chunk : last) {
      if (chunk.kind() != msg::ChunkKind::Object || objects_.count(chunk.id()) == 0) continue;
      if (const auto object = chunk.asObject()) {
        inLast.emplace(chunk.id(), false);
        foldObject(chunk, *object);
      }
    }
    for (const auto& [id, resource] : order_) {
      if (!resource && inLast.count(id) != 0) continue;
      writeEntry(builder, id, resource ? resources_.at(id) : objects_.at(id));
    }
    if (last.stampsOnly()) return;
    for (const msg::ChunkView chunk : last) {
      const auto found =
          chunk.kind() == msg::ChunkKind::Object ? inLast.find(chunk.id()) : inLast.end();
      if (found == inLast.end()) {
        builder.appendChunk(chunk);
      } else if (!found->second) {
        found->second = true;
        writeEntry(builder, chunk.id(), objects_.at(chunk.id()));
      }
    }
  }

 private:
  using Bytes = std::vector<std::byte>;
  struct Entry;
  static void writeEntry(msg::MessageBuilder& builder, uint64_t id, const Entry& entry) {
    const auto& types = msg::ObjectTypeRegistry::global();
    if (entry.type == nullptr) {
      for (const auto& chunk : entry.verbatim)
        builder.appendChunk(msg::ChunkView(chunk, 0, 0, &types));
      return;
    }
    auto writer = builder.addObject(id, *entry.type, entry.op);
    for (const auto& [index, value] : entry.params) writer.setEncoded(index, value);
  }
  struct Entry {
    const msg::ObjectType* type =
        nullptr;  // nullptr: verbatim chunks (resources, deletes, unknown types)
    msg::ObjectOp op = msg::ObjectOp::Update;
    std::map<uint32_t, Bytes> params;
    std::vector<Bytes> verbatim;
  };
  Entry& at(uint64_t id, bool resource) {
    auto& map = resource ? resources_ : objects_;
    const auto [it, added] = map.try_emplace(id);
    if (added) order_.emplace_back(id, resource);
    return it->second;
  }
  std::vector<std::pair<uint64_t, bool>> order_;
  std::unordered_map<uint64_t, Entry> objects_, resources_;
};

class DecimateFilter final : public Filter {
 public:
  DecimateFilter(uint64_t count, bool restamp, bool merge)
      : count_(count == 0 ? 1 : count), restamp_(restamp), merge_(merge) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty()) {
      if (seen_ + 1 < count_) {  // not the last of its group: its time step and state count
        if (const auto view = viewOrWarn(context, in.front())) {
          stepSum_ += view->stamps().timeStep;
          if (merge_) group_.fold(*view);
        }
        if (!merge_) context.countDropped(0, 1, "decimated");
        in.pop_front();
        ++seen_;
        continue;
      }
      if (!context.canEmit(0)) return;
      MessageRef message = std::move(in.front());
      in.pop_front();
      const uint64_t group = groups_++;
      const double steps = stepSum_;
      seen_ = 0;
      stepSum_ = 0;
      if (!restamp_ && group_.empty()) {
        context.emit(0, std::move(message));
        continue;
      }
      const auto view = viewOrWarn(context, message);
      if (!view) {
        group_.clear();
        continue;
      }
      group_.supersede(*view);
      if (!restamp_ && group_.empty()) {
        context.emit(0, std::move(message));
        continue;
      }
      // The group's state, then the last message's chunks (whose updates apply on top of it).
      const bool folded = !group_.empty();
      auto copy = context.compose(view->bytes().size() + group_.bytes() + 64,
                                  [&](msg::MessageBuilder& builder) {
                                    builder.setStamps(view->stamps().toStamps());
                                    if (restamp_) {
                                      builder.setIteration(group);
                                      builder.setTimeStep(steps + view->stamps().timeStep);
                                    }
                                    builder.setStampsOnly(view->stampsOnly() && !folded);
                                    group_.write(builder, *view);
                                  });
      group_.clear();
      if (!copy) {
        context.warn("filter '" + context.name() + "': " + copy.error().message);
        continue;
      }
      context.emit(0, std::move(*copy));
    }
  }

 private:
  uint64_t count_;
  bool restamp_;
  bool merge_;
  uint64_t seen_ = 0;    // messages of the current group consumed
  double stepSum_ = 0;   // their time steps
  uint64_t groups_ = 0;  // messages forwarded
  GroupState group_;     // their objects and resources (merge)
};

constexpr double kMaxRepeat = 1000000;

app::FilterType repeatType() {
  FilterType type;
  type.name = "repeat";
  type.doc =
      "Multi-rate input: each message of in leaves count times, copy j with time step dt/count, "
      "simulation time t + j*dt/count and iteration i*count + j, so the module behind it runs "
      "count iterations per message.";
  type.params.push_back(intParam("count", "10", 1, kMaxRepeat, "copies per message (k)"));
  type.ports = inToOut;
  return type;
}

app::FilterType decimateType() {
  FilterType type;
  type.name = "decimate";
  type.doc =
      "Multi-rate output: forwards only the last of every count messages of in. With restamp, "
      "its iteration becomes the group's number and its time step the sum of the group's.";
  type.params.push_back(intParam("count", "10", 1, kMaxRepeat, "messages per group (k)"));
  type.params.push_back(boolParam("restamp", "true",
                                  "iteration = group number, time step = the group's total (a "
                                  "copy); false forwards the message untouched, by reference"));
  type.params.push_back(boolParam("merge", "true",
                                  "the objects and resources of the dropped messages are folded "
                                  "into the forwarded one (an add and later updates become one "
                                  "add), so no state is lost; events of dropped messages are not "
                                  "kept"));
  type.ports = inToOut;
  return type;
}

}  // namespace

void registerMultiRate(FilterRegistry& registry) {
  addBuiltin(registry,
             {repeatType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                const long count = context.params().getInt("count");
                if (count < 1)
                  return makeError("filter '" + context.name() + "': count must be >= 1");
                return std::unique_ptr<Filter>(
                    std::make_unique<RepeatFilter>(static_cast<uint64_t>(count)));
              }});
  addBuiltin(registry,
             {decimateType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                const long count = context.params().getInt("count");
                if (count < 1)
                  return makeError("filter '" + context.name() + "': count must be >= 1");
                return std::unique_ptr<Filter>(std::make_unique<DecimateFilter>(
                    static_cast<uint64_t>(count), context.params().getBool("restamp"),
                    context.params().getBool("merge")));
              }});
}

}  // namespace vrflow::daemon::filters
