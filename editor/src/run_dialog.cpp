#include "run_dialog.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QRadioButton>
#include <QSpinBox>
#include <QTableWidget>
#include <QVBoxLayout>

#include "qt_text.hpp"

namespace vrflow::editor::gui {

namespace {

// One settings group per application file.
QString groupOf(const QString& path) {
  return "run/" + QString::fromLatin1(path.toUtf8().toBase64(QByteArray::Base64UrlEncoding));
}

}  // namespace

RunRequest loadRunChoices(QSettings& settings, const QString& path) {
  RunRequest request;
  request.application = path;
  if (path.isEmpty()) return request;
  settings.beginGroup(groupOf(path));
  request.launch = settings.value("launch", false).toBool();
  request.backend = settings.value("backend", "local").toString();
  request.hostfile = settings.value("hostfile").toString();
  request.iterations = settings.value("iterations", 0).toInt();
  request.outputDir = settings.value("output").toString();
  request.trace = settings.value("trace", false).toBool();
  const QStringList overrides = settings.value("overrides").toStringList();
  for (const QString& o : overrides) {
    const qsizetype at = o.indexOf('=');
    if (at > 0) request.overrides.emplace_back(o.left(at), o.mid(at + 1));
  }
  settings.endGroup();
  return request;
}

void saveRunChoices(QSettings& settings, const RunRequest& request) {
  if (request.application.isEmpty()) return;
  settings.beginGroup(groupOf(request.application));
  settings.setValue("launch", request.launch);
  settings.setValue("backend", request.backend);
  settings.setValue("hostfile", request.hostfile);
  settings.setValue("iterations", request.iterations);
  settings.setValue("output", request.outputDir);
  settings.setValue("trace", request.trace);
  QStringList overrides;
  for (const auto& [name, value] : request.overrides) overrides << name + "=" + value;
  settings.setValue("overrides", overrides);
  settings.endGroup();
  settings.sync();
}

RunDialog::RunDialog(QString program, const app::Application& application,
                     const RunRequest& initial, QWidget* parent)
    : QDialog(parent),
      program_(std::move(program)),
      base_(initial),
      here_(new QRadioButton("This machine (vrflow run)")),
      hosts_(new QRadioButton("The file's hosts (vrflow launch)")),
      backend_(new QComboBox),
      hostfile_(new QLineEdit(initial.hostfile)),
      iterations_(new QSpinBox),
      overrides_(new QTableWidget(0, 2)),
      output_(new QLineEdit(initial.outputDir)),
      trace_(new QCheckBox("Write a trace (Perfetto JSON) in the output folder")),
      command_(new QPlainTextEdit) {
  setWindowTitle(initial.launch ? "Launch on hosts" : "Run");
  auto* form = new QFormLayout;
  auto* where = new QVBoxLayout;
  where->addWidget(here_);
  QStringList hostIds;
  for (const auto& h : application.hosts) hostIds << qtText(h.id + " (" + h.address + ")");
  hosts_->setToolTip(hostIds.isEmpty() ? "The file names no host" : hostIds.join(", "));
  where->addWidget(hosts_);
  (initial.launch ? hosts_ : here_)->setChecked(true);
  form->addRow("Where", where);

  backend_->addItems({"local", "ssh", "mpirun", "slurm"});
  backend_->setCurrentText(initial.backend);
  form->addRow("Backend", backend_);
  auto* hostfileRow = new QHBoxLayout;
  hostfile_->setPlaceholderText("the file's <hosts>");
  hostfileRow->addWidget(hostfile_);
  auto* chooseHostfile = new QPushButton("Choose\u2026");
  hostfileRow->addWidget(chooseHostfile);
  form->addRow("Hostfile", hostfileRow);

  iterations_->setRange(0, 1000000000);
  iterations_->setSpecialValueText("until it ends");
  iterations_->setValue(initial.iterations);
  form->addRow("Iterations", iterations_);

  overrides_->setHorizontalHeaderLabels({"node.parameter", "value"});
  overrides_->horizontalHeader()->setStretchLastSection(true);
  overrides_->setMinimumHeight(110);
  for (const auto& [name, value] : initial.overrides) addOverride(name, value);
  auto* overrideButtons = new QHBoxLayout;
  auto* addButton = new QPushButton("Add");
  auto* removeButton = new QPushButton("Remove");
  overrideButtons->addWidget(addButton);
  overrideButtons->addWidget(removeButton);
  overrideButtons->addStretch();
  auto* overridesBox = new QVBoxLayout;
  overridesBox->addWidget(overrides_);
  overridesBox->addLayout(overrideButtons);
  form->addRow("Overrides (--set)", overridesBox);

  auto* outputRow = new QHBoxLayout;
  output_->setPlaceholderText(QFileInfo(initial.application).absolutePath());
  outputRow->addWidget(output_);
  auto* chooseOutput = new QPushButton("Choose\u2026");
  outputRow->addWidget(chooseOutput);
  form->addRow("Output folder", outputRow);
  trace_->setChecked(initial.trace);
  form->addRow("Trace", trace_);

  command_->setReadOnly(true);
  command_->setMaximumHeight(80);
  QFont mono("monospace");
  mono.setStyleHint(QFont::Monospace);
  command_->setFont(mono);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  buttons->button(QDialogButtonBox::Ok)->setText(initial.launch ? "Launch" : "Run");
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form);
  layout->addWidget(new QLabel("Command line:"));
  layout->addWidget(command_);
  layout->addWidget(buttons);

  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  connect(here_, &QRadioButton::toggled, this, &RunDialog::showCommandLine);
  connect(backend_, &QComboBox::currentTextChanged, this, &RunDialog::showCommandLine);
  connect(hostfile_, &QLineEdit::textChanged, this, &RunDialog::showCommandLine);
  connect(iterations_, &QSpinBox::valueChanged, this, &RunDialog::showCommandLine);
  connect(overrides_, &QTableWidget::cellChanged, this, &RunDialog::showCommandLine);
  connect(output_, &QLineEdit::textChanged, this, &RunDialog::showCommandLine);
  connect(trace_, &QCheckBox::toggled, this, &RunDialog::showCommandLine);
  connect(addButton, &QPushButton::clicked, this, [this] {
    addOverride({}, {});
    overrides_->setCurrentCell(overrides_->rowCount() - 1, 0);
    overrides_->editItem(overrides_->item(overrides_->rowCount() - 1, 0));
  });
  connect(removeButton, &QPushButton::clicked, this, [this] {
    if (overrides_->currentRow() >= 0) overrides_->removeRow(overrides_->currentRow());
    showCommandLine();
  });
  connect(chooseHostfile, &QPushButton::clicked, this, [this] {
    const QString file = QFileDialog::getOpenFileName(this, "Hostfile", hostfile_->text());
    if (!file.isEmpty()) hostfile_->setText(file);
  });
  connect(chooseOutput, &QPushButton::clicked, this, [this] {
    const QString dir = QFileDialog::getExistingDirectory(this, "Output folder", output_->text());
    if (!dir.isEmpty()) output_->setText(dir);
  });
  showCommandLine();
}

