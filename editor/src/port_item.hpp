#pragma once

// A port on the canvas: a small circle on its node's edge, with the input's initial messages
// drawn as tokens beside it.

#include <QGraphicsItem>
#include <string>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::editor::gui {

/// A port: a small circle on its node's edge with its name beside it (drawn by the node).
class PortItem : public QGraphicsItem {
 public:
  PortItem(QGraphicsItem* parent, std::string node, app::PortSpec spec);
  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& node() const { return node_; }
  const app::PortSpec& spec() const { return spec_; }
  app::Endpoint endpoint() const { return {node_, spec_.name}; }
  /// 0 none, 1 accepts the connection being dragged, -1 refuses it.
  void setHighlight(int highlight) {
    highlight_ = highlight;
    update();
  }
  void setLabelSide(bool left) { labelLeft_ = left; }
  /// The initial messages of an input: one dot each beside the port, "×N" past three.
  void setTokens(int count);
  int tokens() const { return tokens_; }

 private:
  std::string node_;
  app::PortSpec spec_;
  int highlight_ = 0;
  bool labelLeft_ = false;
  int tokens_ = 0;
};

}  // namespace vrflow::editor::gui
