#include "user_scenes.hpp"

#include <sstream>

#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::testing {

std::string userKeys(const std::vector<std::pair<double, msg::Vec3>>& keys) {
  std::ostringstream out;
  out.precision(17);
  out << "# the standing pose, translated\n";
  const auto pose = camera::standingPose();
  for (const auto& [t, shift] : keys)
    for (std::size_t j = 0; j < pose.size(); ++j)
      out << t << " " << camera::kUserJoints[j] << " " << pose[j][0] + shift[0] << " "
          << pose[j][1] + shift[1] << " " << pose[j][2] + shift[2] << "\n";
  return out.str();
}

std::string shiftedUserKeys(double start, double end, const msg::Vec3& shift) {
  return userKeys({{start, {0, 0, 0}}, {end, shift}});
}

std::vector<msg::Vec3> netPositions(const std::string& netFile) {
  std::istringstream in(netFile);
  std::string word;
  std::size_t nodes = 0;
  in >> word >> word >> word >> nodes;  // "massspring 1", "nodes N"
  std::vector<msg::Vec3> positions;
  std::string line;
  std::getline(in, line);
  for (std::size_t i = 0; i < nodes && std::getline(in, line); ++i) {
    std::istringstream fields(line);
    msg::Vec3 p{};
    fields >> p[0] >> p[1] >> p[2];
    positions.push_back(p);
  }
  return positions;
}

UserModules userModules(const std::string& keys, int cells, const msg::Vec3& origin, double edge,
                        const std::string& to) {
  std::ostringstream modules, connections;
  modules << R"(    <module id="truth" package="camera" type="user-truth" host="local">
      <param name="keyframes" value=")"
          << keys << R"("/>
      <param name="cells" value=")"
          << cells << R"("/>
      <param name="volume-origin" value=")"
          << origin[0] << " " << origin[1] << " " << origin[2] << R"("/>
      <param name="volume-edge" value=")"
          << edge << R"("/>
    </module>
    <module id="user" package="camera" type="user-animator" host="local"/>
)";
  connections << R"(    <connection from="truth.hull" to="user.hull"/>
)";
  std::istringstream targets(to);
  for (std::string target; targets >> target;)
    connections << R"(    <connection from="user.objects" to=")" << target << R"("/>
)";
  return {modules.str(), connections.str()};
}

}  // namespace vrflow::testing
