#include "run_table.hpp"

#include <QHeaderView>
#include <QTabWidget>
#include <QTableWidget>
#include <QVBoxLayout>
#include <variant>

#include "qt_text.hpp"

namespace vrflow::editor::gui {

namespace {

// A cell that sorts by its number, not by its text.
class NumberItem : public QTableWidgetItem {
 public:
  NumberItem(double value, int decimals) : QTableWidgetItem(QString::number(value, 'f', decimals)) {
    setData(Qt::UserRole, value);
    setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
  }
  bool operator<(const QTableWidgetItem& other) const override {
    return data(Qt::UserRole).toDouble() < other.data(Qt::UserRole).toDouble();
  }
};

using Cell = std::variant<QString, std::pair<double, int>>;  // text, or a number and decimals

QTableWidget* makeTable(const QStringList& headers) {
  auto* table = new QTableWidget(0, static_cast<int>(headers.size()));
  table->setHorizontalHeaderLabels(headers);
  table->verticalHeader()->hide();
  table->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table->setSelectionBehavior(QAbstractItemView::SelectRows);
  table->horizontalHeader()->setStretchLastSection(true);
  table->setSortingEnabled(true);
  return table;
}

// Replaces the rows, keeping the user's sort.
void fill(QTableWidget* table, const std::vector<std::vector<Cell>>& rows) {
  table->setSortingEnabled(false);
  table->setRowCount(static_cast<int>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      QTableWidgetItem* item = nullptr;
      if (const auto* text = std::get_if<QString>(&rows[r][c])) {
        item = new QTableWidgetItem(*text);
      } else {
        const auto& [value, decimals] = std::get<std::pair<double, int>>(rows[r][c]);
        item = new NumberItem(value, decimals);
      }
      table->setItem(static_cast<int>(r), static_cast<int>(c), item);
    }
  }
  table->setSortingEnabled(true);
}

Cell number(double value, int decimals = 0) {
  return std::pair{value, decimals};
}

constexpr double kMiB = 1048576.0;

// The links' rows: their rates now, or their averages over `wall` seconds when it is positive.
std::vector<std::vector<Cell>> linkRows(const LiveRun& run, double wall) {
  std::vector<std::vector<Cell>> rows;
  for (const auto& l : run.links) {
    const double messages = static_cast<double>(l.messages),
                 mib = static_cast<double>(l.bytes) / kMiB;
    rows.push_back(
        {qtText(l.from), qtText(l.to), number(wall > 0 ? messages / wall : l.messagesPerSecond),
         number(wall > 0 ? mib / wall : l.mibPerSecond, 2), number(messages), number(mib, 2)});
  }
  return rows;
}

}  // namespace

RunTable::RunTable(QWidget* parent)
    : QWidget(parent),
      tabs_(new QTabWidget),
      modules_(makeTable({"Module", "Host", "State", "Iterations", "it/s", "Wait %", "CPU (cores)",
                          "Memory (MiB)", "Exit"})),
      connections_(makeTable(
          {"From", "To", "Queue", "Fill %", "msg/s", "MiB/s", "Messages", "MiB", "Dropped"})),
      links_(makeTable({"From host", "To host", "msg/s", "MiB/s", "Messages", "MiB"})) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  tabs_->addTab(modules_, "Modules");
  tabs_->addTab(connections_, "Connections");
  tabs_->addTab(links_, "Links");
  layout->addWidget(tabs_);
}

void RunTable::showLive(const LiveRun& run) {
  std::vector<std::vector<Cell>> rows;
  for (const auto& [id, m] : run.modules) {
    const std::string exit = !m.failure.empty() ? m.failure : m.exit;
    rows.push_back({qtText(id), qtText(m.host), qtText(m.state),
                    number(static_cast<double>(m.iterations)), number(m.rate, 1),
                    number(m.waitShare * 100), number(m.cpu, 2), number(m.rssMiB, 1),
                    qtText(exit)});
  }
  fill(modules_, rows);
  rows.clear();
  for (const auto& c : run.connections) {
    rows.push_back({qtText(c.from), qtText(c.to),
                    c.capacity > 0 ? QString("%1/%2").arg(c.length).arg(c.capacity)
                                   : QString("%1/\u221e").arg(c.length),
                    number(c.fill * 100), number(c.messagesPerSecond), number(c.mibPerSecond, 2),
                    number(static_cast<double>(c.messages)),
                    number(static_cast<double>(c.bytes) / kMiB, 2),
                    number(static_cast<double>(c.dropped))});
  }
  fill(connections_, rows);
  fill(links_, linkRows(run, 0));
}

void RunTable::showReport(const RunReport& report, const LiveRun& run) {
  const double wall = report.wallSeconds > 0 ? report.wallSeconds : 0;
  const auto average = [wall](double total) { return wall > 0 ? total / wall : 0.0; };
  std::vector<std::vector<Cell>> rows;
  for (const auto& [id, m] : report.modules) {
    const auto live = run.modules.find(id);
    const bool known = live != run.modules.end();
    std::string exit = m.exit;
    if (id == report.failedModule && !report.error.empty()) exit = report.error;
    rows.push_back({qtText(id), known ? qtText(live->second.host) : QString(),
                    id == report.failedModule ? QString("failed") : QString("ended"),
                    number(static_cast<double>(m.iterations)),
                    number(average(static_cast<double>(m.iterations)), 1),
                    number(known ? live->second.waitShare * 100 : 0),
                    number(known ? live->second.cpu : 0, 2),
                    number(known ? live->second.rssMiB : 0, 1), qtText(exit)});
  }
  fill(modules_, rows);
  rows.clear();
  for (const auto& c : report.connections) {
    rows.push_back({qtText(c.from), qtText(c.to), QString(), number(0),
                    number(average(static_cast<double>(c.messages))),
                    number(average(static_cast<double>(c.bytes)) / kMiB, 2),
                    number(static_cast<double>(c.messages)),
                    number(static_cast<double>(c.bytes) / kMiB, 2),
                    number(static_cast<double>(c.dropped))});
  }
  fill(connections_, rows);
  fill(links_, linkRows(run, wall));
}

}  // namespace vrflow::editor::gui
