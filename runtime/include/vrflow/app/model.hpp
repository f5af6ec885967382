#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrflow/app/composite.hpp"
#include "vrflow/app/source_location.hpp"

namespace vrflow::app {

/// The XML comments written just before an element (or at the end of a section), each the text
/// between `<!--` and `-->` as written; the canonical writer puts them back in the same place.
using Comments = std::vector<std::string>;

/// A `name = value` setting of a module or filter; the value is parsed by its declared type.
struct Param {
  std::string name;
  std::string value;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// A machine that runs modules and filters.
struct Host {
  std::string id;
  std::string address = "127.0.0.1";
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// What a connection does when its bounded queue is full.
enum class QueuePolicy { Block, DropOldest, DropNewest };

/// Which message the default input filter hands to the module: the oldest pending per
/// connection (Fifo) or the newest, dropping older ones (Latest).
enum class InputMode { Fifo, Latest };

/// Settings of a module's default input filter for one input port.
struct InputConfig {
  std::string port;
  int initialMessages = 0;
  InputMode mode = InputMode::Fifo;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// When a module sends its `endIt` signal: as it calls wait() again, at the end of the
/// iteration (vrflow's default: a producer paced by it alternates with this module), or as
/// wait() returns, at the start of the iteration (FlowVR's timing: the producer computes its
/// next iteration while this module computes).
enum class EndItTiming { AfterIteration, AfterWait };

/// A module instance: one OS process running `package/type` on `host`.
struct Module {
  std::string id;
  std::string package;
  std::string type;
  std::string host;
  EndItTiming endIt = EndItTiming::AfterIteration;  ///< attribute `endit`
  std::vector<Param> params;
  std::vector<InputConfig> inputs;
  SourceLocation loc;
  Comments comments = {};     ///< written just before the element
  Comments endComments = {};  ///< written after its last child, before its end tag
};

/// A filter instance, run by the daemon of `host`.
struct Filter {
  std::string id;
  std::string type;
  std::string host;
  /// Shared library that defines `type` (docs/filters.md, "Plugins"); empty for built-ins.
  std::string plugin;
  std::vector<Param> params;
  SourceLocation loc;
  Comments comments = {};     ///< written just before the element
  Comments endComments = {};  ///< written after its last child, before its end tag
};

/// One end of a connection: a port of a module or filter, written "node.port" in XML.
struct Endpoint {
  std::string node;
  std::string port;
};

/// A bounded FIFO channel from an output port to an input port.
struct Connection {
  Endpoint from;
  Endpoint to;
  int capacity = 0;  ///< messages; 0 = the runtime's default
  QueuePolicy policy = QueuePolicy::Block;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// A use of a composite: its modules, filters and connections, with ids prefixed by "id:".
/// Connections write `id.port` for the composite's exposed ports.
struct Instance {
  std::string id;
  std::string composite;
  std::string host;  ///< where its nodes without a host run; resolved to the first host on load
  std::vector<Param> params;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// Where the editor draws a module or filter; the runtime ignores it.
struct EditorNode {
  EditorNode() = default;
  /// Keeps `EditorNode{ref, x, y}` working without naming `loc`.
  EditorNode(std::string inRef, double inX, double inY, SourceLocation inLoc = {})
      : ref(std::move(inRef)), x(inX), y(inY), loc(std::move(inLoc)) {}