void RunDialog::addOverride(const QString& name, const QString& value) {
  const QSignalBlocker quiet(overrides_);
  const int row = overrides_->rowCount();
  overrides_->insertRow(row);
  overrides_->setItem(row, 0, new QTableWidgetItem(name));
  overrides_->setItem(row, 1, new QTableWidgetItem(value));
}

RunRequest RunDialog::request() const {
  RunRequest request = base_;
  request.launch = hosts_->isChecked();
  request.backend = backend_->currentText();
  request.hostfile = hostfile_->text().trimmed();
  request.iterations = iterations_->value();
  request.overrides.clear();
  for (int row = 0; row < overrides_->rowCount(); ++row) {
    const QTableWidgetItem* name = overrides_->item(row, 0);
    const QTableWidgetItem* value = overrides_->item(row, 1);
    if (name == nullptr || name->text().trimmed().isEmpty()) continue;
    request.overrides.emplace_back(name->text().trimmed(),
                                   value != nullptr ? value->text() : QString());
  }
  request.outputDir = output_->text().trimmed();
  request.trace = trace_->isChecked();
  return request;
}

QString RunDialog::commandLine() const {
  const RunRequest now = request();
  return "cd " + shellCommandLine({now.workingDirectory()}) + " && " +
         shellCommandLine(QStringList{program_} + now.arguments());
}

void RunDialog::showCommandLine() {
  const bool launch = hosts_->isChecked();
  backend_->setEnabled(launch);
  hostfile_->setEnabled(launch);
  command_->setPlainText(commandLine());
}

}  // namespace vrflow::editor::gui
