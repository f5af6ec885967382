// The editor's dialogs (Reporter): messages, questions, file names, a new host.
#include <QDialog>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QLineEdit>
#include <QMessageBox>

#include "main_window.hpp"

namespace vrflow::editor::gui {
namespace {

constexpr const char* kFileFilter = "vrflow applications (*.xml);;All files (*)";

}  // namespace

void Reporter::error(QWidget* parent, const QString& title, const QString& text) {
  QMessageBox::critical(parent, title, text);
}

void Reporter::warning(QWidget* parent, const QString& title, const QString& text) {
  QMessageBox::warning(parent, title, text);
}

Reporter::Choice Reporter::askToSave(QWidget* parent, const QString& text) {
  const auto answer = QMessageBox::warning(
      parent, "Unsaved changes", text,
      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
  if (answer == QMessageBox::Save) return Choice::Save;
  if (answer == QMessageBox::Discard) return Choice::Discard;
  return Choice::Cancel;
}

QString Reporter::fileName(QWidget* parent, bool forSaving, const QString& suggestion) {
  return forSaving
             ? QFileDialog::getSaveFileName(parent, "Save application", suggestion, kFileFilter)
             : QFileDialog::getOpenFileName(parent, "Open", suggestion, kFileFilter);
}

bool Reporter::newHost(QWidget* parent, QString& id, QString& address) {
  QDialog dialog(parent);
  dialog.setWindowTitle("Add host");
  auto* form = new QFormLayout(&dialog);
  auto* idEdit = new QLineEdit(id);
  auto* addressEdit = new QLineEdit(address);
  form->addRow("Id", idEdit);
  form->addRow("Address", addressEdit);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  form->addRow(buttons);
  QObject::connect(buttons, &QDialogButtonBox::accepted, &dialog, &QDialog::accept);
  QObject::connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  if (dialog.exec() != QDialog::Accepted) return false;
  id = idEdit->text().trimmed();
  address = addressEdit->text().trimmed();
  return true;
}

std::unique_ptr<QFileDialog> makeHostfileDialog(QWidget* parent, const QString& folder) {
  auto dialog = std::make_unique<QFileDialog>(parent, "Import hostfile", folder);
  dialog->setFileMode(QFileDialog::ExistingFile);
  dialog->setAcceptMode(QFileDialog::AcceptOpen);
  dialog->setNameFilters({"All files (*)",
                          "Hostfiles (hosts hostfile* *.hostfile *.hosts nodes* "
                          "machinefile* *.txt)"});
  dialog->selectNameFilter("All files (*)");
  return dialog;
}

QString Reporter::hostfileName(QWidget* parent, const QString& folder) {
  const std::unique_ptr<QFileDialog> dialog = makeHostfileDialog(parent, folder);
  if (dialog->exec() != QDialog::Accepted || dialog->selectedFiles().isEmpty()) return {};
  return dialog->selectedFiles().front();
}

}  // namespace vrflow::editor::gui
