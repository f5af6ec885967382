// routing/tile-viewer: a viewer of one tile of a display wall. Each iteration it reads the
// objects it is sent, then publishes its volume of interest on `interest` (a message with the
// string user stamp `interest`: "minx miny minz maxx maxy maxz", the `box` parameter, or `box2`
// from iteration `move-at` on). With `file`, it writes one CSV line per chunk received:
// iteration,kind,id,op,mask,x,ref (objects: op add/update/delete, parameter mask in hex, the
// x of the position or empty, the shape id or empty; resources: a mesh's vertex count as the
// mask and its first vertex's x as x).
#include <cstdio>
#include <fstream>
#include <string>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& objects = module.addInput("objects");
  auto& interest = module.addOutput("interest");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "routing-tile-viewer: %s\n", status.error().message.c_str());
    return 2;
  }
  const std::string box = module.params().getString("box");
  const std::string box2 = module.params().getString("box2");
  const auto moveAt = static_cast<uint64_t>(module.params().getInt("move-at"));
  std::ofstream log;
  if (const auto path = module.params().getString("file"); !path.empty()) {
    log.open(path);
    log << "iteration,kind,id,op,mask,x,ref\n";
    log.precision(17);
  }
  while (module.wait()) {
    const auto it = module.iteration();
    const Message& received = module.get(objects);
    if (log.is_open() && received.valid()) {
      for (const auto chunk : received.view()) {
        log << it << ",";
        if (const auto object = chunk.asObject()) {
          const char* op = object->op() == msg::ObjectOp::Add      ? "add"
                           : object->op() == msg::ObjectOp::Update ? "update"
                                                                   : "delete";
          char mask[32];
          std::snprintf(mask, sizeof mask, "%llx", static_cast<unsigned long long>(object->mask()));
          log << "object," << chunk.id() << "," << op << "," << mask << ",";
          if (const auto p = object->vec3(msg::RigidParam::kPosition)) log << (*p)[0];
          log << ",";
          if (const auto shape = object->idParam(msg::RigidParam::kShape)) log << *shape;
        } else if (const auto resource = chunk.asResource()) {
          // A mesh: its vertex count as the mask, its first vertex's x as x.
          log << "resource," << chunk.id() << ",,";
          const auto mesh = resource->mesh();
          if (mesh) log << mesh->vertexCount();
          log << ",";
          if (mesh && mesh->vertexCount() > 0) log << mesh->vertex(0)[0];
          log << ",";
        } else {
          log << "event," << chunk.id() << ",,,,";
        }
        log << "\n";
      }
      log.flush();
    }
    auto out = module.newMessage();
    const bool moved = !box2.empty() && it >= moveAt;
    out.builder().addStringStamp("interest", moved ? box2 : box);
    if (!module.put(interest, std::move(out))) break;
  }
  return module.exitStatus();
}
