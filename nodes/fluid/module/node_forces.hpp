#pragma once

#include <vector>

#include "vrflow/fluid/solver.hpp"
#include "vrflow/message/builder.hpp"

// Forces on mass-spring nodes go back to the net's animator as the massspring package's
// node-forces event (user event kind 1025, vrflow/massspring/events.hpp): one event per net,
// one record per node the grid resolved.

namespace vrflow::fluid {

/// Adds one node-forces event per net to `builder`. `points` are the nodes given to the step and
/// `forces` the step's result for them (same order). Nodes covering no face get no record.
/// Returns the number of events added.
int addNodeForceEvents(msg::MessageBuilder& builder, const std::vector<PointMass>& points,
                       const std::vector<BodyForce>& forces);

}  // namespace vrflow::fluid
