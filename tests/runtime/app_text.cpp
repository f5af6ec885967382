#include "app_text.hpp"

#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {

std::string appXml(const std::string& modules, const std::string& filters,
                   const std::string& connections) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"test\" version=\"1\">\n"
         "  <hosts>\n    <host id=\"h1\"/>\n  </hosts>\n"
         "  <modules>\n" +
         modules + "  </modules>\n" +
         (filters.empty() ? "" : "  <filters>\n" + filters + "  </filters>\n") +
         "  <connections>\n" + connections + "  </connections>\n</application>\n";
}

std::string moduleXml(const std::string& id, const std::string& type, const std::string& inner) {
  const auto slash = type.find('/');
  return "    <module id=\"" + id + "\" package=\"" + type.substr(0, slash) + "\" type=\"" +
         type.substr(slash + 1) + "\"" +
         (inner.empty() ? "/>\n" : ">\n" + inner + "    </module>\n");
}

std::string filterXml(const std::string& id, const std::string& type, const std::string& params,
                      const std::string& attributes) {
  return "    <filter id=\"" + id + "\" type=\"" + type + "\"" +
         (attributes.empty() ? "" : " " + attributes) +
         (params.empty() ? "/>\n" : ">\n" + params + "    </filter>\n");
}

std::string paramXml(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

std::string connectXml(const std::string& from, const std::string& to,
                       const std::string& attributes) {
  return "    <connection from=\"" + from + "\" to=\"" + to + "\"" +
         (attributes.empty() ? "" : " " + attributes) + "/>\n";
}

std::vector<RecordedChunk> readRecording(const std::string& path) {
  std::vector<RecordedChunk> rows;
  const auto lines = readLines(path);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    // iteration,source,source_iteration,sim_time,kind,id,x,y,z
    std::vector<std::string> f;
    std::stringstream in(lines[i]);
    for (std::string field; std::getline(in, field, ',');) f.push_back(field);
    f.resize(9);
    RecordedChunk row;
    row.iteration = std::stol(f[0]);
    row.source = f[1];
    row.sourceIteration = std::stol(f[2]);
    row.kind = f[4];
    row.id = f[5];
    row.x = f[6];
    row.y = f[7];
    rows.push_back(row);
  }
  return rows;
}

std::vector<long> recordedCounters(const std::string& path) {
  std::vector<long> counters;
  for (const auto& row : readRecording(path)) {
    if (row.kind == "resource") counters.push_back(std::stol(row.x));
  }
  return counters;
}

}  // namespace vrflow::testing
