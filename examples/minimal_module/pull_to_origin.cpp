#include <cstdio>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  vrflow::Module module;
  auto& objects = module.addInput("objects");  // names as in the package manifest
  auto& forces = module.addOutput("forces");
  if (auto status = module.init(); !status) {  // joins the run that started this process
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const double k = module.params().getFloat("stiffness");
  while (module.wait()) {            // false when the run stops
    auto out = module.newMessage();  // written straight into shared memory
    for (const auto chunk : module.get(objects).view()) {
      auto object = chunk.asObject();
      if (!object) continue;
      if (auto p = object->vec3(vrflow::msg::PointParam::kPosition)) {
        out.builder().addForce(object->id(), {{-k * (*p)[0], -k * (*p)[1], -k * (*p)[2]}});
      }
    }
    if (!module.put(forces, std::move(out))) break;
  }
  return module.exitStatus();  // non-zero if put() reported an error
}
