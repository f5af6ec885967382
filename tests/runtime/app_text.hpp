#pragma once

// Small writers of application files and readers of core/recorder CSV files, for the
// end-to-end tests of filters.

#include <string>
#include <vector>

namespace vrflow::testing {

/// An application on one host `h1`; each argument is the text of one section's children.
std::string appXml(const std::string& modules, const std::string& filters,
                   const std::string& connections);
/// `<module>`: `type` is "package/type", `inner` its <param>/<input> lines.
std::string moduleXml(const std::string& id, const std::string& type,
                      const std::string& inner = "");
/// `<filter>` with its <param> lines; `attributes` are added to the element as written.
std::string filterXml(const std::string& id, const std::string& type,
                      const std::string& params = "", const std::string& attributes = "");
/// `<param name= value=/>`.
std::string paramXml(const std::string& name, const std::string& value);
/// `<connection from= to=/>` with extra attributes as written.
std::string connectXml(const std::string& from, const std::string& to,
                       const std::string& attributes = "");

/// One line of a core/recorder CSV file.
struct RecordedChunk {
  long iteration = 0;        ///< the recorder's iteration
  std::string source;        ///< the message's source stamp
  long sourceIteration = 0;  ///< the message's iteration stamp
  std::string kind;          ///< object, resource, event or empty
  std::string id;            ///< the chunk's id
  std::string x;             ///< objects: x of a point (empty for other types); resources: counter
  std::string y;             ///< objects: y of a point; resources: size
};

/// The lines of a recorder's CSV file after its header.
std::vector<RecordedChunk> readRecording(const std::string& path);
/// The resource counters recorded, in order (one per resource line).
std::vector<long> recordedCounters(const std::string& path);

}  // namespace vrflow::testing
