#pragma once

#include <cstdint>
#include <map>
#include <optional>

#include "vrflow/base/result.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/message/reader.hpp"
#include "vrflow/rigid/animator.hpp"
#include "vrflow/rigid/body.hpp"

// How rigid bodies travel in messages (the `rigid` built-in object type): the animator writes
// them, interactors keep a local copy. A kinematic (infinite-mass) body travels with mass = 0
// and an all-zero inertia (messages carry no infinities): read mass 0 as inverse mass 0; its shape
// is a static Raw resource (encodeShape) sent once, in the message with the body's add chunk,
// before it.

namespace vrflow::rigid {

/// Adds the shape resource (id `shapeId`) and an add chunk with every parameter.
void writeAdd(msg::MessageBuilder& builder, const Body& body, std::uint64_t shapeId);
/// Adds an update chunk with the parameters `change` names (pose: position, orientation,
/// bounds; velocity: both velocities).
void writeUpdate(msg::MessageBuilder& builder, const Body& body, const Change& change);

/// An interactor's copy of the rigid objects of the messages it receives, ordered by id. A body
/// appears once both its add chunk and its shape resource arrived.
class RigidObjectCopy {
 public:
  struct Entry {
    Body body;
    std::uint64_t shapeId = 0;
    bool hasShape = false;
    bool shapeChanged = false;  ///< set when the shape (or the body) is new since the last clear
    /// set when an add or update chunk of the body arrived since the last clear: a reader that
    /// keeps its own copy of the state (the contact solver) updates only these bodies
    bool stateChanged = false;
  };
  /// Applies the message's rigid add/update/delete chunks and shape resources. Returns an error
  /// for a shape resource that does not decode. `deleted` receives removed ids when given.
  Status apply(const msg::MessageView& message, std::vector<std::uint64_t>* deleted = nullptr);
  const std::map<std::uint64_t, Entry>& entries() const { return entries_; }
  std::map<std::uint64_t, Entry>& entries() { return entries_; }

 private:
  std::map<std::uint64_t, Entry> entries_;
  std::map<std::uint64_t, msg::Shape> shapes_;
};

}  // namespace vrflow::rigid
