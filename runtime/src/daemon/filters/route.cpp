// route: dynamic routing by bounding volume. Each receiver k publishes its volume of interest
// on interest{k}; out{k} gets only the object chunks of objects whose bounds meet it, the full
// current state of an object when it enters the volume, and the resources such objects refer
// to, once, then their updates while it holds an object that refers to them (a receiver whose
// objects all left stops getting a dynamic resource's updates, and gets its newest copy if one
// comes back: a dynamic resource such as a fluid region's particles costs only the tiles that see
// it).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "filters.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr std::size_t kIn = 0;

struct Box {
  msg::Vec3 min{}, max{};
  bool meets(const Box& other) const {
    for (std::size_t a = 0; a < 3; ++a) {
      if (min[a] > other.max[a] || other.min[a] > max[a]) return false;
    }
    return true;
  }
};

std::optional<Box> boxOf(const msg::Aabb& aabb) {
  Box box;
  for (std::size_t a = 0; a < 3; ++a) {
    if (!std::isfinite(aabb.min[a]) || !std::isfinite(aabb.max[a])) return std::nullopt;
    box.min[a] = std::min(aabb.min[a], aabb.max[a]);
    box.max[a] = std::max(aabb.min[a], aabb.max[a]);
  }
  return box;
}

// The parameter holding the bounds of an object of a built-in type (a point: its position).
std::optional<std::pair<uint32_t, bool>> boundsParamOf(uint32_t typeId) {
  if (typeId == msg::rigidType().id()) return std::pair{uint32_t{msg::RigidParam::kBounds}, true};
  if (typeId == msg::massSpringType().id())
    return std::pair{uint32_t{msg::MassSpringParam::kBounds}, true};
  if (typeId == msg::fluidType().id()) return std::pair{uint32_t{msg::FluidParam::kBounds}, true};
  if (typeId == msg::userType().id()) return std::pair{uint32_t{msg::UserParam::kBounds}, true};
  if (typeId == msg::pointType().id())
    return std::pair{uint32_t{msg::PointParam::kPosition}, false};
  return std::nullopt;
}

using Bytes = std::vector<std::byte>;

struct ObjectState {
  const msg::ObjectType* type = nullptr;  // nullptr: a type this process does not know
  uint32_t typeId = 0;
  std::map<uint32_t, Bytes> params;  // latest value of every parameter (known types)
  Bytes lastChunk;                   // unknown types: the latest chunk, verbatim
  std::optional<Box> bounds;
};

// What one receiver gets for one input message, in order.
struct Action {
  enum Kind { Chunk, Entry, Resource } kind;
  uint64_t value;  // Chunk: index in the message; Entry: object id; Resource: resource id
};

struct Receiver {
  std::optional<Box> interest;             // nullopt: nothing
  bool changed = false;                    // interest changed since the last message of `in`
  std::unordered_set<uint64_t> objects;    // objects whose state it holds (inside its volume)
  std::unordered_set<uint64_t> resources;  // resources it was sent
  std::unordered_set<uint64_t> wanted;     // resources its objects refer to, not seen yet
  std::vector<Action> actions;
  uint64_t interestsRead = 0;  // messages taken from interest{k} (lockstep)
};

class RouteFilter final : public Filter {
 public:
  RouteFilter(std::string stamp, bool initiallyAll, bool unboundedToAll, bool lockstep)
      : stamp_(std::move(stamp)),
        initiallyAll_(initiallyAll),
        unboundedToAll_(unboundedToAll),
        lockstep_(lockstep) {}

  Status start(FilterContext& context) override {
    receivers_.resize(context.outputCount());
    if (initiallyAll_) {
      for (auto& receiver : receivers_) receiver.interest = everything();
    }
    return {};
  }

  void process(FilterContext& context) override {
    auto& in = context.input(kIn);
    for (std::size_t r = 0; r < receivers_.size(); ++r) readInterest(context, r);
    while (!in.empty()) {
      if (lockstep_ && !interestsCaughtUp(context)) return;
      for (std::size_t o = 0; o < context.outputCount(); ++o) {
        if (!context.canEmit(o)) return;  // every receiver's part leaves together
      }
      MessageRef message = std::move(in.front());
      in.pop_front();
      ++taken_;
      const auto view = viewOrWarn(context, message);
      if (!view) continue;
      route(context, message, *view);
    }
  }

  // Goes on while `in` may bring something; the end of an interest input freezes its volume.
  bool exhausted(FilterContext& context) const override {
    return context.inputClosed(kIn) && context.input(kIn).empty();
  }

 private:
  static Box everything() {
    const double inf = std::numeric_limits<double>::infinity();
    return Box{{-inf, -inf, -inf}, {inf, inf, inf}};
  }

