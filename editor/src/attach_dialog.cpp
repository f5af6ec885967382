#include "attach_dialog.hpp"

#include <QDialogButtonBox>
#include <QHeaderView>
#include <QJsonArray>
#include <QLabel>
#include <QPushButton>
#include <QTableWidget>
#include <QVBoxLayout>

namespace vrflow::editor::gui {

AttachDialog::AttachDialog(const QList<QJsonObject>& runs, QWidget* parent)
    : QDialog(parent), table_(new QTableWidget(0, 5)) {
  setWindowTitle("Attach to a run");
  table_->setHorizontalHeaderLabels({"Run", "Application", "Hosts", "Iteration", "File"});
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->horizontalHeader()->setStretchLastSection(true);
  table_->verticalHeader()->hide();
  for (const QJsonObject& run : runs) {
    QStringList hosts;
    for (const auto& h : run.value("hosts").toArray()) hosts << h.toString();
    QString iteration = QString::number(run.value("iterations").toInteger());
    if (run.value("iteration_target").toInteger() > 0)
      iteration += "/" + QString::number(run.value("iteration_target").toInteger());
    const int row = table_->rowCount();
    table_->insertRow(row);
    const QStringList cells{run.value("id").toString(), run.value("application").toString(),
                            hosts.join(','), iteration, run.value("file").toString()};
    for (int column = 0; column < cells.size(); ++column)
      table_->setItem(row, column, new QTableWidgetItem(cells[column]));
  }
  table_->resizeColumnsToContents();
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  QPushButton* attach = buttons->button(QDialogButtonBox::Ok);
  attach->setText("Attach");
  attach->setEnabled(false);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(new QLabel(runs.isEmpty() ? "No run is going on (vrflow list)."
                                              : "The runs going on (vrflow list):"));
  layout->addWidget(table_);
  layout->addWidget(buttons);
  resize(760, 300);
  connect(table_, &QTableWidget::itemSelectionChanged, this,
          [this, attach] { attach->setEnabled(!chosenRun().isEmpty()); });
  connect(table_, &QTableWidget::cellDoubleClicked, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  if (table_->rowCount() == 1) table_->selectRow(0);
}

QString AttachDialog::chosenRun() const {
  const auto rows = table_->selectionModel()->selectedRows();
  return rows.isEmpty() ? QString() : table_->item(rows.front().row(), 0)->text();
}

}  // namespace vrflow::editor::gui
