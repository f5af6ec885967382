#include "vrflow/editor/analysis.hpp"

#include <graphviz/cgraph.h>
#include <graphviz/gvc.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {

namespace {

constexpr std::string_view kCyclePrefix = "cycle without initial message (would deadlock): ";

struct Target {
  std::string node;
  std::optional<std::size_t> connection;
};

// The connections a deadlock message names ("a.x -> b.y, b.z -> a.w; give ...").
std::vector<std::size_t> cycleConnections(const app::Application& app, const std::string& message) {
  std::vector<std::size_t> result;
  const auto start = message.find(kCyclePrefix);
  if (start == std::string::npos) return result;
  std::string list = message.substr(start + kCyclePrefix.size());
  list = list.substr(0, list.find(';'));
  std::size_t pos = 0;
  while (pos < list.size()) {
    std::size_t end = list.find(", ", pos);
    if (end == std::string::npos) end = list.size();
    const std::string edge = list.substr(pos, end - pos);
    const auto arrow = edge.find(" -> ");
    if (arrow != std::string::npos) {
      const auto from = app::parseEndpoint(edge.substr(0, arrow));
      const auto to = app::parseEndpoint(edge.substr(arrow + 4));
      for (std::size_t c = 0; from && to && c < app.connections.size(); ++c) {
        const auto& conn = app.connections[c];
        if (conn.from.node == from->node && conn.from.port == from->port &&
            conn.to.node == to->node && conn.to.port == to->port) {
          result.push_back(c);
          break;
        }
      }
    }
    pos = end + 2;
  }
  return result;
}

}  // namespace

std::vector<Problem> findProblems(const app::Application& app, const app::Catalog& catalog,
                                  const ExtraCheck& extra, const OpenedText* opened) {
  const std::string fileName = app.file.empty() ? std::string("untitled.xml") : app.file;
  const std::string xml = opened != nullptr ? textToSave(app, *opened) : app::saveApplication(app);
  std::vector<app::Diagnostic> diagnostics;
  auto loaded = app::loadApplicationString(xml, fileName, &diagnostics);
  std::vector<Problem> problems;
  if (!loaded) {
    // The writer's output always parses; keep the message should it ever not.
    Problem p;
    p.text = loaded.error().message;
    p.message = p.text;
    problems.push_back(p);
    return problems;
  }
  if (extra) {
    auto more = extra(*loaded);
    diagnostics.insert(diagnostics.end(), more.begin(), more.end());
  }
  auto more = app::validate(*loaded, catalog);
  diagnostics.insert(diagnostics.end(), more.begin(), more.end());
  app::sortAndDeduplicate(diagnostics);

  // Each line of the canonical text holds one element: map lines to what they belong to.
  std::map<int, Target> byLine;
  for (const auto& m : loaded->modules) {
    byLine[m.loc.line] = {m.id, std::nullopt};
    for (const auto& p : m.params) byLine[p.loc.line] = {m.id, std::nullopt};
    for (const auto& i : m.inputs) byLine[i.loc.line] = {m.id, std::nullopt};
  }
  for (const auto& f : loaded->filters) {
    byLine[f.loc.line] = {f.id, std::nullopt};
    for (const auto& p : f.params) byLine[p.loc.line] = {f.id, std::nullopt};
  }
  for (const auto& i : loaded->instances) {
    byLine[i.loc.line] = {i.id, std::nullopt};
    for (const auto& p : i.params) byLine[p.loc.line] = {i.id, std::nullopt};
  }
  for (std::size_t c = 0; c < loaded->connections.size(); ++c) {
    byLine[loaded->connections[c].loc.line] = {std::string(), c};
  }

  for (const auto& d : diagnostics) {
    Problem p;
    p.severity = d.severity;
    p.text = app::formatDiagnostic(d);
    p.message = d.message;
    if (!d.loc.expandedFrom.empty()) {
      const std::string& outer = d.loc.expandedFrom.back().instance;
      p.node = outer.substr(0, outer.find(app::kInstanceSeparator));
    } else if (d.loc.file == fileName) {
      if (auto it = byLine.find(d.loc.line); it != byLine.end()) {
        p.node = it->second.node;
        p.connection = it->second.connection;
      }
    }
    p.cycle = cycleConnections(*loaded, d.message);
    problems.push_back(std::move(p));
  }
  return problems;
}

