// Hostfiles in two formats: vrflow's (`HOST key=value...`, one line per host of the application)
// and Open MPI's (`MACHINE [slots=N] [max_slots=N]`, the hosts of the application placed on the
// machines' slots in order, as mpirun's by-slot mapping places ranks).
#include <fstream>
#include <set>
#include <sstream>

#include "vrflow/launcher/launch.hpp"

namespace vrflow::launcher {
namespace {

// One line that holds something: its number and its words (the comment cut off).
struct Line {
  int number = 0;
  std::vector<std::string> words;
};

bool isOpenMpiKey(const std::string& key) {
  return key == "slots" || key == "max_slots" || key == "max-slots";
}

std::string keyOf(const std::string& word) {
  return word.substr(0, word.find('='));
}

// A whole number of slots, 1 to 1,000,000, or -1.
int slotCount(const std::string& value) {
  if (value.empty() || value.size() > 7 || value.find_first_not_of("0123456789") != value.npos) {
    return -1;
  }
  const int n = std::stoi(value);
  return n >= 1 && n <= 1'000'000 ? n : -1;
}

// A key of vrflow's format: its name and what it sets (the error text, empty when the value is
// good). The table is the one list of keys: the parser and the "allowed:" message read it.
struct HostKey {
  const char* name;
  std::string (*set)(HostEntry& entry, const std::string& value);
};

std::string needsAssignment(const char* key, const char* what, const std::string& value) {
  return value.find('=') == std::string::npos
             ? std::string(key) + " needs " + what + ", got '" + value + "'"
             : std::string();
}

constexpr HostKey kHostKeys[] = {
    {"address", [](HostEntry& e, const std::string& v) { return e.address = v, std::string(); }},
    {"node", [](HostEntry& e, const std::string& v) { return e.node = v, std::string(); }},
    {"user", [](HostEntry& e, const std::string& v) { return e.user = v, std::string(); }},
    {"ssh-port",
     [](HostEntry& e, const std::string& v) {
       const bool digits =
           !v.empty() && v.size() <= 5 && v.find_first_not_of("0123456789") == v.npos;
       e.sshPort = digits ? std::stoi(v) : -1;
       return e.sshPort <= 0 || e.sshPort > 65535 ? "bad ssh-port '" + v + "'" : std::string();
     }},
    {"identity", [](HostEntry& e, const std::string& v) { return e.identity = v, std::string(); }},
    {"ssh-option",
     [](HostEntry& e, const std::string& v) {
       e.sshOptions.push_back(v);
       return needsAssignment("ssh-option", "KEY=VALUE", v);
     }},
    {"dir", [](HostEntry& e, const std::string& v) { return e.directory = v, std::string(); }},
    {"daemon", [](HostEntry& e, const std::string& v) { return e.daemon = v, std::string(); }},
    {"env",
     [](HostEntry& e, const std::string& v) {
       e.environment.push_back(v);
       return needsAssignment("env", "NAME=VALUE", v);
     }},
};

Result<HostEntry> vrflowLine(const Line& line, const std::string& path) {
  auto fail = [&](const std::string& why) {
    return makeError(path + ":" + std::to_string(line.number) + ": error: " + why);
  };
  HostEntry entry;
  entry.line = line.number;
  entry.host = line.words[0];
  for (std::size_t w = 1; w < line.words.size(); ++w) {
    const std::string& word = line.words[w];
    const auto eq = word.find('=');
    if (eq == std::string::npos) return fail("expected KEY=VALUE, got '" + word + "'");
    const std::string key = word.substr(0, eq), value = word.substr(eq + 1);
    const HostKey* found = nullptr;
    std::string allowed;
    for (const HostKey& k : kHostKeys) {
      if (key == k.name) found = &k;
      allowed += (allowed.empty() ? "" : ", ") + std::string(k.name);
    }
    if (found == nullptr) return fail("unknown key '" + key + "' (allowed: " + allowed + ")");
    if (const std::string error = found->set(entry, value); !error.empty()) return fail(error);
  }
  return entry;
}

// One machine of an Open MPI hostfile.
struct Machine {
  std::string name;
  int slots = 1, maxSlots = 0;  ///< maxSlots 0: no more than `slots`
  int line = 0;
};

Result<Machine> openMpiLine(const Line& line, const std::string& path) {
  auto fail = [&](const std::string& why) {
    return makeError(path + ":" + std::to_string(line.number) + ": error: " + why);
  };
  Machine machine;
  machine.name = line.words[0];
  machine.line = line.number;
  for (std::size_t w = 1; w < line.words.size(); ++w) {
    const std::string& word = line.words[w];
    const auto eq = word.find('=');
    const std::string key = keyOf(word);
    if (eq == std::string::npos || !isOpenMpiKey(key)) {
      return fail("unknown word '" + word +
                  "' in an Open MPI hostfile (allowed: slots=N, max_slots=N)");
    }
    const int n = slotCount(word.substr(eq + 1));
    if (n < 0) return fail("bad " + key + " '" + word.substr(eq + 1) + "' (a whole number >= 1)");
    (key == "slots" ? machine.slots : machine.maxSlots) = n;
  }
  if (machine.maxSlots > 0 && machine.maxSlots < machine.slots) {
    return fail("max_slots=" + std::to_string(machine.maxSlots) +
                " is below slots=" + std::to_string(machine.slots));
  }
  return machine;
}

// The hosts of the application in file order on the machines' slots: each machine's slots=
// first, in file order, then up to its max_slots=.
Result<std::vector<HostEntry>> placeOnSlots(const std::vector<Machine>& machines,
                                            const app::Application& application,
                                            const std::string& path) {
  std::vector<HostEntry> entries;
  auto place = [&](const Machine& m, int count) {
    for (int s = 0; s < count && entries.size() < application.hosts.size(); ++s) {
      HostEntry entry;
      entry.host = application.hosts[entries.size()].id;
      entry.node = m.name;
      entry.line = m.line;
      entries.push_back(entry);
    }
  };
  for (const auto& m : machines) place(m, m.slots);
  for (const auto& m : machines) place(m, m.maxSlots > 0 ? m.maxSlots - m.slots : 0);
  if (entries.size() < application.hosts.size()) {
    return makeError(path + ": error: the Open MPI hostfile has " + std::to_string(entries.size()) +
                     " slot(s) for the " + std::to_string(application.hosts.size()) + " hosts of " +
                     application.file + " (raise slots= or max_slots=)");
  }
  return entries;
}

}  // namespace

Result<std::vector<HostEntry>> readHostfile(const std::string& path,
                                            const app::Application& application) {
  std::ifstream in(path);
  if (!in) return makeError(path + ": cannot read the hostfile");
  std::vector<Line> lines;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    Line line{number, {}};
    for (std::string word; words >> word;) line.words.push_back(word);
    if (!line.words.empty()) lines.push_back(line);
  }
  // The format: Open MPI's when a line has slots= or max_slots=, vrflow's otherwise. A line of
  // the other format than the first line with a key is an error.
  const Line* first = nullptr;
  bool openMpi = false;
  for (const auto& line : lines) {
    for (std::size_t w = 1; w < line.words.size(); ++w) {
      if (line.words[w].find('=') == std::string::npos) continue;  // no key: malformed below
      const bool mpiWord = isOpenMpiKey(keyOf(line.words[w]));
      if (first == nullptr) {
        first = &line;
        openMpi = mpiWord;
      } else if (mpiWord != openMpi) {
        return makeError(path + ":" + std::to_string(line.number) + ": error: '" + line.words[w] +
                         "' mixes the two hostfile formats: line " + std::to_string(first->number) +
                         " makes this " +
                         (openMpi ? "an Open MPI hostfile (MACHINE slots=N)"
                                  : "a vrflow hostfile (HOST key=value)"));
      }
    }
  }
  if (openMpi) {
    std::vector<Machine> machines;
    for (const auto& line : lines) {
      auto machine = openMpiLine(line, path);
      if (!machine) return machine.error();
      machines.push_back(*machine);
    }
    return placeOnSlots(machines, application, path);
  }
  std::vector<HostEntry> entries;
  std::set<std::string> seen;
  for (const auto& line : lines) {
    auto fail = [&](const std::string& why) {
      return makeError(path + ":" + std::to_string(line.number) + ": error: " + why);
    };
    if (app::findHost(application, line.words[0]) == nullptr) {
      return fail("no host '" + line.words[0] + "' in " + application.file +
                  " (an Open MPI hostfile, naming machines, needs slots= on a line)");
    }
    if (!seen.insert(line.words[0]).second) {
      return fail("host '" + line.words[0] + "' is listed twice");
    }
    auto entry = vrflowLine(line, path);
    if (!entry) return entry.error();
    entries.push_back(*entry);
  }
  return entries;
}

}  // namespace vrflow::launcher
