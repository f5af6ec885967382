#pragma once

#include <cstdio>
#include <optional>
#include <string>

#include "vrflow/module/module.hpp"

namespace vrflow {

/// Calls module.init() once the ports are declared; when it fails, prints "PROGRAM: why" on
/// stderr and returns false, and the program should exit with status 2 (a module that cannot
/// join its run).
[[nodiscard]] inline bool initOrReport(Module& module, const std::string& program) {
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s: %s\n", program.c_str(), status.error().message.c_str());
    return false;
  }
  return true;
}

/// The ports of an interactor (manifest kind "interactor"): the scene in, its forces out.
struct InteractorPorts {
  const InputPort& objects;  ///< "objects"
  const OutputPort& forces;  ///< "forces"
};

/// The ports of an animator (manifest kind "animator"): force and other events in, the
/// objects it owns out.
struct AnimatorPorts {
  const InputPort& events;    ///< "events"
  const OutputPort& objects;  ///< "objects"
};

/// Declares an interactor's ports and joins the run (initOrReport()); nullopt when it cannot.
[[nodiscard]] inline std::optional<InteractorPorts> startInteractor(Module& module,
                                                                    const std::string& program) {
  const InteractorPorts ports{module.addInput("objects"), module.addOutput("forces")};
  if (!initOrReport(module, program)) return std::nullopt;
  return ports;
}

/// Declares an animator's ports and joins the run (initOrReport()); nullopt when it cannot.
[[nodiscard]] inline std::optional<AnimatorPorts> startAnimator(Module& module,
                                                                const std::string& program) {
  const AnimatorPorts ports{module.addInput("events"), module.addOutput("objects")};
  if (!initOrReport(module, program)) return std::nullopt;
  return ports;
}

}  // namespace vrflow
