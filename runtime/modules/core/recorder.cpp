// core/recorder: writes what it receives as CSV, one line per chunk (or per empty message):
// iteration,source,source_iteration,sim_time,kind,id,values...
#include <cstdio>
#include <cstring>
#include <fstream>

#include "vrflow/base/echo.hpp"
#include "vrflow/base/file_access.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  if (!initOrReport(module, "vrflow-core-recorder")) return 2;
  const std::string path = module.params().getString("file");
  // A missing folder is created only inside the run's working folder.
  if (auto folder = prepareOutputPath(path); !folder) {
    std::fprintf(stderr, "vrflow-core-recorder: module %s: cannot write %s: %s\n",
                 quotedValue(module.id()).c_str(), quotedValue(path).c_str(),
                 folder.error().message.c_str());
    return 2;
  }
  std::ofstream csv(path);
  if (!csv) {
    std::fprintf(stderr, "vrflow-core-recorder: module %s: cannot write %s\n",
                 quotedValue(module.id()).c_str(), quotedValue(path).c_str());
    return 2;
  }
  csv << "iteration,source,source_iteration,sim_time,kind,id,x,y,z\n";
  csv.precision(17);
  while (module.wait()) {
    const Message& message = module.get(in);
    const auto stamps = message->stamps();
    const auto prefix = std::to_string(module.iteration()) + "," + std::string(stamps.source) +
                        "," + std::to_string(stamps.iteration) + ",";
    if (message->chunkCount() == 0) {
      csv << prefix << stamps.simTime << ",empty,,,,\n";
      continue;
    }
    for (const auto chunk : message.view()) {
      csv << prefix << stamps.simTime << ",";
      if (const auto object = chunk.asObject()) {
        csv << "object," << object->id();
        if (const auto p = object->vec3(msg::PointParam::kPosition);
            p && object->typeId() == msg::pointType().id()) {
          csv << "," << (*p)[0] << "," << (*p)[1] << "," << (*p)[2];
        } else {
          csv << ",,,";
        }
      } else if (const auto resource = chunk.asResource()) {
        uint64_t counter = 0;
        const auto raw = resource->raw();
        if (raw.size() >= 8) std::memcpy(&counter, raw.data(), 8);
        csv << "resource," << resource->id() << "," << counter << "," << raw.size() << ",";
      } else if (const auto event = chunk.asEvent()) {
        csv << "event," << event->id();
        if (const auto f = event->force()) {
          csv << "," << f->force[0] << "," << f->force[1] << "," << f->force[2];
        } else {
          csv << ",,,";
        }
      }
      csv << "\n";
    }
  }
  csv.flush();
  return csv ? 0 : 2;
}
