#pragma once

// The inside of a composite instance, opened over the canvas (drill down): a breadcrumb bar with
// "Back" and a read-only canvas of the composite's nodes and connections.

#include <string>

#include "canvas_overlay.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::editor::gui {

class Canvas;

class CompositeView : public CanvasOverlay {
  Q_OBJECT

 public:
  /// Shows `inside` (what compositeInside() gives for an instance) over `parent`, which it covers
  /// while open; `path` is the breadcrumb's text.
  CompositeView(Canvas* parent, app::Application inside, const app::Catalog& catalog,
                const QString& path);

  Canvas* canvas() const { return canvas_; }
  const app::Application& inside() const { return inside_; }

 private:
  app::Application inside_;
  Canvas* canvas_;
};

}  // namespace vrflow::editor::gui