  std::string ref;
  double x = 0;
  double y = 0;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// A note on the editor's canvas (`<note>` in `<editor>`): text in a box; the runtime ignores it.
struct EditorNote {
  std::string id;
  double x = 0;  ///< top-left corner, scene units
  double y = 0;
  double width = 200;
  double height = 80;
  std::string text;  ///< plain text, lines separated by '\n'
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// A frame on the editor's canvas (`<frame>` in `<editor>`): a titled, coloured rectangle drawn
/// behind the nodes it surrounds, for grouping; the runtime ignores it.
struct EditorFrame {
  std::string id;
  std::string title;
  double x = 0;  ///< top-left corner, scene units
  double y = 0;
  double width = 400;
  double height = 300;
  std::string color;  ///< "#rrggbb", empty for the default
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// A folder of node packages the file names (`<packages path="..."/>`): searched like a
/// --packages folder, after the command line's and before $VRFLOW_PACKAGE_PATH and the installed
/// packages (docs/application-format.md, "Package folders"). `path` is kept as written; a
/// relative one is taken from the folder of the file (packageFolderPath()).
struct PackageFolder {
  std::string path;
  SourceLocation loc;
  Comments comments = {};  ///< written just before the element
};

/// The comments of one section of an application file (`<modules>`, `<editor>`, ...).
struct SectionComments {
  std::string section;  ///< the section's element name
  Comments before;      ///< before its start tag
  Comments end;         ///< after its last element, before its end tag
};

/// A whole application file. Every vector keeps the order of the file.
struct Application {
  std::string name;
  std::vector<PackageFolder> packages;
  std::vector<Host> hosts;
  std::vector<Composite> composites;  ///< defined in the file; see expandComposites()
  std::vector<Module> modules;
  std::vector<Instance> instances;  ///< composites used; see expandComposites()
  std::vector<Filter> filters;
  std::vector<Connection> connections;
  std::vector<EditorNode> editor;
  std::vector<EditorNote> notes;    ///< in `<editor>`, after the nodes
  std::vector<EditorFrame> frames;  ///< in `<editor>`, after the notes
  std::string file;             ///< the file it was loaded from; empty for a model built in code
  Comments comments = {};       ///< before `<application>`
  Comments endComments = {};    ///< before `</application>`
  Comments afterComments = {};  ///< after `</application>`
  std::vector<SectionComments> sectionComments = {};  ///< sections with comments, in file order
};

/// The host the loader adds to a file that declares none.
inline constexpr std::string_view kDefaultHostId = "localhost";
/// The address of hosts that do not state one.
inline constexpr std::string_view kDefaultHostAddress = "127.0.0.1";

/// The module with this id, or nullptr.
const Module* findModule(const Application& app, std::string_view id);
/// The module with this id, or nullptr.
Module* findModule(Application& app, std::string_view id);
/// The filter with this id, or nullptr.
const Filter* findFilter(const Application& app, std::string_view id);
/// The filter with this id, or nullptr.
Filter* findFilter(Application& app, std::string_view id);
/// The composite instance with this id, or nullptr.
const Instance* findInstance(const Application& app, std::string_view id);
/// The composite defined in the file with this name, or nullptr.
const Composite* findComposite(const Application& app, std::string_view name);
/// The host with this id, or nullptr.
const Host* findHost(const Application& app, std::string_view id);
/// The editor position of this module or filter, or nullptr.
const EditorNode* findEditorNode(const Application& app, std::string_view ref);
/// The comments of section `section` (e.g. "modules"), or nullptr when it has none.
const SectionComments* findSectionComments(const Application& app, std::string_view section);
/// The `<input>` settings of one input port of a module, or nullptr when it has none.
const InputConfig* findInputConfig(const Module& module, std::string_view port);
/// The `<input>` settings of one port, or the defaults (no initial message, Fifo).
InputConfig inputConfigOrDefault(const Module& module, std::string_view port);

/// The parameter with this name, or nullptr.
const Param* findParam(const std::vector<Param>& params, std::string_view name);
/// A parameter's value as text, or `fallback` when it is absent.
std::string paramString(const std::vector<Param>& params, std::string_view name,
                        std::string_view fallback);
/// A parameter's value as an integer, or `fallback` when absent or not an integer.
long long paramInt(const std::vector<Param>& params, std::string_view name, long long fallback);
/// A parameter's value as a finite float, or `fallback` when absent or not a finite number.
double paramFloat(const std::vector<Param>& params, std::string_view name, double fallback);
/// A parameter's value as a bool ("true"/"false"/"1"/"0"), or `fallback` otherwise.
bool paramBool(const std::vector<Param>& params, std::string_view name, bool fallback);
/// Sets a parameter, replacing its value when present, appending it otherwise.
void setParam(std::vector<Param>& params, std::string_view name, std::string value);
/// The items of a comma-separated list ("point, rigid"), spaces around items removed and empty
/// items dropped.
std::vector<std::string> splitList(std::string_view text);

/// How a merging filter (merge, gather) combines a user stamp over the messages it joins:
/// the first message's value, or the sum, minimum or maximum of the numeric values.
enum class StampCombine { First, Sum, Min, Max };
/// One user stamp's combination (parameter `stamps` of merge and gather).
struct StampRule {
  std::string name;
  StampCombine combine = StampCombine::First;
};
/// The rules written "name:first|sum|min|max, ..."; nullopt with `problem` set when malformed.
std::optional<std::vector<StampRule>> parseStampRules(std::string_view text, std::string& problem);

/// The "node.port" text of an endpoint.
std::string toString(const Endpoint& endpoint);
/// Splits "node.port" at its first '.'; nullopt when either side would be empty.
std::optional<Endpoint> parseEndpoint(std::string_view text);

/// "block", "drop-oldest" or "drop-newest".
std::string toString(QueuePolicy policy);
/// The policy written `text`, or nullopt.
std::optional<QueuePolicy> parseQueuePolicy(std::string_view text);
/// "fifo" or "latest".
std::string toString(InputMode mode);
/// The mode written `text`, or nullopt.
std::optional<InputMode> parseInputMode(std::string_view text);
/// "after-iteration" or "after-wait".
std::string toString(EndItTiming timing);
/// The timing written `text`, or nullopt.
std::optional<EndItTiming> parseEndItTiming(std::string_view text);

/// The folder `folder` names: its path as written when absolute or when the application has no
/// file, else taken from the folder of `app.file`.
std::string packageFolderPath(const Application& app, const PackageFolder& folder);

/// The host a module or filter runs on: `host`, or the first host when empty.
std::string effectiveHost(const Application& app, const std::string& host);

}  // namespace vrflow::app
