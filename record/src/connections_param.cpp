#include "vrflow/record/connections_param.hpp"

#include <algorithm>
#include <sstream>

namespace vrflow::record {

Result<std::vector<RecordedConnection>> parseConnectionsParam(std::string_view text) {
  std::vector<RecordedConnection> connections;
  std::istringstream words{std::string(text)};
  std::string word;
  while (words >> word) {
    const auto colon = word.rfind(':');
    const auto dot = word.find('.');
    if (dot == std::string::npos || colon == std::string::npos || dot == 0 || dot + 1 >= colon ||
        colon + 1 == word.size()) {
      return makeError("'" + word + "' is not MODULE.PORT:DATA");
    }
    RecordedConnection c{word.substr(0, dot), word.substr(dot + 1, colon - dot - 1),
                         word.substr(colon + 1)};
    if (std::find(connections.begin(), connections.end(), c) != connections.end()) {
      return makeError("'" + c.name() + "' is listed twice");
    }
    connections.push_back(std::move(c));
  }
  if (connections.empty()) return makeError("no connection listed (expected MODULE.PORT:DATA ...)");
  return connections;
}

std::string connectionsParam(const std::vector<RecordedConnection>& connections) {
  std::string text;
  for (const auto& c : connections) {
    if (!text.empty()) text += ' ';
    text += c.name() + ":" + c.data;
  }
  return text;
}

}  // namespace vrflow::record
