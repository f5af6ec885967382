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
#include "live_run.hpp"
#include "panels.hpp"
#include "qt_text.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor::gui {

namespace {

class HostTable : public QTableWidget {
 public:
  using QTableWidget::QTableWidget;
  std::vector<std::string>* ids = nullptr;

 protected:
  QMimeData* mimeData(const QList<QTableWidgetItem*>& items) const override {
    if (items.isEmpty() || ids == nullptr) return nullptr;
    const int row = items.front()->row();
    if (row < 0 || static_cast<std::size_t>(row) >= ids->size()) return nullptr;
    auto* mime = new QMimeData;
    mime->setData(kHostMime, QByteArray::fromStdString((*ids)[static_cast<std::size_t>(row)]));
    return mime;
  }
};

}  // namespace

// ---- Hosts -------------------------------------------------------------------------------

HostsPanel::HostsPanel(QWidget* parent) : QWidget(parent) {
  auto* table = new HostTable(0, 4);
  table->ids = &ids_;
  table_ = table;
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  table_->setHorizontalHeaderLabels({"", "Host", "Address", "Load"});
  table_->horizontalHeader()->setSectionResizeMode(0, QHeaderView::Fixed);
  table_->setColumnWidth(0, 22);
  table_->horizontalHeader()->setStretchLastSection(true);
  table_->verticalHeader()->hide();
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setDragEnabled(true);
  table_->setDragDropMode(QAbstractItemView::DragOnly);
  table_->setToolTip("Drag a host onto a node to run it there");
  layout->addWidget(table_);
  auto* buttons = new QHBoxLayout;
  auto* add = new QPushButton("Add");
  auto* remove = new QPushButton("Remove");
  auto* import = new QPushButton("Import\u2026");
  auto* assign = new QPushButton("Assign selection");
  assign->setToolTip("Run the selected nodes on this host");
  buttons->addWidget(add);
  buttons->addWidget(remove);
  buttons->addWidget(import);
  buttons->addWidget(assign);
  layout->addLayout(buttons);
  connect(add, &QPushButton::clicked, this, &HostsPanel::addRequested);
  connect(import, &QPushButton::clicked, this, &HostsPanel::importRequested);
  connect(remove, &QPushButton::clicked, this, [this] {
    if (!currentHost().empty()) Q_EMIT removeRequested(currentHost());
  });
  connect(assign, &QPushButton::clicked, this, [this] {
    if (!currentHost().empty()) Q_EMIT assignSelectionRequested(currentHost());
  });
  connect(table_, &QTableWidget::itemChanged, this, [this](QTableWidgetItem* item) {
    if (filling_ || item->row() < 0 || static_cast<std::size_t>(item->row()) >= ids_.size()) return;
    const std::string host = ids_[static_cast<std::size_t>(item->row())];
    const std::string text = stdText(item->text());
    const int column = item->column();
    // Applied after the table is done with its item (the refresh replaces the rows).
    QTimer::singleShot(0, this, [this, host, text, column] {
      if (column == 1) Q_EMIT renameRequested(host, text);
      if (column == 2) Q_EMIT addressChanged(host, text);
    });
  });
}

std::string HostsPanel::currentHost() const {
  const int row = table_->currentRow();
  if (row < 0 || static_cast<std::size_t>(row) >= ids_.size()) return {};
  return ids_[static_cast<std::size_t>(row)];
}

void HostsPanel::show(const app::Application& app) {
  filling_ = true;
  const int current = table_->currentRow();
  ids_.clear();
  table_->setRowCount(static_cast<int>(app.hosts.size()));
  for (std::size_t i = 0; i < app.hosts.size(); ++i) {
    const int row = static_cast<int>(i);
    ids_.push_back(app.hosts[i].id);
    auto* swatch = new QTableWidgetItem;
    swatch->setBackground(colorOfHost(i));
    swatch->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsDragEnabled);
    table_->setItem(row, 0, swatch);
    auto* id = new QTableWidgetItem(qtText(app.hosts[i].id));
    id->setFlags(id->flags() | Qt::ItemIsDragEnabled);
    table_->setItem(row, 1, id);
    table_->setItem(row, 2, new QTableWidgetItem(qtText(app.hosts[i].address)));
  }
  if (current >= 0 && current < table_->rowCount()) table_->setCurrentCell(current, 1);
  filling_ = false;
  fillLoad();
}

void HostsPanel::showLoad(const LiveRun& run) {
  load_.clear();
  for (const auto& host : run.hosts) {
    Load load;
    load.failed = host.lost || !host.cause.empty();
    if (host.lost) {
      load.text = "lost";
    } else if (!host.cause.empty()) {
      load.text = "failed";
    } else {
      load.text =
          QString("%1 cores \u00b7 %2 MiB").arg(host.cpu, 0, 'f', 2).arg(host.rssMiB, 0, 'f', 0);
    }
    load.tooltip = QString("%1 module(s): %2 cores of CPU, %3 MiB resident")
                       .arg(host.modules)
                       .arg(host.cpu, 0, 'f', 2)
                       .arg(host.rssMiB, 0, 'f', 1);
    if (!host.cause.empty()) load.tooltip += "\n" + qtText(host.cause);
    load_[host.id] = load;
  }
  fillLoad();
}

void HostsPanel::fillLoad() {
  const bool filling = filling_;
  filling_ = true;
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    const auto it = load_.find(ids_[i]);
    auto* item = new QTableWidgetItem(it == load_.end() ? QString() : it->second.text);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable);
    if (it != load_.end()) {
      item->setToolTip(it->second.tooltip);
      if (it->second.failed) {
        item->setForeground(QColor(200, 20, 20));
        item->setBackground(QColor(255, 225, 225));
      }
    }
    table_->setItem(static_cast<int>(i), 3, item);
  }
  filling_ = filling;
}

}  // namespace vrflow::editor::gui
