#pragma once

// The run table (a dock): per module and per connection of the expanded network, the live
// figures while a run goes and the report's totals after it; every column sorts.

#include <QWidget>

#include "live_run.hpp"
#include "vrflow/editor/analysis.hpp"

class QTableWidget;
class QTabWidget;

namespace vrflow::editor::gui {

class RunTable : public QWidget {
  Q_OBJECT

 public:
  explicit RunTable(QWidget* parent = nullptr);
  /// The figures of a run going on (or ended, before its report is read).
  void showLive(const LiveRun& run);
  /// The report's totals and averages over the run's wall time; `run` adds hosts, CPU and
  /// memory where it knows them.
  void showReport(const RunReport& report, const LiveRun& run);
  QTableWidget* modules() const { return modules_; }
  QTableWidget* connections() const { return connections_; }
  QTableWidget* links() const { return links_; }

 private:
  QTabWidget* tabs_;
  QTableWidget* modules_;
  QTableWidget* connections_;
  QTableWidget* links_;
};

}  // namespace vrflow::editor::gui
