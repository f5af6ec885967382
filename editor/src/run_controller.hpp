#pragma once

#include <QJsonObject>
#include <QList>
#include <QObject>
#include <QProcess>
#include <QString>
#include <QStringList>
#include <optional>
#include <utility>
#include <vector>

#include "live_run.hpp"
#include "vrflow/editor/analysis.hpp"

namespace vrflow::editor::gui {

/// What to start: `vrflow run` or `vrflow launch` of one application file, with the choices of
/// the Run/Launch dialog. arguments() is the exact command line.
struct RunRequest {
  QString application;        ///< the application file
  bool launch = false;        ///< `vrflow launch` on the file's hosts; false: `vrflow run` here
  QString backend = "local";  ///< launch only: local, ssh, mpirun, slurm
  QString hostfile;           ///< launch only: `--hosts FILE`; empty: the file's own hosts
  int iterations = 0;         ///< `--iterations N`; 0: until the application ends
  /// `--set NODE.PARAM=VALUE` each, in order.
  std::vector<std::pair<QString, QString>> overrides;
  QString outputDir;        ///< the run's working folder; empty: the application file's folder
  bool trace = false;       ///< `--trace <outputDir>/<application>.trace.json`
  QStringList packageDirs;  ///< `--packages DIR` each

  /// The working folder the run starts in.
  QString workingDirectory() const;
  /// The trace file written with `trace` (absolute; empty without).
  QString traceFile() const;
  /// The report it writes: `<outputDir>/<application>.report.json` (absolute).
  QString reportFile() const;
  /// The arguments after the program, ending with `--report REPORT --events -`.
  QStringList arguments() const;
};

/// `words` as one shell command line (each quoted when it needs it), for people to read and copy.
QString shellCommandLine(const QStringList& words);

/// One run the editor follows: started by it (a QProcess of `vrflow run|launch ... --events -`)
/// or attached to (`vrflow monitor RUN --follow-events`). Either way each line of the child's
/// standard output is an event (docs/events.md) fed to live(); its stderr is the run log.
class RunController : public QObject {
  Q_OBJECT

 public:
  /// `program`: the `vrflow` executable.
  explicit RunController(QString program, QObject* parent = nullptr);
  ~RunController() override;

  /// Starts a run; false (and a logLine saying why) while one is followed.
  bool start(const RunRequest& request);
  /// Follows the registered run `runId` (any unique start of it) that this editor did not start.
  bool attach(const QString& runId);
  /// Stops the run: SIGTERM to the `vrflow` it started, or `vrflow stop RUN` when attached.
  void stop();
  bool running() const;
  bool attached() const { return attached_; }

  /// The run's id in the registry (docs/operations.md); empty until known.
  QString runId() const { return runId_; }
  /// The `--trace` file of a started run (empty without one).
  QString traceFile() const { return traceFile_; }
  /// The log folder of the run (`log_dir` of its registration); empty until known.
  QString logDir() const { return logDir_; }
  /// The exact command line of the last start or attach.
  QString commandLine() const { return commandLine_; }
  /// The report of the last started run once it ended (none if it wrote none, or attached).
  const std::optional<RunReport>& report() const { return report_; }
  /// What the event stream told of the run.
  LiveRunModel* live() const { return live_; }
  const QString& program() const { return program_; }

  /// The runs of this user (`vrflow list --json`): one JSON object each; empty on failure.
  QList<QJsonObject> listRuns(bool all) const;

 Q_SIGNALS:
  /// The process started (a run or an attach).
  void started();
  /// A line of the run's log (stderr), or a line about starting or stopping it.
  void logLine(const QString& line);
  /// The run (or the attached follower) ended; `exitCode` is the run's (from its `end` event
  /// when attached); -1: it could not start.
  void finished(int exitCode);

 private:
  /// Clears what is known of the last run; false while one is followed.
  bool forgetLastRun(bool attaching);
  bool startProcess(const QStringList& args, const QString& workingDirectory);
  void readEvents();
  void readLog();
  void end(int exitCode);
  void learnRunId();

  QString program_;
  QProcess* process_ = nullptr;
  LiveRunModel* live_;
  QString commandLine_, runId_, traceFile_, reportFile_, logDir_;
  QByteArray pendingEvents_, pendingLog_;
  std::optional<RunReport> report_;
  int idLookups_ = 0;  ///< `vrflow list` calls made to find the run's id
  bool attached_ = false;
  bool ended_ = true;
};

}  // namespace vrflow::editor::gui
