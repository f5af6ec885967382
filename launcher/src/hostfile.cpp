#include <fstream>
#include <set>
#include <sstream>

#include "vrflow/launcher/launch.hpp"

namespace vrflow::launcher {

Result<std::vector<HostEntry>> readHostfile(const std::string& path,
                                            const app::Application& application) {
  std::ifstream in(path);
  if (!in) return makeError(path + ": cannot read the hostfile");
  std::vector<HostEntry> entries;
  std::set<std::string> seen;
  std::string text;
  int line = 0;
  auto fail = [&](const std::string& why) {
    return makeError(path + ":" + std::to_string(line) + ": error: " + why);
  };
  while (std::getline(in, text)) {
    ++line;
    if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    HostEntry entry;
    entry.line = line;
    if (!(words >> entry.host)) continue;
    if (app::findHost(application, entry.host) == nullptr) {
      return fail("no host '" + entry.host + "' in " + application.file);
    }
    if (!seen.insert(entry.host).second) return fail("host '" + entry.host + "' is listed twice");
    std::string word;
    while (words >> word) {
      const auto eq = word.find('=');
      if (eq == std::string::npos) return fail("expected KEY=VALUE, got '" + word + "'");
      const std::string key = word.substr(0, eq), value = word.substr(eq + 1);
      if (key == "address") {
        entry.address = value;
      } else if (key == "user") {
        entry.user = value;
      } else if (key == "ssh-port") {
        try {
          entry.sshPort = std::stoi(value);
        } catch (...) {
          entry.sshPort = -1;
        }
        if (entry.sshPort <= 0 || entry.sshPort > 65535)
          return fail("bad ssh-port '" + value + "'");
      } else if (key == "identity") {
        entry.identity = value;
      } else if (key == "ssh-option") {
        if (value.find('=') == std::string::npos)
          return fail("ssh-option needs KEY=VALUE, got '" + value + "'");
        entry.sshOptions.push_back(value);
      } else if (key == "dir") {
        entry.directory = value;
      } else if (key == "daemon") {
        entry.daemon = value;
      } else if (key == "env") {
        if (value.find('=') == std::string::npos)
          return fail("env needs NAME=VALUE, got '" + value + "'");
        entry.environment.push_back(value);
      } else {
        return fail("unknown key '" + key +
                    "' (allowed: address, user, ssh-port, identity, ssh-option, dir, daemon, env)");
      }
    }
    entries.push_back(entry);
  }
  return entries;
}

}  // namespace vrflow::launcher
