// The live state of a run from its event lines (run_state.hpp).
#include "vrflow/run/run_state.hpp"

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>

namespace vrflow::run {

using nlohmann::json;

struct RunState::Data {
  json state = {{"application", "?"},
                {"file", ""},
                {"hosts", json::array()},
                {"warnings", json::array()},
                {"end", nullptr}};

  // The entry of host `id`; `vrflow run` has one snapshot for all its hosts, without "host".
  json& hostEntry(const std::string& id) {
    json& hosts = state["hosts"];
    for (auto& h : hosts) {
      if (id.empty() || h["host"] == id) {
        if (id.empty() && hosts.size() > 1) h["host"] = "all";
        return h;
      }
    }
    hosts.push_back({{"host", id.empty() ? "all" : id}, {"now", nullptr}, {"before", nullptr}});
    return hosts.back();
  }
};

RunState::RunState() : data_(std::make_unique<Data>()) {}
RunState::~RunState() = default;
RunState::RunState(const RunState& other) : data_(std::make_unique<Data>(*other.data_)) {}
RunState& RunState::operator=(const RunState& other) {
  if (this != &other) data_ = std::make_unique<Data>(*other.data_);
  return *this;
}
RunState::RunState(RunState&&) noexcept = default;
RunState& RunState::operator=(RunState&&) noexcept = default;

RunState RunState::fromJson(const std::string& text) {
  RunState state;
  auto saved = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (saved.is_object() && saved.contains("hosts") && saved["hosts"].is_array()) {
    for (const char* key : {"application", "file", "hosts", "warnings", "end"}) {
      if (saved.contains(key)) state.data_->state[key] = std::move(saved[key]);
    }
  }
  return state;
}

bool RunState::take(const std::string& line) {
  const json event = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (!event.is_object() || !event.contains("event") || !event["event"].is_string()) return false;
  json& state = data_->state;
  const std::string kind = event["event"];
  if (kind == "started") {
    state["application"] = event.value("application", "?");
    state["file"] = event.value("file", "");
    state["hosts"] = json::array();
    for (const auto& h : event.value("hosts", json::array())) {
      state["hosts"].push_back(
          {{"host", h.value("id", "?")}, {"now", nullptr}, {"before", nullptr}});
    }
    return false;
  }
  if (kind == "stats") {
    json& host = data_->hostEntry(event.value("host", ""));
    host["before"] = std::move(host["now"]);
    host["now"] = event;
    return true;
  }
  if (kind == "warning") {
    json& warnings = state["warnings"];
    warnings.push_back(event.value("text", ""));
    if (warnings.size() > kMaxWarnings) warnings.erase(warnings.begin());
    return false;
  }
  if (kind == "end") {
    state["end"] = {{"exit_code", event.value("exit_code", -1)},
                    {"status", event.value("status", "?")},
                    {"error", event.value("error", "")}};
  }
  return false;
}

void RunState::endAs(const std::string& status, const std::string& error) {
  data_->state["end"] = {{"exit_code", -1}, {"status", status}, {"error", error}};
}

std::string RunState::toJson() const {
  return data_->state.dump();
}

bool RunState::ended() const {
  return data_->state["end"].is_object();
}

std::string RunState::endStatus() const {
  return ended() ? data_->state["end"].value("status", "?") : std::string();
}

std::string RunState::endLine() const {
  if (!ended()) return {};
  const json& end = data_->state["end"];
  std::string line = "run ended: " + end.value("status", "?");
  if (end.value("exit_code", -1) >= 0) {
    line += " (exit " + std::to_string(end.value("exit_code", -1)) + ")";
  }
  if (const std::string error = end.value("error", ""); !error.empty()) line += ": " + error;
  return line;
}

namespace {

// The module with the fewest iterations in any host's last snapshot, with that snapshot's host.
struct Slowest {
  const json* module = nullptr;
  const json* host = nullptr;
};

Slowest slowest(const json& state) {
  Slowest found;
  uint64_t fewest = std::numeric_limits<uint64_t>::max();
  for (const auto& host : state["hosts"]) {
    const json& now = host["now"];
    // The modules are iterated in place: the pointer kept must outlive the loop.
    if (!now.is_object() || !now.contains("modules") || !now["modules"].is_array()) continue;
    for (const auto& m : now["modules"]) {
      const uint64_t it = m.value("iterations", uint64_t{0});
      if (it < fewest) {
        fewest = it;
        found = {&m, &host};
      }
    }
  }
  return found;
}

}  // namespace

uint64_t RunState::iterations() const {
  const Slowest s = slowest(data_->state);
  return s.module != nullptr ? s.module->value("iterations", uint64_t{0}) : 0;
}

double RunState::rate() const {
  const Slowest s = slowest(data_->state);
  if (s.module == nullptr || !(*s.host)["before"].is_object()) return 0.0;
  const json& now = (*s.host)["now"];
  const json& before = (*s.host)["before"];
  const std::string id = s.module->value("id", "");
  if (!before.contains("modules") || !before["modules"].is_array()) return 0.0;
  for (const auto& m : before["modules"]) {
    if (m.value("id", "") != id) continue;
    const double seconds =
        static_cast<double>(now.value("t_ns", int64_t{0}) - before.value("t_ns", int64_t{0})) / 1e9;
    const uint64_t done = s.module->value("iterations", uint64_t{0});
    const uint64_t was = std::min(done, m.value("iterations", uint64_t{0}));
    return seconds > 0 ? static_cast<double>(done - was) / seconds : 0.0;
  }
  return 0.0;
}

}  // namespace vrflow::run
