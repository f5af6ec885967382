#include "run_console.hpp"

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>

namespace vrflow::editor::gui {

RunConsole::RunConsole(QObject* parent) : QObject(parent) {}

RunConsole::~RunConsole() {
  if (running()) {
    process_->disconnect(this);
    process_->terminate();
    if (!process_->waitForFinished(5000)) process_->kill();
    process_->waitForFinished(2000);
  }
}

bool RunConsole::running() const {
  return process_ != nullptr && process_->state() != QProcess::NotRunning;
}

void RunConsole::start(const QString& program, const QString& application,
                       const QStringList& extra) {
  if (running()) return;
  dir_ = std::make_unique<QTemporaryDir>();
  QStringList args{"run", application, "--report", dir_->filePath("report.json"), "--events", "-"};
  args << extra;
  delete process_;
  process_ = new QProcess(this);
  process_->setProcessChannelMode(QProcess::SeparateChannels);
  connect(process_, &QProcess::readyReadStandardOutput, this, &RunConsole::readEvents);
  connect(process_, &QProcess::readyReadStandardError, this, &RunConsole::readLog);
  connect(process_, &QProcess::finished, this,
          [this](int code, QProcess::ExitStatus) { end(code); });
  connect(process_, &QProcess::errorOccurred, this, [this, program](QProcess::ProcessError error) {
    if (error == QProcess::FailedToStart) {
      Q_EMIT logLine("Cannot start " + program + ": " + process_->errorString());
      end(-1);
    }
  });
  pendingEvents_.clear();
  pendingLog_.clear();
  liveRates_.clear();
  lastIterations_.clear();
  lastStatsTime_ = -1;
  report_.reset();
  ended_ = false;
  commandLine_ = program + " " + args.join(' ');
  clock_.start();
  process_->start(program, args);
}

void RunConsole::stop() {
  if (running()) process_->terminate();
}

void RunConsole::readEvents() {
  pendingEvents_ += process_->readAllStandardOutput();
  for (qsizetype end = 0; (end = pendingEvents_.indexOf('\n')) >= 0;) {
    const QByteArray line = pendingEvents_.left(end);
    pendingEvents_.remove(0, end + 1);
    handleEvent(line);
  }
}

void RunConsole::readLog() {
  pendingLog_ += process_->readAllStandardError();
  for (qsizetype end = 0; (end = pendingLog_.indexOf('\n')) >= 0;) {
    const QString line = QString::fromUtf8(pendingLog_.left(end));
    pendingLog_.remove(0, end + 1);
    if (!line.trimmed().isEmpty()) Q_EMIT logLine(line);
  }
}

void RunConsole::handleEvent(const QByteArray& line) {
  Q_EMIT eventLine(line);
  const QJsonObject event = QJsonDocument::fromJson(line).object();
  if (event.value("event").toString() != "stats") return;
  // Rates from two successive snapshots of the modules' iteration counters.
  const double time = event.value("time").toDouble();
  std::map<std::string, double> iterations, rates;
  for (const auto& value : event.value("modules").toArray()) {
    const QJsonObject module = value.toObject();
    const std::string id = module.value("id").toString().toStdString();
    iterations[id] = module.value("iterations").toDouble();
    const auto before = lastIterations_.find(id);
    if (lastStatsTime_ >= 0 && time > lastStatsTime_ && before != lastIterations_.end()) {
      rates[id] = (iterations[id] - before->second) / (time - lastStatsTime_);
    }
  }
  lastIterations_ = std::move(iterations);
  lastStatsTime_ = time;
  if (rates.empty()) return;
  liveRates_ = std::move(rates);
  Q_EMIT liveRatesUpdated();
}

void RunConsole::end(int exitCode) {
  if (ended_) return;
  ended_ = true;
  if (process_ != nullptr) {
    readEvents();
    readLog();
    if (!pendingLog_.trimmed().isEmpty()) Q_EMIT logLine(QString::fromUtf8(pendingLog_));
    pendingLog_.clear();
  }
  QFile file(dir_ ? dir_->filePath("report.json") : QString());
  if (dir_ && file.open(QIODevice::ReadOnly)) {
    auto parsed = parseRunReport(file.readAll().toStdString());
    if (parsed) report_ = std::move(*parsed);
  }
  Q_EMIT finished(exitCode);
}

}  // namespace vrflow::editor::gui
