#pragma once

#include <QDialog>
#include <QSettings>

#include "run_controller.hpp"
#include "vrflow/app/model.hpp"

class QButtonGroup;
class QCheckBox;
class QComboBox;
class QLineEdit;
class QPlainTextEdit;
class QRadioButton;
class QSpinBox;
class QTableWidget;

namespace vrflow::editor::gui {

/// The choices last made in the Run/Launch dialog for the application file `path`.
RunRequest loadRunChoices(QSettings& settings, const QString& path);
/// Remembers `request`'s choices for its application file.
void saveRunChoices(QSettings& settings, const RunRequest& request);

/// Run/Launch: where (this machine, or the file's hosts with a backend and a hostfile),
/// iterations, `--set` overrides, output folder, trace; it shows the exact command line.
class RunDialog : public QDialog {
  Q_OBJECT

 public:
  /// `program`: the `vrflow` shown in the command line; `initial`: the choices to start from.
  RunDialog(QString program, const app::Application& application, const RunRequest& initial,
            QWidget* parent = nullptr);

  /// The request the dialog's fields describe now.
  RunRequest request() const;
  /// The command line it will run (as shown).
  QString commandLine() const;

  QRadioButton* hereButton() const { return here_; }
  QRadioButton* hostsButton() const { return hosts_; }
  QComboBox* backend() const { return backend_; }
  QLineEdit* hostfile() const { return hostfile_; }
  QSpinBox* iterations() const { return iterations_; }
  QTableWidget* overrides() const { return overrides_; }
  QLineEdit* outputFolder() const { return output_; }
  QCheckBox* trace() const { return trace_; }
  QPlainTextEdit* commandLineView() const { return command_; }

 private:
  void addOverride(const QString& name, const QString& value);
  void showCommandLine();

  QString program_;
  RunRequest base_;
  QRadioButton* here_;
  QRadioButton* hosts_;
  QComboBox* backend_;
  QLineEdit* hostfile_;
  QSpinBox* iterations_;
  QTableWidget* overrides_;
  QLineEdit* output_;
  QCheckBox* trace_;
  QPlainTextEdit* command_;
};

}  // namespace vrflow::editor::gui
