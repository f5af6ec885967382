// testing/stamps: sends one message per iteration on `out` with user stamps value=`value`
// (int), weight=`weight` (float) and name=`id` (string); with `in` connected, appends the user
// stamps of what it receives to `log`, one line per message: "value=3 weight=1.5 name=a".
// Runs `count` iterations (0: until the run stops).
#include <cstdio>
#include <fstream>
#include <string>
#include <variant>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const int64_t value = module.params().getInt("value");
  const double weight = module.params().getFloat("weight");
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  std::ofstream log;
  if (in.connected()) log.open(module.params().getString("log"), std::ios::app);
  for (uint64_t i = 0; count == 0 || i < count; ++i) {
    if (!module.wait()) break;
    if (in.connected()) {
      std::string line;
      for (const auto stamp : module.get(in)->stamps().user) {
        const auto copy = stamp.toUserStamp();
        line += (line.empty() ? "" : " ") + copy.name + "=";
        if (const auto* v = std::get_if<int64_t>(&copy.value)) line += std::to_string(*v);
        if (const auto* v = std::get_if<double>(&copy.value)) {
          char text[32];
          std::snprintf(text, sizeof text, "%g", *v);
          line += text;
        }
        if (const auto* v = std::get_if<std::string>(&copy.value)) line += *v;
      }
      log << line << std::endl;
    }
    auto message = module.newMessage();
    message.builder().addInt64Stamp("value", value);
    message.builder().addDoubleStamp("weight", weight);
    message.builder().addStringStamp("name", module.id());
    if (!module.put(out, std::move(message))) break;
  }
  return module.exitStatus();
}
