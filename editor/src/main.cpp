// vrflow-editor [APP.xml] [--screenshot OUT.png [--run N | --launch BACKEND [--hosts FILE]
//               [--iterations N]] [--select ID]] [--packages DIR]...
#include <QApplication>
#include <QCommandLineParser>
#include <QEventLoop>
#include <cstdio>
#include <string>

#include "main_window.hpp"
#include "vrflow/base/version.hpp"

int main(int argc, char** argv) {
  QApplication application(argc, argv);
  QApplication::setApplicationName("vrflow-editor");
  QApplication::setOrganizationName("vrflow");
  // `vrflow-editor --version` alone is answered before main(), without a display
  // (vrflow/base/version.hpp); -v and --version among other options come here.
  QApplication::setApplicationVersion(
      QString::fromStdString("(vrflow " + std::string(vrflow::versionText()) + ")"));
  QCommandLineParser parser;
  parser.setApplicationDescription(
      "vrflow node editor: lay out, validate, save and run applications");
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument("APP.xml", "Application file to open");
  QCommandLineOption screenshot("screenshot", "Render the window to OUT.png and exit", "OUT.png");
  QCommandLineOption packages("packages", "Extra folder of node packages (repeatable)", "DIR");
  QCommandLineOption runFirst("run", "With --screenshot: run the application N iterations first",
                              "N");
  parser.addOption(screenshot);
  QCommandLineOption select(
      "select", "With --screenshot: select this node first (its properties show)", "ID");
  QCommandLineOption launchFirst(
      "launch",
      "With --screenshot: launch on the file's hosts first (vrflow launch --backend BACKEND: "
      "local, ssh, mpirun, slurm), wait for the end, and exit with the launch's exit status",
      "BACKEND");
  QCommandLineOption hostfile("hosts", "With --launch: the hostfile (vrflow launch --hosts)",
                              "FILE");
  QCommandLineOption iterations("iterations", "With --launch: stop after N iterations", "N");
  parser.addOption(runFirst);
  parser.addOption(launchFirst);
  parser.addOption(hostfile);
  parser.addOption(iterations);
  parser.addOption(select);
  parser.addOption(packages);
  parser.process(application);

  vrflow::editor::gui::EditorOptions options;
  for (const QString& dir : parser.values(packages))
    options.packageDirs.push_back(dir.toStdString());
  // A screenshot must never wait on a dialog: messages go to stderr.
  struct StderrReporter : vrflow::editor::gui::Reporter {
    void error(QWidget*, const QString& title, const QString& text) override {
      std::fprintf(stderr, "vrflow-editor: %s: %s\n", qPrintable(title), qPrintable(text));
    }
    void warning(QWidget*, const QString& title, const QString& text) override {
      std::fprintf(stderr, "vrflow-editor: warning: %s: %s\n", qPrintable(title), qPrintable(text));
    }
    Choice askToSave(QWidget*, const QString&) override { return Choice::Discard; }
  } stderrReporter;
  const bool shooting = parser.isSet(screenshot);
  if (shooting) {
    options.reporter = &stderrReporter;
    options.rememberRecent = false;  // a picture is not a use of the file
  }

  vrflow::editor::gui::MainWindow window(options);
  window.show();
  const QStringList files = parser.positionalArguments();
  bool opened = true;
  if (!files.isEmpty()) opened = window.openFile(files.front());
  if (!shooting) return application.exec();
  if (!opened) return 1;
  int exitCode = 0;
  if (parser.isSet(runFirst) || parser.isSet(launchFirst)) {
    QEventLoop loop;
    QObject::connect(&window, &vrflow::editor::gui::MainWindow::runFinished, &loop, [&](int code) {
      exitCode = code;
      loop.quit();
    });
    if (parser.isSet(launchFirst)) {
      // As the Run/Launch dialog would start it, with the command line's choices only (not
      // the user's remembered ones: a script gives the same run anywhere).
      vrflow::editor::gui::RunRequest request;
      request.launch = true;
      request.packageDirs = parser.values(packages);
      request.backend = parser.value(launchFirst);
      request.hostfile = parser.value(hostfile);
      request.iterations = parser.value(iterations).toInt();
      if (!window.startRun(request)) return 1;
    } else {
      window.runApplication(parser.value(runFirst).toInt());
    }
    if (window.running()) loop.exec();
  }
  if (parser.isSet(select)) window.canvas()->selectOnly({parser.value(select).toStdString()});
  QApplication::processEvents();
  window.canvas()->fitAll();
  if (!window.screenshot(parser.value(screenshot))) {
    std::fprintf(stderr, "vrflow-editor: cannot write %s\n", qPrintable(parser.value(screenshot)));
    return 1;
  }
  // --launch exits as the launch did; --run keeps its old meaning (the picture was written).
  return parser.isSet(launchFirst) ? exitCode : 0;
}
