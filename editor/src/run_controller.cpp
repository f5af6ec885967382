#include "run_controller.hpp"

#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QRegularExpression>

namespace vrflow::editor::gui {

QString shellCommandLine(const QStringList& words) {
  static const QRegularExpression plain("^[A-Za-z0-9_./=:,+@%-]+$");
  QStringList quoted;
  for (QString word : words) {
    if (!plain.match(word).hasMatch()) word = "'" + word.replace("'", "'\\''") + "'";
    quoted << word;
  }
  return quoted.join(' ');
}

QString RunRequest::workingDirectory() const {
  return outputDir.isEmpty() ? QFileInfo(application).absolutePath()
                             : QFileInfo(outputDir).absoluteFilePath();
}

QString RunRequest::traceFile() const {
  if (!trace) return {};
  return QDir(workingDirectory())
      .filePath(QFileInfo(application).completeBaseName() + ".trace.json");
}

QString RunRequest::reportFile() const {
  return QDir(workingDirectory())
      .filePath(QFileInfo(application).completeBaseName() + ".report.json");
}

QStringList RunRequest::arguments() const {
  QStringList args{launch ? "launch" : "run", QFileInfo(application).absoluteFilePath()};
  if (launch) {
    args << "--backend" << backend;
    if (!hostfile.isEmpty()) args << "--hosts" << QFileInfo(hostfile).absoluteFilePath();
  }
  if (iterations > 0) args << "--iterations" << QString::number(iterations);
  for (const auto& [name, value] : overrides) args << "--set" << name + "=" + value;
  for (const QString& dir : packageDirs) args << "--packages" << dir;
  if (trace) args << "--trace" << traceFile();
  args << "--report" << reportFile() << "--events"
       << "-";
  return args;
}

RunController::RunController(QString program, QObject* parent)
    : QObject(parent), program_(std::move(program)), live_(new LiveRunModel(this)) {}

RunController::~RunController() {
  if (running()) {
    process_->disconnect(this);
    // An attached run goes on without its follower; a started one is stopped with the editor.
    process_->terminate();
    if (!process_->waitForFinished(5000)) process_->kill();
    process_->waitForFinished(2000);
  }
}

bool RunController::running() const {
  return process_ != nullptr && process_->state() != QProcess::NotRunning;
}

bool RunController::forgetLastRun(bool attaching) {
  if (running()) {
    Q_EMIT logLine("A run is going on: stop it first");
    return false;
  }
  attached_ = attaching;
  runId_.clear();
  logDir_.clear();
  traceFile_.clear();
  reportFile_.clear();
  report_.reset();
  return true;
}

bool RunController::start(const RunRequest& request) {
  if (!forgetLastRun(false)) return false;
  traceFile_ = request.traceFile();
  reportFile_ = request.reportFile();
  QFile::remove(reportFile_);  // a report read at the end is this run's
  const QString workingDirectory = request.workingDirectory();
  if (!QDir().mkpath(workingDirectory)) {
    Q_EMIT logLine("Cannot create the output folder " + workingDirectory);
    return false;
  }
  return startProcess(request.arguments(), workingDirectory);
}

bool RunController::attach(const QString& runId) {
  if (!forgetLastRun(true)) return false;
  runId_ = runId;
  for (const QJsonObject& run : listRuns(false)) {
    if (run.value("id").toString().startsWith(runId)) {
      runId_ = run.value("id").toString();
      logDir_ = run.value("log_dir").toString();
    }
  }
  return startProcess({"monitor", runId_, "--follow-events"}, QDir::currentPath());
}

bool RunController::startProcess(const QStringList& args, const QString& workingDirectory) {
  delete process_;
  process_ = new QProcess(this);
  process_->setProcessChannelMode(QProcess::SeparateChannels);
  process_->setWorkingDirectory(workingDirectory);
  connect(process_, &QProcess::readyReadStandardOutput, this, &RunController::readEvents);
  connect(process_, &QProcess::readyReadStandardError, this, &RunController::readLog);
  connect(process_, &QProcess::finished, this,
          [this](int code, QProcess::ExitStatus) { end(code); });
  connect(process_, &QProcess::errorOccurred, this, [this](QProcess::ProcessError error) {
    if (error == QProcess::FailedToStart) {
      Q_EMIT logLine("Cannot start " + program_ + ": " + process_->errorString());
      end(-1);
    }
  });
  pendingEvents_.clear();
  pendingLog_.clear();
  idLookups_ = 0;
  live_->reset();
  ended_ = false;
  commandLine_ = shellCommandLine(QStringList{program_} + args);
  Q_EMIT logLine("$ " + commandLine_ +
                 (attached_ ? QString() : "   (in " + workingDirectory + ")"));
  process_->start(program_, args);
  if (!process_->waitForStarted(10000)) return false;
  Q_EMIT started();
  return true;
}

void RunController::stop() {
  if (!running()) return;
  if (attached_) {
    Q_EMIT logLine("Stopping run " + runId_ + " (vrflow stop)");
    QProcess::startDetached(program_, {"stop", runId_});
  } else {
    Q_EMIT logLine("Stopping the run (SIGTERM)");
    process_->terminate();
  }
}

QList<QJsonObject> RunController::listRuns(bool all) const {
  QProcess list;
  QStringList args{"list", "--json"};
  if (all) args << "--all";
  list.start(program_, args);
  QList<QJsonObject> runs;
  if (!list.waitForFinished(10000)) return runs;
  for (const auto& value : QJsonDocument::fromJson(list.readAllStandardOutput()).array())
    runs.push_back(value.toObject());
  return runs;
}

void RunController::learnRunId() {
  if (!runId_.isEmpty() || process_ == nullptr) return;
  const qint64 pid = process_->processId();
  for (const QJsonObject& run : listRuns(false)) {
    if (run.value("pid").toInteger() == pid) {
      runId_ = run.value("id").toString();
      logDir_ = run.value("log_dir").toString();
    }
  }
}

void RunController::readEvents() {
  pendingEvents_ += process_->readAllStandardOutput();
  for (qsizetype at = 0; (at = pendingEvents_.indexOf('\n')) >= 0;) {
    const QByteArray line = pendingEvents_.left(at);
    pendingEvents_.remove(0, at + 1);
    // The registration exists once the run writes events: its id can be read now.
    if (runId_.isEmpty() && !attached_ && idLookups_ < 3) {
      ++idLookups_;
      learnRunId();
    }
    live_->handleLine(line);
  }
}

void RunController::readLog() {
  pendingLog_ += process_->readAllStandardError();
  for (qsizetype at = 0; (at = pendingLog_.indexOf('\n')) >= 0;) {
    const QString line = QString::fromUtf8(pendingLog_.left(at));
    pendingLog_.remove(0, at + 1);
    if (!line.trimmed().isEmpty()) Q_EMIT logLine(line);
  }
}

void RunController::end(int exitCode) {
  if (ended_) return;
  ended_ = true;
  if (process_ != nullptr) {
    readEvents();
    readLog();
    if (!pendingLog_.trimmed().isEmpty()) Q_EMIT logLine(QString::fromUtf8(pendingLog_));
    pendingLog_.clear();
  }
  if (!reportFile_.isEmpty()) {
    QFile file(reportFile_);
    if (file.open(QIODevice::ReadOnly)) {
      auto parsed = parseRunReport(file.readAll().toStdString());
      if (parsed) report_ = std::move(*parsed);
    }
  }
  // Attached: the follower exits 0; the run's own exit status is in its `end` event.
  if (attached_ && exitCode == 0 && live_->run().phase == LiveRun::Phase::Ended)
    exitCode = live_->run().exitCode;
  Q_EMIT finished(exitCode);
}

}  // namespace vrflow::editor::gui
