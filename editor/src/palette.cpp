#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMimeData>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QTableWidget>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>
#include <cmath>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "canvas.hpp"
#include "panels.hpp"
#include "qt_text.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor::gui {

namespace {

QString kindGroup(app::ModuleKind kind) {
  switch (kind) {
    case app::ModuleKind::Animator:
      return "Animators";
    case app::ModuleKind::Interactor:
      return "Interactors";
    case app::ModuleKind::Viewer:
      return "Viewers";
    case app::ModuleKind::Input:
      return "Inputs";
    case app::ModuleKind::Other:
      break;
  }
  return "Other modules";
}

constexpr int kSpecRole = Qt::UserRole + 1;
// A group's name without its count.
constexpr int kGroupRole = Qt::UserRole + 2;

}  // namespace

// ---- Palette -----------------------------------------------------------------------------

Palette::Palette(QWidget* parent)
    : QWidget(parent), search_(new QLineEdit), tree_(new PaletteTree) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  search_->setPlaceholderText("Search node types\u2026");
  search_->setClearButtonEnabled(true);
  layout->addWidget(search_);
  layout->addWidget(tree_);
  tree_->setHeaderHidden(true);
  tree_->setDragEnabled(true);
  tree_->setDragDropMode(QAbstractItemView::DragOnly);
  tree_->setSelectionMode(QAbstractItemView::SingleSelection);
  connect(search_, &QLineEdit::textChanged, this, &Palette::setFilterText);
  connect(tree_, &QTreeWidget::itemDoubleClicked, this, [this](QTreeWidgetItem* item) {
    const QString spec = item->data(0, kSpecRole).toString();
    if (!spec.isEmpty()) Q_EMIT addRequested(spec);
  });
}

void Palette::setCatalog(const app::Catalog& catalog) {
  tree_->clear();
  std::map<QString, QTreeWidgetItem*> groups;
  const QStringList order = {"Animators", "Interactors",   "Viewers",
                             "Inputs",    "Other modules", "Filters"};
  for (const auto& name : order) {
    auto* group = new QTreeWidgetItem(tree_, QStringList{name});
    group->setFlags(Qt::ItemIsEnabled);
    QFont font = group->font(0);
    font.setBold(true);
    group->setFont(0, font);
    group->setData(0, kGroupRole, name);
    groups[name] = group;
  }
  for (const app::ModuleType* type : catalog.moduleTypes()) {
    auto* item =
        new QTreeWidgetItem(groups[kindGroup(type->kind)],
                            QStringList{qtText(type->type) + "  (" + qtText(type->package) + ")"});
    item->setData(0, kSpecRole, "module " + qtText(type->package) + " " + qtText(type->type));
    item->setToolTip(0, qtText(type->package + "/" + type->type) +
                            (type->doc.empty() ? "" : "\n" + qtText(type->doc)));
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsDragEnabled);
  }
  for (const app::FilterType* type : catalog.filterTypes()) {
    auto* item = new QTreeWidgetItem(groups["Filters"], QStringList{qtText(type->name)});
    item->setData(0, kSpecRole, "filter " + qtText(type->name));
    item->setToolTip(0, qtText(type->name) + (type->doc.empty() ? "" : "\n" + qtText(type->doc)));
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsDragEnabled);
  }
  for (auto& [name, group] : groups) {
    if (group->childCount() == 0) delete group;
  }
  tree_->expandAll();
  setFilterText(search_->text());
}

void Palette::setFilterText(const QString& text) {
  for (int g = 0; g < tree_->topLevelItemCount(); ++g) {
    QTreeWidgetItem* group = tree_->topLevelItem(g);
    int shown = 0;
    for (int i = 0; i < group->childCount(); ++i) {
      QTreeWidgetItem* item = group->child(i);
      const bool match = text.isEmpty() || item->text(0).contains(text, Qt::CaseInsensitive) ||
                         item->toolTip(0).contains(text, Qt::CaseInsensitive);
      item->setHidden(!match);
      shown += match ? 1 : 0;
    }
    group->setHidden(shown == 0);
    // The count is of the entries shown: "(3)", or "(1 of 3)" while a search hides some.
    const int total = group->childCount();
    const QString name = group->data(0, kGroupRole).toString();
    group->setText(0, shown == total ? QString("%1 (%2)").arg(name).arg(total)
                                     : QString("%1 (%2 of %3)").arg(name).arg(shown).arg(total));
  }
}

QTreeWidgetItem* Palette::findEntry(const QString& spec) const {
  for (int g = 0; g < tree_->topLevelItemCount(); ++g) {
    QTreeWidgetItem* group = tree_->topLevelItem(g);
    for (int i = 0; i < group->childCount(); ++i) {
      if (group->child(i)->data(0, kSpecRole).toString() == spec) return group->child(i);
    }
  }
  return nullptr;
}

QMimeData* PaletteTree::mimeData(const QList<QTreeWidgetItem*>& items) const {
  if (items.isEmpty()) return nullptr;
  const QString spec = items.front()->data(0, kSpecRole).toString();
  if (spec.isEmpty()) return nullptr;
  auto* mime = new QMimeData;
  mime->setData(kNodeMime, spec.toUtf8());
  mime->setText(spec);
  return mime;
}

}  // namespace vrflow::editor::gui
