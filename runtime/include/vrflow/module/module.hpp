#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "vrflow/base/parameters.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/module/message.hpp"

namespace vrflow {

class Module;

/// What the input and output ports of a module share: the name it declared and, once
/// Module::init() ran, the run's port it stands for.
class Port {
 public:
  const std::string& name() const { return name_; }
  /// True when the application connects something to this port.
  bool connected() const;

 protected:
  Port() = default;

 private:
  friend class Module;
  std::string name_;
  Module* module_ = nullptr;
  int slot_ = -1;
};

/// An input port declared by a module.
class InputPort : public Port {};

/// An output port declared by a module.
class OutputPort : public Port {};

/// A message being written straight into shared memory; hand it to Module::put().
class OutgoingMessage {
 public:
  OutgoingMessage(OutgoingMessage&&) noexcept;
  OutgoingMessage& operator=(OutgoingMessage&&) noexcept;
  ~OutgoingMessage();
  /// The builder: add chunks, user stamps, set the simulation time.
  msg::MessageBuilder& builder();

 private:
  friend class Module;
  struct Impl;
  explicit OutgoingMessage(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// The module side of the runtime: declare ports, then loop on wait(), get(), put().
/// One Module per process; it connects to the run that started the process.
class Module {
 public:
  Module();
  ~Module();
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;

  /// Declares an input port (as named in the package manifest).
  InputPort& addInput(std::string name);
  /// Declares an output port.
  OutputPort& addOutput(std::string name);

  /// Connects to the run (from the environment the runtime set) and checks the declared ports
  /// against the application. On error the module should print it and exit non-zero.
  Status init();

  /// Ends the previous iteration and waits for one message on every connected input port.
  /// False when the module must end (its iteration count, end of input, the run stops, or
  /// every module its outputs reach has ended): leave the loop then. Each true return begins
  /// an iteration, which counts once the module calls wait() again or leaves its loop
  /// (destroys the Module): call wait() only for an iteration you will do
  /// (docs/module-api.md).
  bool wait();

  /// The message received on `port` in this iteration (invalid if the port is unconnected).
  const Message& get(const InputPort& port) const;

  /// Starts a message in shared memory; `sizeHint` bytes are reserved up front.
  OutgoingMessage newMessage(std::size_t sizeHint = 256);
  /// Sends a message on `port`; blocks while the port's buffer is full (backpressure).
  Status put(const OutputPort& port, OutgoingMessage&& message);
  /// Finishes a message without sending it, to send it (or keep it) later by reference.
  Result<Message> seal(OutgoingMessage&& message);
  /// Sends a message held by reference (received, or sealed) without copying its bytes.
  Status put(const OutputPort& port, const Message& message);

  /// This module's id in the application, and the iteration in progress (0-based).
  const std::string& id() const;
  uint64_t iteration() const;
  /// Simulation time and step of this iteration: from the first input message's stamps.
  double simTime() const;
  double timeStep() const;
  /// True once the run asked every module to stop (not set when only this module is asked to
  /// end because nothing needs its outputs: wait() returns false then).
  bool stopRequested() const;

  /// The typed parameters: the application file's values over the manifest's defaults, each of
  /// its declared type (params().getFloat("dt"), getInt, getBool, getString, getVec3). Reading
  /// one the manifest does not declare, or as another type, prints an error naming the module
  /// and the parameter and exits with status 1 (docs/module-api.md).
  const Parameters& params() const;

  /// A new object or resource id, unique in the run and independent of placement.
  uint64_t newId();

  /// Leaves the loop now, as destroying the Module does: the iteration in progress counts, the
  /// run reports "left its loop" and wait() returns false from then on. Messages still held
  /// stay readable until the Module is destroyed (for language bindings, whose objects may
  /// outlive the loop).
  void leave();

  /// What main() should return: 1 if an error was reported (e.g. shared memory exhausted in
  /// put()), else 0. A put() that fails because the run stops is not an error.
  int exitStatus() const;

 private:
  friend class Port;
  struct Impl;
  /// Adds a port named `name` to `ports` (the inputs or the outputs); before init() only.
  template <typename Ports>
  typename Ports::value_type& declarePort(Ports& ports, std::string name);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow
