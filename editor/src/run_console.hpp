#pragma once

#include <QElapsedTimer>
#include <QObject>
#include <QProcess>
#include <QString>
#include <QStringList>
#include <QTemporaryDir>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "vrflow/editor/analysis.hpp"

namespace vrflow::editor::gui {

/// One `vrflow run` started by the editor: a QProcess whose standard output is the run's event
/// stream (`--events -`, docs/events.md) and whose stderr is its log. It turns the stream's
/// statistics into live iterations/s per module and reads the run report when the run ends.
class RunConsole : public QObject {
  Q_OBJECT

 public:
  explicit RunConsole(QObject* parent = nullptr);
  ~RunConsole() override;

  /// Starts `program run APPLICATION --report ... --events - EXTRA...`; nothing while a run
  /// goes on.
  void start(const QString& program, const QString& application, const QStringList& extra);
  /// Asks the run to stop (SIGTERM: it stops every module, writes its report, exits 130).
  void stop();
  bool running() const;
  /// Iterations/s per module, from the last two statistics of the run (empty before).
  const std::map<std::string, double>& liveRates() const { return liveRates_; }
  /// The report of the last run that ended (none if it wrote none).
  const std::optional<RunReport>& report() const { return report_; }
  /// Seconds since the run started.
  qint64 elapsedSeconds() const { return clock_.elapsed() / 1000; }
  /// The command line of the run, for the log.
  QString commandLine() const { return commandLine_; }

 Q_SIGNALS:
  /// A line the run printed on stderr (its log), or a line about starting it.
  void logLine(const QString& line);
  /// liveRates() changed.
  void liveRatesUpdated();
  /// One line of the run's event stream (helper B: fed to the window's LiveRunModel).
  void eventLine(const QByteArray& line);
  /// The run is over; report() holds its report. -1: it could not start.
  void finished(int exitCode);

 private:
  void readEvents();
  void readLog();
  void handleEvent(const QByteArray& line);
  void end(int exitCode);

  QProcess* process_ = nullptr;
  std::unique_ptr<QTemporaryDir> dir_;
  QElapsedTimer clock_;
  QString commandLine_;
  QByteArray pendingEvents_, pendingLog_;
  std::map<std::string, double> liveRates_;
  /// The previous statistics: when (the stream's seconds) and each module's iterations.
  double lastStatsTime_ = -1;
  std::map<std::string, double> lastIterations_;
  std::optional<RunReport> report_;
  bool ended_ = false;
};

}  // namespace vrflow::editor::gui
