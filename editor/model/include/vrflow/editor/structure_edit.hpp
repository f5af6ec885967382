#pragma once

// Edits that change the structure of an application on the canvas: a node inserted on a
// connection, nodes pasted at a point, a selection collapsed into a composite, and the inside of
// a composite instance (what the editor shows when it opens one).

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {

/// The first port of node `id` that a connection to (when `input`) or from `other` would accept,
/// or nullopt. `other` is an output when `input` is true, an input otherwise. beginIt/endIt are
/// considered only when `other` is one of them.
std::optional<std::string> firstCompatiblePort(const app::Application& app,
                                               const app::Catalog& catalog, std::string_view id,
                                               bool input, const app::Endpoint& other);

/// The palette specs ("module PACKAGE TYPE", "filter TYPE") of every catalog type, or only of
/// those with a port that would connect to `other` (an output when `otherIsOutput`).
std::vector<std::string> compatibleNodeSpecs(const app::Application& app,
                                             const app::Catalog& catalog,
                                             const app::Endpoint* other = nullptr,
                                             bool otherIsOutput = true);

/// Adds the node a palette spec names at (x, y); with `other`, connects it in the same edit:
/// `other` (an output when `otherIsOutput`) to the new node's first compatible port. Fails with
/// the reason when the spec is unknown or no port of the new node fits.
Result<Edit> addNodeFromSpec(const app::Application& app, const app::Catalog& catalog,
                             std::string_view spec, double x, double y,
                             const app::Endpoint* other = nullptr, bool otherIsOutput = true,
                             std::string* newId = nullptr);

/// Inserts node `id` on connection `connection` (from -> to): the connection is replaced by
/// from -> the node's first compatible input and the node's first compatible output -> to, with
/// the old connection's capacity and policy on both. With `position`, the node also moves
/// there. Fails with the reason (a port that does not fit, the node is an end of the
/// connection already).
Result<Edit> insertOnConnection(const app::Application& app, const app::Catalog& catalog,
                                std::string_view id, std::size_t connection,
                                std::optional<std::pair<double, double>> position = {});

/// Pastes what copyAsXml() made (as pasteXml()) with the top-left corner of the pasted nodes'
/// bounding box at `corner`; without one, beside the copied nodes (to their right).
Result<Edit> pasteXmlAt(const app::Application& app, std::string_view xml,
                        std::optional<std::pair<double, double>> corner,
                        std::vector<std::string>* pastedIds = nullptr);

/// Replaces nodes `ids` (modules, filters, instances) by one instance of a new composite defined
/// in the file: the nodes and the connections among them become its body, each connection that
/// crossed the selection's border goes to an exposed port of the new instance. The composite is
/// named `name` (made unique) and its instance too. Fails when a node cannot be written in a
/// composite (a filter from a plugin, a value holding `${`).
Result<Edit> collapseToComposite(const app::Application& app, const std::vector<std::string>& ids,
                                 std::string_view name = "group",
                                 std::string* instanceId = nullptr);

/// What a composite instance holds, expanded with the instance's parameters: its modules,
/// filters and connections with their ids inside the instance (nested instances expanded as
/// "inner:id"), on the application's hosts. Fails with the expansion's problems.
Result<app::Application> compositeInside(const app::Application& app, std::string_view instance);

}  // namespace vrflow::editor
