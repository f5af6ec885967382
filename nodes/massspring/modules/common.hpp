#pragma once

// Helpers shared by the mass-spring modules: parameter parsing with clear errors, sending
// per-node forces as "massspring node forces" events, and the loop of the interactors.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/events.hpp"
#include "vrflow/massspring/objects.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace vrflow::massspring::modules {

/// Reads `count` numbers from a parameter, or nullopt when the text is not exactly that.
inline std::optional<std::vector<double>> numbers(const std::string& text, std::size_t count) {
  std::istringstream in(text);
  std::vector<double> values;
  for (std::string word; in >> word;) {
    char* end = nullptr;
    const double v = std::strtod(word.c_str(), &end);
    if (!end || *end != '\0' || !std::isfinite(v)) return std::nullopt;
    values.push_back(v);
  }
  if (values.size() != count) return std::nullopt;
  return values;
}

/// The module's typed parameters (Module::params()), with the first problem in their values
/// kept for the module to report.
class Params {
 public:
  Params(const Module& module, std::string program)
      : values_(module.params()), program_(std::move(program)) {}

  double number(const char* name) const { return values_.getFloat(name); }
  int integer(const char* name) const { return static_cast<int>(values_.getInt(name)); }
  bool flag(const char* name) const { return values_.getBool(name); }
  msg::Vec3 vec3(const char* name) const { return values_.getVec3(name); }
  std::string text(const char* name) const { return values_.getString(name); }
  /// A string parameter holding `count` numbers (an orientation's quaternion).
  std::vector<double> numbersIn(const char* name, std::size_t count) {
    const std::string value = text(name);
    const auto v = numbers(value, count);
    if (!v) {
      fail(std::string("parameter '") + name + "' = '" + value + "' must be " +
           std::to_string(count) + " finite numbers");
      return std::vector<double>(count, 0.0);
    }
    return *v;
  }

  void fail(std::string message) {
    if (error_.empty()) error_ = std::move(message);
  }
  /// Prints the first error and returns true when there was one.
  bool report() const {
    if (error_.empty()) return false;
    std::fprintf(stderr, "%s: %s\n", program_.c_str(), error_.c_str());
    return true;
  }

 private:
  const Parameters& values_;
  std::string program_;
  std::string error_;
};

/// Adds one node-forces event per net with a non-zero force (nets in id order).
inline void addNodeForces(msg::MessageBuilder& builder,
                          const std::map<std::uint64_t, std::vector<double>>& forces) {
  for (const auto& [id, dense] : forces) {
    const auto sparse = sparseForces(dense);
    if (sparse.empty()) continue;
    const auto payload = encodeNodeForces(sparse);
    builder.addEvent(id, kNodeForcesEvent, payload);
  }
}

/// Prints a problem with received data once per distinct message (a module keeps running).
class Warnings {
 public:
  explicit Warnings(std::string program) : program_(std::move(program)) {}
  void warn(const std::string& message) {
    if (last_ == message) return;
    last_ = message;
    std::fprintf(stderr, "%s: warning: %s\n", program_.c_str(), message.c_str());
  }

 private:
  std::string program_;
  std::string last_;
};

/// A message holding one node-forces event per net (addNodeForces), with `extraBytes` reserved
/// for what the caller adds after them.
inline OutgoingMessage nodeForcesMessage(Module& module,
                                         const std::map<std::uint64_t, std::vector<double>>& forces,
                                         std::size_t extraBytes = 0) {
  std::size_t nodes = 0;
  for (const auto& [id, f] : forces) nodes += f.size() / 3;
  auto out = module.newMessage(128 + nodes * 40 + extraBytes);
  addNodeForces(out.builder(), forces);
  return out;
}

/// The loop of an interactor: each iteration brings its copy of the scene up to date from the
/// objects port (a message it cannot apply is warned about, and the module goes on) and puts
/// the message `forcesOf(scene)` builds on the forces port. Returns the module's exit status.
template <typename ForcesOf>
int runInteractor(Module& module, const InteractorPorts& ports, const std::string& program,
                  ForcesOf forcesOf) {
  SceneCopy scene;
  Warnings warnings(program);
  while (module.wait()) {
    if (const Message& received = module.get(ports.objects); received.valid()) {
      if (auto status = scene.apply(received.view()); !status)
        warnings.warn(status.error().message);
    }
    if (!module.put(ports.forces, forcesOf(std::as_const(scene)))) break;
  }
  return module.exitStatus();
}

/// The whole main of a contact interactor (collision, rigid): starts the module, reads the
/// contact parameters (thickness, beta, dt, spring-mass-weight, and `gravity` where `withGravity`;
/// dt is the fallback time step when the run has none), validates them (an error names the
/// parameter) and runs the interactor loop, where `forcesOf(scene, contact, &memory)` builds each
/// forces message. Returns the exit status.
template <typename ForcesOf>
int runContactInteractor(const char* program, ForcesOf forcesOf, bool withGravity = false) {
  Module module;
  const auto ports = startInteractor(module, program);
  if (!ports) return 2;
  Params params(module, program);
  ContactParams contact;
  contact.thickness = params.number("thickness");
  contact.beta = params.number("beta");
  const double fallbackDt = params.number("dt");
  contact.dt = fallbackDt;
  contact.springMassWeight = params.number("spring-mass-weight");
  if (withGravity) {
    contact.gravity = params.vec3("gravity");
    if (!std::all_of(contact.gravity.begin(), contact.gravity.end(),
                     [](double g) { return std::isfinite(g); }))
      params.fail("parameter 'gravity' must be 3 finite numbers (m/s^2)");
  }
  if (auto status = validateContactParams(contact); !status) params.fail(status.error().message);
  if (params.report()) return 2;
  ContactMemory memory;
  return runInteractor(module, *ports, program, [&](const SceneCopy& scene) {
    contact.dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    return forcesOf(module, scene, std::as_const(contact), &memory);
  });
}

}  // namespace vrflow::massspring::modules
