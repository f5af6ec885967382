#include "node_forces.hpp"

#include <map>

#include "vrflow/massspring/events.hpp"

namespace vrflow::fluid {

int addNodeForceEvents(msg::MessageBuilder& builder, const std::vector<PointMass>& points,
                       const std::vector<BodyForce>& forces) {
  std::map<std::uint64_t, std::vector<massspring::NodeForce>> byNet;
  for (std::size_t i = 0; i < points.size() && i < forces.size(); ++i) {
    if (forces[i].cells == 0) continue;
    byNet[points[i].id].push_back({points[i].index, forces[i].force});
  }
  for (const auto& [net, list] : byNet) {
    builder.addEvent(net, massspring::kNodeForcesEvent, massspring::encodeNodeForces(list));
  }
  return static_cast<int>(byNet.size());
}

}  // namespace vrflow::fluid