  // lockstep: message k of `in` (from 0) waits for k messages on every interest input that
  // may still bring one, so that each receiver's answer to message k-1 applies to message k
  // whatever the order in which the two paths deliver (another host, a slower link).
  bool interestsCaughtUp(FilterContext& context) {
    for (std::size_t r = 0; r < receivers_.size(); ++r) {
      readInterest(context, r);
      if (receivers_[r].interestsRead < taken_ && !context.inputClosed(1 + r)) return false;
    }
    return true;
  }

  // Applies the control messages pending on interest{r}: the last one that names a volume wins.
  void readInterest(FilterContext& context, std::size_t r) {
    auto& queue = context.input(1 + r);
    while (!queue.empty()) {
      MessageRef message = std::move(queue.front());
      queue.pop_front();
      ++receivers_[r].interestsRead;
      const auto view = viewOrWarn(context, message);
      if (!view) continue;
      for (const auto stamp : view->stamps().user) {
        if (stamp.name() != stamp_) continue;
        const auto text = stamp.asString();
        if (!text) {
          context.warn("filter '" + context.name() + "': user stamp '" + stamp_ +
                       "' must be a string (\"all\", \"none\" or six numbers)");
          continue;
        }
        std::optional<std::optional<Box>> parsed = parseInterest(*text);
        if (!parsed) {
          context.warn("filter '" + context.name() + "': cannot read the volume of interest '" +
                       std::string(*text) + "' on interest" + std::to_string(r) +
                       " (\"all\", \"none\" or \"minx miny minz maxx maxy maxz\")");
          continue;
        }
        auto& receiver = receivers_[r];
        receiver.interest = *parsed;
        receiver.changed = true;
      }
    }
  }

