#include "vrflow/editor/changes.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "vrflow/app/expand.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {

namespace {

// Field by field, without source locations.
bool sameParams(const std::vector<app::Param>& a, const std::vector<app::Param>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.name == y.name && x.value == y.value;
  });
}

bool sameInputs(const std::vector<app::InputConfig>& a, const std::vector<app::InputConfig>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.port == y.port && x.initialMessages == y.initialMessages && x.mode == y.mode;
  });
}

// Whether node `id` is the same element in both applications (same kind assumed).
bool sameNode(const app::Application& a, const app::Application& b, const std::string& id) {
  if (const auto* x = app::findModule(a, id)) {
    const auto* y = app::findModule(b, id);
    return y != nullptr && x->package == y->package && x->type == y->type && x->host == y->host &&
           x->endIt == y->endIt && sameParams(x->params, y->params) &&
           sameInputs(x->inputs, y->inputs);
  }
  if (const auto* x = app::findFilter(a, id)) {
    const auto* y = app::findFilter(b, id);
    return y != nullptr && x->type == y->type && x->host == y->host && x->plugin == y->plugin &&
           sameParams(x->params, y->params);
  }
  auto instance = [](const app::Application& app, const std::string& name) {
    auto it = std::find_if(app.instances.begin(), app.instances.end(),
                           [&](const app::Instance& i) { return i.id == name; });
    return it == app.instances.end() ? nullptr : &*it;
  };
  const auto* x = instance(a, id);
  const auto* y = instance(b, id);
  return x != nullptr && y != nullptr && x->composite == y->composite && x->host == y->host &&
         sameParams(x->params, y->params);
}

std::set<std::string> connectionKeys(const app::Application& app) {
  std::set<std::string> keys;
  for (const auto& c : app.connections) keys.insert(connectionKey(c));
  return keys;
}

}  // namespace

bool Changes::empty() const {
  return nodesAdded.empty() && nodesRemoved.empty() && nodesChanged.empty() && nodesMoved.empty() &&
         connectionsAdded.empty() && connectionsRemoved.empty() && !hostsChanged && !notesChanged &&
         !framesChanged;
}

std::string connectionKey(const app::Connection& connection) {
  return app::toString(connection.from) + " -> " + app::toString(connection.to);
}

Changes diff(const app::Application& before, const app::Application& after) {
  Changes changes;
  const std::vector<std::string> oldIds = nodeIds(before);
  const std::vector<std::string> newIds = nodeIds(after);
  const std::set<std::string> oldSet(oldIds.begin(), oldIds.end());
  const std::set<std::string> newSet(newIds.begin(), newIds.end());
  for (const auto& id : oldIds) {
    if (newSet.count(id) == 0) changes.nodesRemoved.push_back(id);
  }
  for (const auto& id : newIds) {
    if (oldSet.count(id) == 0) {
      changes.nodesAdded.push_back(id);
      continue;
    }
    if (nodeKind(before, id) != nodeKind(after, id) || !sameNode(before, after, id))
      changes.nodesChanged.push_back(id);
    const auto* p = app::findEditorNode(before, id);
    const auto* q = app::findEditorNode(after, id);
    if ((p == nullptr) != (q == nullptr) || (p != nullptr && (p->x != q->x || p->y != q->y)))
      changes.nodesMoved.push_back(id);
  }
  const auto oldKeys = connectionKeys(before);
  const auto newKeys = connectionKeys(after);
  std::set_difference(newKeys.begin(), newKeys.end(), oldKeys.begin(), oldKeys.end(),
                      std::back_inserter(changes.connectionsAdded));
  std::set_difference(oldKeys.begin(), oldKeys.end(), newKeys.begin(), newKeys.end(),
                      std::back_inserter(changes.connectionsRemoved));
  changes.hostsChanged = !std::equal(
      before.hosts.begin(), before.hosts.end(), after.hosts.begin(), after.hosts.end(),
      [](const auto& x, const auto& y) { return x.id == y.id && x.address == y.address; });
  changes.notesChanged =
      !std::equal(before.notes.begin(), before.notes.end(), after.notes.begin(), after.notes.end(),
                  [](const app::EditorNote& x, const app::EditorNote& y) {
                    return x.id == y.id && x.x == y.x && x.y == y.y && x.width == y.width &&
                           x.height == y.height && x.text == y.text;
                  });
  changes.framesChanged =
      !std::equal(before.frames.begin(), before.frames.end(), after.frames.begin(),
                  after.frames.end(), [](const app::EditorFrame& x, const app::EditorFrame& y) {
                    return x.id == y.id && x.x == y.x && x.y == y.y && x.width == y.width &&
                           x.height == y.height && x.title == y.title && x.color == y.color;
                  });
  return changes;
}

std::vector<std::pair<std::string, InstanceSummary>> instanceSummaries(
    const app::Application& app) {
  std::vector<std::pair<std::string, InstanceSummary>> result;
  if (app.instances.empty()) return result;
  auto flat = app::expandComposites(app, app::defaultCompositeSources(app));
  if (!flat) return result;
  std::map<std::string, std::pair<int, std::set<std::string>>> spread;
  for (const auto& m : flat->modules) {
    const auto sep = m.id.find(app::kInstanceSeparator);
    if (sep == std::string::npos) continue;
    auto& entry = spread[m.id.substr(0, sep)];
    ++entry.first;
    entry.second.insert(app::effectiveHost(*flat, m.host));
  }
  for (const auto& i : app.instances) {
    auto it = spread.find(i.id);
    if (it == spread.end()) continue;
    InstanceSummary summary;
    summary.modules = it->second.first;
    summary.hosts.assign(it->second.second.begin(), it->second.second.end());
    result.emplace_back(i.id, std::move(summary));
  }
  return result;
}

std::string badgeText(const InstanceSummary& summary) {
  std::string where;
  if (summary.hosts.size() <= 2) {
    for (const auto& h : summary.hosts) where += (where.empty() ? "" : ", ") + h;
  } else {
    where = std::to_string(summary.hosts.size()) + " hosts";
  }
  return std::to_string(summary.modules) + " modules on " + where;
}

}  // namespace vrflow::editor
