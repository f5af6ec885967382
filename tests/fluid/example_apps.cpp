#include "example_apps.hpp"

#include <stdexcept>

namespace vrflow::testing {
namespace {

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// The [begin, end) range of module `id`'s element, end just past its closing tag's line.
std::pair<std::size_t, std::size_t> moduleRange(const std::string& app, const std::string& id) {
  const auto tag = app.find("<module id=\"" + id + "\"");
  if (tag == std::string::npos) throw std::runtime_error("no module " + id);
  const auto begin = app.rfind('\n', tag) + 1;
  const auto close = app.find("</module>", tag);
  const auto selfClose = app.find("/>", tag);
  const auto lineEnd = [&](std::size_t at) { return app.find('\n', at) + 1; };
  if (selfClose < app.find('>', tag) + 1 && selfClose < close) return {begin, lineEnd(selfClose)};
  return {begin, lineEnd(close)};
}

void removeViewer(std::string& app) {
  const auto [begin, end] = moduleRange(app, "camera");
  app.erase(begin, end - begin);
  for (auto at = app.find("camera."); at != std::string::npos; at = app.find("camera.")) {
    const auto lineBegin = app.rfind('\n', at) + 1;
    app.erase(lineBegin, app.find('\n', at) + 1 - lineBegin);
  }
}

void setParam(std::string& app, const std::string& module, const std::string& name,
              const std::string& value) {
  const auto [begin, end] = moduleRange(app, module);
  const std::string line = "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
  const auto at = app.find("<param name=\"" + name + "\"", begin);
  if (at != std::string::npos && at < end) {
    const auto lineBegin = app.rfind('\n', at) + 1;
    app.replace(lineBegin, app.find('\n', at) + 1 - lineBegin, line);
    return;
  }
  const auto close = app.find("</module>", begin);
  if (close >= end) throw std::runtime_error("module " + module + " has no body to add to");
  app.insert(app.rfind('\n', close) + 1, line);
}

}  // namespace

std::string exampleForTest(const std::string& folder, const std::string& file,
                           const ParamOverrides& overrides, bool keepViewer) {
  const std::string base = sourceDir() + "/examples/" + folder + "/";
  std::string app = readFile(base + file);
  replaceAll(app, "value=\"scene.json\"", "value=\"" + base + "scene.json\"");
  if (!keepViewer) removeViewer(app);
  for (const auto& [key, value] : overrides) {
    const auto dot = key.find('.');
    setParam(app, key.substr(0, dot), key.substr(dot + 1), value);
  }
  return app;
}

CommandResult runApp(const TempDir& dir, const std::string& app, int iterations,
                     double timeoutSeconds, const std::string& extraArgs) {
  const auto file = dir.write("app.xml", app);
  return runCommand({"/bin/sh", "-c",
                     "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' run '" + file +
                         "' -n " + std::to_string(iterations) + " --timeout " +
                         std::to_string(static_cast<int>(timeoutSeconds * 0.8)) +
                         " --no-progress --report report.json " + extraArgs},
                    timeoutSeconds);
}

}  // namespace vrflow::testing