  static std::optional<std::optional<Box>> parseInterest(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::string first;
    in >> first;
    if (first == "none" || first.empty()) return std::optional<Box>{};
    if (first == "all") return std::optional<Box>{everything()};
    std::array<double, 6> v{};
    try {
      std::size_t used = 0;
      v[0] = std::stod(first, &used);
      if (used != first.size()) return std::nullopt;
    } catch (const std::exception&) {
      return std::nullopt;
    }
    for (std::size_t i = 1; i < 6; ++i) {
      if (!(in >> v[i])) return std::nullopt;
    }
    std::string rest;
    if (in >> rest) return std::nullopt;
    const auto box = boxOf(msg::Aabb{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
    if (!box) return std::nullopt;
    return std::optional<Box>{*box};
  }

  bool inside(const Receiver& receiver, const ObjectState& object) const {
    if (!object.bounds) return unboundedToAll_ && receiver.interest.has_value();
    return receiver.interest && receiver.interest->meets(*object.bounds);
  }

  // Entry of `id` into receiver r: the resources its state refers to first, then the state.
  void enter(Receiver& receiver, uint64_t id, const ObjectState& object) {
    receiver.objects.insert(id);
    if (object.type != nullptr) {
      for (const auto& [index, value] : object.params) {
        if (index >= object.type->paramCount() ||
            object.type->param(index).kind != msg::ParamKind::Id || value.size() != 8) {
          continue;
        }
        uint64_t resource = 0;
        std::memcpy(&resource, value.data(), 8);  // little-endian on the wire and here
        want(receiver, resource);
      }
    }
    receiver.actions.push_back({Action::Entry, id});
  }

  void want(Receiver& receiver, uint64_t resource) {
    if (resource == 0 || receiver.resources.count(resource) != 0) return;
    if (resources_.count(resource) != 0) {
      receiver.resources.insert(resource);
      receiver.actions.push_back({Action::Resource, resource});
    } else {
      receiver.wanted.insert(resource);
    }
  }

  // True when an object the receiver holds refers to `resource` (an object that left since it
  // asked for it does not count; it asks again when it comes back).
  bool holdsReferrer(const Receiver& receiver, uint64_t resource) const {
    for (const uint64_t id : receiver.objects) {
      const auto found = objects_.find(id);
      if (found == objects_.end() || found->second.type == nullptr) continue;
      const ObjectState& object = found->second;
      for (const auto& [index, value] : object.params) {
        if (index < object.type->paramCount() &&
            object.type->param(index).kind == msg::ParamKind::Id && value.size() == 8 &&
            std::memcmp(value.data(), &resource, 8) == 0) {
          return true;
        }
      }
    }
    return false;
  }

  void updateObject(const msg::ChunkView& chunk, const msg::ObjectView& object) {
    auto& state = objects_[chunk.id()];
    if (object.op() == msg::ObjectOp::Add || state.typeId != object.typeId()) {
      state = ObjectState{};
      state.typeId = object.typeId();
      state.type = object.type();
    }
    if (state.type == nullptr) {
      const auto bytes = chunk.bytes();
      state.lastChunk.assign(bytes.begin(), bytes.end());
      return;
    }
    for (const msg::ParamEntry entry : object.params()) {
      state.params[entry.index].assign(entry.bytes.begin(), entry.bytes.end());
    }
    const auto boundsParam = boundsParamOf(state.typeId);
    if (!boundsParam || !object.has(boundsParam->first)) return;
    if (boundsParam->second) {
      if (const auto aabb = object.aabb(boundsParam->first)) state.bounds = boxOf(*aabb);
    } else if (const auto p = object.vec3(boundsParam->first)) {
      state.bounds = boxOf(msg::Aabb{*p, *p});
    }
  }

  void route(FilterContext& context, const MessageRef& message, const msg::MessageView& view) {
    // A receiver whose volume moved forgets the objects it no longer meets (it knows its own
    // volume); those that meet it and that this message does not bring enter after the
    // message's chunks, so that an object of the message enters once, with its newest state.
    for (auto& receiver : receivers_) {
      receiver.actions.clear();
      if (!receiver.changed) continue;
      for (auto it = receiver.objects.begin(); it != receiver.objects.end();) {
        const auto object = objects_.find(*it);
        if (object == objects_.end() || !inside(receiver, object->second)) {
          it = receiver.objects.erase(it);
        } else {
          ++it;
        }
      }
    }
    for (const msg::ChunkView chunk : view) {
      const uint64_t index = chunk.index();
      const uint64_t id = chunk.id();
      switch (chunk.kind()) {
        case msg::ChunkKind::Object: {
          const auto object = chunk.asObject();
          if (!object) break;
          if (object->op() == msg::ObjectOp::Delete) {
            objects_.erase(id);
            for (auto& receiver : receivers_) {
              if (receiver.objects.erase(id) != 0)
                receiver.actions.push_back({Action::Chunk, index});
            }
            break;
          }
          updateObject(chunk, *object);
          const ObjectState& state = objects_[id];
          for (auto& receiver : receivers_) {
            const bool holds = receiver.objects.count(id) != 0;
            const bool in = inside(receiver, state);
            if (in && !holds) {
              enter(receiver, id, state);
            } else if (holds) {
              if (in) {
                for (const msg::ParamEntry entry : object->params()) {  // a new resource?
                  if (state.type != nullptr && entry.index < state.type->paramCount() &&
                      state.type->param(entry.index).kind == msg::ParamKind::Id &&
                      entry.bytes.size() == 8) {
                    uint64_t resource = 0;
                    std::memcpy(&resource, entry.bytes.data(), 8);
                    want(receiver, resource);
                  }
                }
              } else {
                receiver.objects.erase(id);  // leaves: this chunk, which moves it out, is the last
              }
              receiver.actions.push_back({Action::Chunk, index});
            }
          }
          break;
        }
        case msg::ChunkKind::Resource: {
          const auto bytes = chunk.bytes();
          resources_[id].assign(bytes.begin(), bytes.end());
          const auto resource = chunk.asResource();
          const bool dynamic = resource && resource->dynamic();
          for (auto& receiver : receivers_) {
            if (receiver.resources.count(id) != 0) {
              if (!dynamic || holdsReferrer(receiver, id)) {
                receiver.actions.push_back({Action::Chunk, index});  // an update of one it has
              } else {
                receiver.resources.erase(id);  // no longer needed; resent on re-entry
              }
            } else if (receiver.wanted.erase(id) != 0 && holdsReferrer(receiver, id)) {
              receiver.resources.insert(id);
              receiver.actions.push_back({Action::Chunk, index});
            }
          }
          break;
        }
        default:  // events go to every receiver
          for (auto& receiver : receivers_) receiver.actions.push_back({Action::Chunk, index});
          break;
      }
    }
    for (auto& receiver : receivers_) {
      if (!receiver.changed) continue;
      receiver.changed = false;
      std::vector<uint64_t> entering;
      for (const auto& [id, object] : objects_) {
        if (receiver.objects.count(id) == 0 && inside(receiver, object)) entering.push_back(id);
      }
      std::sort(entering.begin(), entering.end());  // the same order on every run
      for (const uint64_t id : entering) enter(receiver, id, objects_[id]);
    }
    emitAll(context, message, view);
  }

  void emitAll(FilterContext& context, const MessageRef& message, const msg::MessageView& view) {
    std::vector<msg::ChunkView> chunks;
    for (const msg::ChunkView chunk : view) chunks.push_back(chunk);
    const auto& types = msg::ObjectTypeRegistry::global();
    for (std::size_t r = 0; r < receivers_.size(); ++r) {
      const auto& actions = receivers_[r].actions;
      bool whole = actions.size() == chunks.size();
      for (std::size_t i = 0; whole && i < actions.size(); ++i) {
        whole = actions[i].kind == Action::Chunk && actions[i].value == i;
      }
      if (whole) {
        context.emit(r, message);  // everything passes: by reference
        continue;
      }
      std::size_t size = 256;
      for (const auto& action : actions) {
        if (action.kind == Action::Chunk) size += chunks[action.value].bytes().size();
        if (action.kind == Action::Resource) size += resources_[action.value].size();
        if (action.kind == Action::Entry) {
          const auto& object = objects_[action.value];
          size += 64 + object.lastChunk.size();
          for (const auto& [index, value] : object.params) size += 16 + value.size();
        }
      }
      auto part = context.compose(size, [&](msg::MessageBuilder& builder) {
        builder.setStamps(view.stamps().toStamps());
        for (const auto& action : actions) {
          if (action.kind == Action::Chunk) {
            builder.appendChunk(chunks[action.value]);
          } else if (action.kind == Action::Resource) {
            const auto& bytes = resources_[action.value];
            builder.appendChunk(msg::ChunkView(bytes, 0, 0, &types));
          } else {
            const auto found = objects_.find(action.value);
            if (found == objects_.end()) continue;  // deleted later in the same message
            const ObjectState& object = found->second;
            if (object.type == nullptr) {
              builder.appendChunk(msg::ChunkView(object.lastChunk, 0, 0, &types));
              continue;
            }
            auto writer = builder.addObject(action.value, *object.type, msg::ObjectOp::Add);
            for (const auto& [index, value] : object.params) writer.setEncoded(index, value);
          }
        }
      });
      if (!part) {
        context.warn("filter '" + context.name() + "': " + part.error().message);
        continue;
      }
      context.emit(r, std::move(*part));
    }
  }

  std::string stamp_;
  bool initiallyAll_;
  bool unboundedToAll_;
  bool lockstep_;
  uint64_t taken_ = 0;  // messages of `in` routed so far
  std::vector<Receiver> receivers_;
  std::unordered_map<uint64_t, ObjectState> objects_;
  std::unordered_map<uint64_t, Bytes> resources_;  // latest chunk of every resource, verbatim
};

app::FilterType routeType() {
  FilterType type;
  type.name = "route";
  type.doc =
      "Dynamic routing by bounding volume: receiver k publishes its volume of interest on "
      "interest{k} (string user stamp `stamp`: \"minx miny minz maxx maxy maxz\", \"all\" or "
      "\"none\"); out{k} gets the chunks of objects whose bounds meet it, the full state of "
      "an object when it enters, and the resources those objects refer to, once.";
  const app::ParamSpec outputCount =
      intParam("outputs", "1", 1, static_cast<double>(kMaxFilterPorts), "number of receivers N");
  type.params.push_back(outputCount);
  const app::ParamSpec stamp =
      stringParam("stamp", "interest", "name of the string user stamp holding the volume");
  type.params.push_back(stamp);
  type.params.push_back(enumParam("initially", {"none", "all"},
                                  "the volume of every receiver before its first interest"));
  type.params.push_back(enumParam("unbounded", {"all", "drop"},
                                  "objects whose bounds are unknown: to every receiver that has "
                                  "a volume, or to none"));
  type.params.push_back(boolParam("lockstep", "false",
                                  "message k of `in` waits for k messages on every open "
                                  "interest input: each receiver's answer to the sender's "
                                  "previous message applies, on any host layout"));
  type.ports = [outputCount](const std::vector<Param>& params) {
    const long long n = clampedInt(outputCount, params);
    std::vector<PortSpec> ports{filterPort("in", true, "the sender's messages")};
    for (auto& port : numberedPorts("interest", n, true, "a receiver's volume of interest")) {
      port.gating = false;  // out{k} leaves without it: a receiver -> interest cycle is fine
      ports.push_back(std::move(port));
    }
    for (auto& port : numberedPorts("out", n, false, "what one receiver's volume meets")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  type.check = [stamp](const std::vector<Param>& params) -> std::optional<std::string> {
    if (declaredText(stamp, params).empty()) {
      return "parameter 'stamp' must name a user stamp (e.g. \"interest\")";
    }
    return std::nullopt;
  };
  return type;
}

}  // namespace

void registerRoute(FilterRegistry& registry) {
  addBuiltin(
      registry,
      {routeType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
         const std::string initially = context.params().getString("initially");
         const std::string unbounded = context.params().getString("unbounded");
         if (initially != "none" && initially != "all") {
           return makeError("filter '" + context.name() + "': initially must be none or all");
         }
         if (unbounded != "all" && unbounded != "drop") {
           return makeError("filter '" + context.name() + "': unbounded must be all or drop");
         }
         return std::unique_ptr<Filter>(std::make_unique<RouteFilter>(
             context.params().getString("stamp"), initially == "all", unbounded == "all",
             context.params().getBool("lockstep")));
       }});
}

}  // namespace vrflow::daemon::filters