std::map<std::string, std::pair<double, double>> autoLayout(
    const app::Application& app, const std::map<std::string, std::pair<double, double>>& sizes) {
  std::map<std::string, std::pair<double, double>> result;
  const auto ids = nodeIds(app);
  if (ids.empty()) return result;
  // One Graphviz context for the process: contexts made and freed one after the other leave
  // its text-measuring plugin with dangling font caches (seen under AddressSanitizer).
  static GVC_t* const gvc = gvContext();
  Agraph_t* g = agopen(const_cast<char*>("app"), Agdirected, nullptr);
  agattr(g, AGRAPH, const_cast<char*>("rankdir"), const_cast<char*>("LR"));
  agattr(g, AGRAPH, const_cast<char*>("nodesep"), const_cast<char*>("0.35"));
  agattr(g, AGRAPH, const_cast<char*>("ranksep"), const_cast<char*>("0.6"));
  agattr(g, AGNODE, const_cast<char*>("shape"), const_cast<char*>("box"));
  agattr(g, AGNODE, const_cast<char*>("label"), const_cast<char*>(""));  // sizes are given: no text
  agattr(g, AGNODE, const_cast<char*>("fixedsize"), const_cast<char*>("true"));
  agattr(g, AGNODE, const_cast<char*>("width"), const_cast<char*>("2"));
  agattr(g, AGNODE, const_cast<char*>("height"), const_cast<char*>("1"));
  std::map<std::string, Agnode_t*> nodes;
  for (const auto& id : ids) {
    Agnode_t* n = agnode(g, const_cast<char*>(id.c_str()), 1);
    nodes[id] = n;
    double w = 160;
    double h = 80;
    if (auto it = sizes.find(id); it != sizes.end()) std::tie(w, h) = it->second;
    char text[32];
    std::snprintf(text, sizeof text, "%.3f", w / 72.0);
    agsafeset(n, const_cast<char*>("width"), text, const_cast<char*>("2"));
    std::snprintf(text, sizeof text, "%.3f", h / 72.0);
    agsafeset(n, const_cast<char*>("height"), text, const_cast<char*>("1"));
  }
  for (const auto& c : app.connections) {
    auto from = nodes.find(c.from.node);
    auto to = nodes.find(c.to.node);
    if (from == nodes.end() || to == nodes.end()) continue;
    agedge(g, from->second, to->second, nullptr, 1);
  }
  if (gvLayout(gvc, g, "dot") == 0) {
    for (const auto& [id, n] : nodes) {
      double w = 160;
      double h = 80;
      if (auto it = sizes.find(id); it != sizes.end()) std::tie(w, h) = it->second;
      const pointf centre = ND_coord(n);
      result[id] = {std::round(centre.x - w / 2), std::round(-centre.y - h / 2)};
    }
    gvFreeLayout(gvc, g);
  }
  agclose(g);
  return result;
}

std::string moduleNamedIn(const std::string& error) {
  const auto start = error.find("module '");
  if (start == std::string::npos) return {};
  const auto begin = start + 8;
  const auto end = error.find('\'', begin);
  if (end == std::string::npos) return {};
  return error.substr(begin, end - begin);
}

Result<RunReport> parseRunReport(const std::string& json) {
  const auto doc = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return makeError("the run report is not JSON");
  RunReport report;
  report.status = doc.value("status", std::string());
  report.error = doc.value("error", std::string());
  if (doc.contains("timing") && doc["timing"].is_object()) {
    report.wallSeconds = doc["timing"].value("wall_s", 0.0);
  }
  if (doc.contains("modules") && doc["modules"].is_array()) {
    for (const auto& m : doc["modules"]) {
      if (!m.is_object()) continue;
      RunReport::ModuleStats stats;
      stats.iterations = m.value("iterations", 0LL);
      stats.exit = m.value("exit", std::string());
      report.modules[m.value("id", std::string())] = stats;
    }
  }
  if (doc.contains("connections") && doc["connections"].is_array()) {
    for (const auto& c : doc["connections"]) {
      if (!c.is_object()) continue;
      RunReport::ConnectionStats stats;
      stats.from = c.value("from", std::string());
      stats.to = c.value("to", std::string());
      stats.messages = c.value("messages", 0LL);
      stats.bytes = c.value("bytes", 0LL);
      stats.dropped = c.value("dropped", 0LL);
      report.connections.push_back(stats);
    }
  }
  report.failedModule = moduleNamedIn(report.error);
  return report;
}

}  // namespace vrflow::editor
