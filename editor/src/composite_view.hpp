#pragma once

// The inside of a composite instance, opened over the canvas (drill down): a breadcrumb bar with
// "Back" and a read-only canvas of the composite's nodes and connections.

#include <QWidget>
#include <string>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"

class QLabel;
class QToolButton;

namespace vrflow::editor::gui {

class Canvas;

class CompositeView : public QWidget {
  Q_OBJECT

 public:
  /// Shows `inside` (what compositeInside() gives for an instance) over `parent`, which it covers
  /// while open; `path` is the breadcrumb's text.
  CompositeView(Canvas* parent, app::Application inside, const app::Catalog& catalog,
                const QString& path);

  Canvas* canvas() const { return canvas_; }
  /// The breadcrumb: "APPLICATION › INSTANCE (COMPOSITE)" and the exposed ports.
  QString breadcrumb() const;
  QToolButton* backButton() const { return back_; }
  const app::Application& inside() const { return inside_; }

 Q_SIGNALS:
  /// "Back" (or Escape): return to the application.
  void closeRequested();

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  app::Application inside_;
  Canvas* canvas_;
  QLabel* path_;
  QToolButton* back_;
};

}  // namespace vrflow::editor::gui
