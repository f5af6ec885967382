#pragma once

// The quick-add popup: a search field over the list of node types, opened on the canvas by
// typing or by releasing a dragged wire over empty space.

#include <QFrame>
#include <QStringList>

class QLineEdit;
class QListWidget;

namespace vrflow::editor::gui {

class QuickAdd : public QFrame {
  Q_OBJECT

 public:
  explicit QuickAdd(QWidget* parent);

  /// Shows the popup with its top-left corner at `at` (parent coordinates), offering `specs`
  /// (palette specs, "module PACKAGE TYPE" / "filter TYPE") filtered by `text`.
  void open(QPoint at, const QStringList& specs, const QString& text, const QString& title);
  QLineEdit* searchField() const { return search_; }
  QListWidget* list() const { return list_; }
  /// The specs shown now (those matching the search), in order.
  QStringList shownSpecs() const;

 Q_SIGNALS:
  /// The user chose a type (Enter or a click): its palette spec.
  void chosen(const QString& spec);

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  void filter(const QString& text);
  void choose();

  QLineEdit* search_;
  QListWidget* list_;
  QStringList specs_;
};

}  // namespace vrflow::editor::gui
