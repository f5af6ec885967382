#include "composite_view.hpp"

#include "canvas.hpp"
#include "vrflow/editor/analysis.hpp"

namespace vrflow::editor::gui {

CompositeView::CompositeView(Canvas* parent, app::Application inside, const app::Catalog& catalog,
                             const QString& path)
    : CanvasOverlay(parent, path, "compositeView"),
      inside_(std::move(inside)),
      canvas_(new Canvas) {
  canvas_->setReadOnly(true);
  CanvasState& state = canvas_->state();
  state.app = &inside_;
  state.catalog = &catalog;
  // Composites have no positions of their own: the automatic layout places their nodes.
  canvas_->rebuild();
  state.fallback = autoLayout(inside_, canvas_->nodeSizes());
  canvas_->rebuild();

  setContent(canvas_);
  canvas_->fitAll();
  canvas_->setFocus();
}

}  // namespace vrflow::editor::gui
