#pragma once

// A node on the canvas: a module (box), filter (rhombus) or composite instance (dashed box)
// with its ports.

#include <QColor>
#include <QGraphicsItem>
#include <QString>
#include <string>
#include <vector>

#include "port_item.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor::gui {

/// A module (box), filter (rhombus) or composite instance (dashed box).
class NodeItem : public QGraphicsItem {
 public:
  NodeItem(std::string id, NodeKind kind, QString title, QString subtitle, QColor hostColor,
           QString hostName, const std::vector<app::PortSpec>& ports);
  QRectF boundingRect() const override;
  QPainterPath shape() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& id() const { return id_; }
  NodeKind kind() const { return kind_; }
  QSizeF size() const { return size_; }
  /// The node's body in scene coordinates (what connections are routed around).
  QRectF sceneBody() const { return QRectF(scenePos(), size_); }
  std::vector<PortItem*> ports() const { return ports_; }
  /// Problems on this node: 0 none, 1 warning, 2 error; the tooltip lists them.
  void setProblems(int level, const QString& text);
  /// Text under the node (run statistics) and whether the run failed here.
  void setRunInfo(const QString& text, bool failed);
  /// Text on the node's badge ("5 modules on a, b" for instances), empty for none.
  void setBadge(const QString& text) {
    badge_ = text;
    update();
  }
  int problemLevel() const { return problemLevel_; }

 private:
  std::string id_;
  NodeKind kind_;
  QString title_;
  QString subtitle_;
  QColor hostColor_;
  QString hostName_;
  QSizeF size_;
  std::vector<PortItem*> ports_;
  int problemLevel_ = 0;
  QString runInfo_;
  QString badge_;
  bool failed_ = false;
};

}  // namespace vrflow::editor::gui
