#include "vrflow/module/module.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <new>
#include <optional>
#include <vector>

#include "vrflow/base/assert.hpp"
#include "vrflow/ipc/control.hpp"
#include "vrflow/ipc/join_contract.hpp"
#include "vrflow/ipc/module_slot_user.hpp"
#include "vrflow/ipc/ring.hpp"
#include "vrflow/ipc/shm_byte_sink.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow {
namespace {

uint64_t nowNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

uint64_t wallNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count());
}

// A module that reads a parameter its manifest does not declare (or as another type) has a bug
// the run cannot work around: say so and leave with a non-zero status.
void exitOnParameterError(const Error& error) {
  std::fprintf(stderr, "%s\n", error.message.c_str());
  std::fflush(nullptr);
  std::_Exit(1);
}

constexpr int64_t kPollNs = 200'000'000;  // re-check the stop flag at least this often

// The slot of this process's module, marked when operator new finds no memory (the runtime
// then names its memory limit as the cause of the module's end).
std::atomic<ipc::ModuleSlotUser*> slotToMarkOutOfMemory{nullptr};

void markOutOfMemory() {
  if (auto* slot = slotToMarkOutOfMemory.load()) slot->markOutOfMemory();
  std::set_new_handler(nullptr);  // operator new now throws std::bad_alloc
}

}  // namespace

struct OutgoingMessage::Impl {
  Impl(ipc::Segment& segment, std::size_t hint) : sink(segment, hint), builder(sink) {}
  ipc::ShmByteSink sink;
  msg::MessageBuilder builder;
};

OutgoingMessage::OutgoingMessage(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OutgoingMessage::OutgoingMessage(OutgoingMessage&&) noexcept = default;
OutgoingMessage& OutgoingMessage::operator=(OutgoingMessage&&) noexcept = default;
OutgoingMessage::~OutgoingMessage() = default;
msg::MessageBuilder& OutgoingMessage::builder() {
  return impl_->builder;
}

struct Module::Impl {
  ipc::Segment segment;
  ipc::ModuleSlotUser slot;
  std::optional<msg::IdSource> ids;  // this module's ids, from init(): its prefix, a counter
  std::string id;
  std::deque<InputPort> inputs;
  std::deque<OutputPort> outputs;
  std::vector<Message> current;  // by port slot index
  std::vector<int> waitOrder;    // connected input slots, in port order
  int endItSlot = -1;
  bool finished = false;
  bool initialized = false;
  bool failed = false;
  bool inIteration = false;  // wait() returned true and the module has not called it again
  uint64_t iteration = 0;
  uint64_t iterationStartNs = 0;
  ipc::TraceRing* trace = nullptr;  ///< set when the run is traced
  void traceEvent(ipc::TraceKind kind, uint64_t begin, uint64_t end, uint64_t sourceHash = 0,
                  uint64_t sourceIteration = 0) {
    if (trace == nullptr) return;
    trace->record({begin, end, iteration, sourceIteration, static_cast<uint32_t>(kind),
                   static_cast<uint32_t>(sourceHash)});
  }
  using TraceEvent = ipc::TraceEvent;
  TraceEvent sentEvent(uint64_t handle) const {
    const uint64_t now = nowNs();
    TraceEvent event{now,
                     now,
                     iteration,
                     iteration,
                     static_cast<uint32_t>(ipc::TraceKind::Sent),
                     msg::fnv1a32(id)};
    if (auto view = msg::MessageView::parse(segment.bytes(handle))) {
      event.sourceHash = msg::fnv1a32(view->stamps().source);
      event.sourceIteration = view->stamps().iteration;
    }
    return event;
  }
  double simTime = 0.0;
  double timeStep = 0.0;
  Parameters params{"module (not joined to a run yet)"};

  bool stopRequested() const { return slot.stopRequested(); }
  void setState(ipc::ModuleState state, int port = -1) { slot.setState(state, port); }
  // Pushes a handle on an output ring, sleeping while it is full. False if the run stops.
  bool push(int portSlot, uint64_t handle) {
    if (!slot.portConnected(portSlot)) {
      segment.release(handle);  // nothing listens: dropped here, as the output filter would
      return true;
    }
    // Traced: the send time is taken before the push (a receiver may wake at once), with the
    // stamps that name the message, which differ from this module's when it forwards one.
    TraceEvent sent{};
    if (trace != nullptr) sent = sentEvent(handle);
    if (!slot.put(portSlot, handle, kPollNs)) return false;
    if (trace != nullptr) trace->record(sent);
    setState(ipc::ModuleState::Computing);
    return true;
  }
  // Closes the iteration in progress (at the next wait(), or as the module leaves its loop).
  void endIteration() {
    const uint64_t now = nowNs();
    const uint64_t took = now - iterationStartNs;
    slot.addCompute(took);
    traceEvent(ipc::TraceKind::Compute, iterationStartNs, now);
    if (!slot.endItAfterWait()) sendEndIt();
    inIteration = false;
    ++iteration;
    slot.setIterations(iteration);
  }
  // The endIt signal of the iteration in progress, when the port is connected.
  void sendEndIt() {
    if (endItSlot >= 0 && slot.portConnected(endItSlot)) {
      ipc::ShmByteSink sink(segment, 64);
      msg::MessageBuilder builder(sink);
      builder.setSource(id);
      builder.setIteration(iteration);
      builder.setSimTime(simTime);
      builder.setTimeStep(timeStep);
      builder.setSendTimeNs(wallNs());
      builder.setStampsOnly(true);
      const std::size_t used = builder.finish();
      if (used == 0 || sink.data() == nullptr) {
        fail("shared memory exhausted while sending endIt");
      } else {
        const uint64_t handle = sink.take(used);
        if (!push(endItSlot, handle)) segment.release(handle);
      }
    }
  }
  // Reports an error once; the module's exit status becomes non-zero.
  void fail(const std::string& message) {
    if (!failed) std::fprintf(stderr, "vrflow: module '%s': %s\n", id.c_str(), message.c_str());
    failed = true;
  }
  void finish(ipc::EndCause cause) {
    if (finished) return;
    finished = true;
    current.clear();
    slot.finish(cause);
  }
};

bool Port::connected() const {
  return module_->impl_->slot.joined() && slot_ >= 0 && module_->impl_->slot.portConnected(slot_);
}

Module::Module() : impl_(std::make_unique<Impl>()) {
  impl_->params.setFailureHandler(&exitOnParameterError);  // also before init(): a bug to report
}

Module::~Module() {
  leave();
}

void Module::leave() {
  if (!impl_->slot.joined() || impl_->finished) return;
  // Leaving the loop ends the iteration in progress: it counts (docs/module-api.md).
  if (impl_->inIteration) impl_->endIteration();
  impl_->finish(ipc::EndCause::LeftLoop);
}

template <typename Ports>
typename Ports::value_type& Module::declarePort(Ports& ports, std::string name) {
  VRFLOW_ASSERT(!impl_->initialized, "declare ports before init()");
  auto& port = ports.emplace_back();
  port.name_ = std::move(name);
  port.module_ = this;
  return port;
}

InputPort& Module::addInput(std::string name) {
  return declarePort(impl_->inputs, std::move(name));
}

OutputPort& Module::addOutput(std::string name) {
  return declarePort(impl_->outputs, std::move(name));
}

namespace {

// A module's standard output is a pipe to its runtime, which logs it (docs/logs.md): make it
// line-buffered before main() prints anything, so that a module that crashes loses no line it
// printed (the C library would otherwise hold up to 4 KiB). Only in a process the runtime
// started as a module (its join contract in the environment).
__attribute__((constructor)) void lineBufferedStandardOutput() {
  if (std::getenv("VRFLOW_MODULE_INDEX") != nullptr ||
      std::getenv("VRFLOW_MODULE_INDICES") != nullptr) {
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
  }
}

}  // namespace

Status Module::init() {
  Impl& m = *impl_;
  // The supervisor's contract: which segment, and which slot of it is this module's. A module
  // of an MPI job takes the slot of its rank.
  const auto contract = ipc::JoinContract::decodeEnvironment();
  if (!contract) return contract.error();
  const auto found = contract->slotIndex([](const char* name) { return std::getenv(name); });
  if (!found) return found.error();
  const long index = *found;
  int fd = contract->segmentFd;
  if (fd < 0) {
    // A module started through mpirun (which closes inherited descriptors) opens the runtime's
    // descriptor by its /proc path instead.
    fd = open(contract->segmentPath.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
      return makeError("cannot join the run: cannot open " + contract->segmentPath + ": " +
                       std::strerror(errno));
    }
  }
  auto segment = ipc::Segment::attach(fd);
  if (!segment) return makeError("cannot join the run: " + segment.error().message);
  // Die with the runtime even when started through a wrapper, and do not hand the segment on
  // to processes this module starts.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  fcntl(fd, F_SETFD, FD_CLOEXEC);
  m.segment = std::move(*segment);
  auto slot = ipc::ModuleSlotUser::join(m.segment, index);
  if (!slot) return slot.error();
  m.slot = *slot;
  m.id = m.slot.id();
  if (m.slot.idPrefix() == 0) {
    return makeError("cannot join the run: the daemon gave module '" + m.id + "' no id prefix");
  }
  m.ids.emplace(m.slot.idPrefix());
  m.slot.setPid(static_cast<int32_t>(getpid()));
  slotToMarkOutOfMemory.store(&m.slot);
  if (std::get_new_handler() == nullptr) std::set_new_handler(&markOutOfMemory);
  m.current.resize(static_cast<std::size_t>(m.slot.portCount()));
  m.trace = m.slot.traceRing();

  // Parameters: the typed set the daemon encoded (vrflow/base/parameters.hpp).
  auto params = decodeParameters(m.slot.paramsBlock());
  if (!params) return makeError("cannot join the run: " + params.error().message);
  m.params = std::move(*params);
  m.params.setFailureHandler(&exitOnParameterError);

  // Match declared ports with the run's.
  std::vector<bool> declared(static_cast<std::size_t>(m.slot.portCount()), false);
  auto match = [&](Port& port, bool isInput) -> Status {
    port.slot_ = m.slot.findPort(port.name_, isInput);
    if (port.slot_ < 0) {
      return makeError("module '" + m.id + "' declares " + (isInput ? "input" : "output") +
                       " port '" + port.name_ + "' that its package manifest does not list");
    }
    declared[static_cast<std::size_t>(port.slot_)] = true;
    return {};
  };
  for (auto& port : m.inputs) {
    if (auto status = match(port, true); !status) return status;
  }
  for (auto& port : m.outputs) {
    if (auto status = match(port, false); !status) return status;
  }
  for (int i = 0; i < m.slot.portCount(); ++i) {
    const std::string_view name = m.slot.portName(i);
    const bool isInput = m.slot.portIsInput(i);
    const bool connected = m.slot.portConnected(i);
    const bool implicit = name == "beginIt" || name == "endIt";
    if (name == "endIt" && !isInput) m.endItSlot = i;
    if (!declared[static_cast<std::size_t>(i)] && !implicit && connected) {
      return makeError("module '" + m.id + "' does not declare port '" + std::string(name) +
                       "' that the application connects");
    }
    if (isInput && connected) m.waitOrder.push_back(i);
  }
  m.initialized = true;
  m.setState(ipc::ModuleState::Computing);
  return {};
}

bool Module::wait() {
  Impl& m = *impl_;
  VRFLOW_ASSERT(m.initialized, "call init() before wait()");
  if (m.finished) return false;
  if (m.inIteration) m.endIteration();
  if (m.slot.iterationLimit() != 0 && m.iteration >= m.slot.iterationLimit()) {
    m.finish(ipc::EndCause::IterationLimit);
    return false;
  }
  // Waiting on an input sees a stop request; a module without connected inputs sees it here
  // (or it would run until killed).
  if (m.waitOrder.empty() && (m.stopRequested() || m.slot.unneeded())) {
    m.finish(m.stopRequested() ? ipc::EndCause::RunStopped : ipc::EndCause::Unneeded);
    return false;
  }
  const uint64_t waitStart = nowNs();
  for (const int portSlot : m.waitOrder) {
    uint64_t handle = 0;
    switch (m.slot.take(portSlot, handle, kPollNs)) {
      case ipc::ModuleSlotUser::Take::Message:
        break;
      case ipc::ModuleSlotUser::Take::RunStopped:
        m.finish(ipc::EndCause::RunStopped);
        return false;
      case ipc::ModuleSlotUser::Take::Unneeded:
        m.finish(ipc::EndCause::Unneeded);
        return false;
      case ipc::ModuleSlotUser::Take::EndOfInput:
        m.finish(ipc::EndCause::EndOfInput);  // every upstream module has ended
        return false;
    }
    auto message = Message::adopt(m.segment, handle);
    if (!message) {
      std::fprintf(stderr, "vrflow: module '%s': malformed message on input '%s': %s\n",
                   m.id.c_str(), std::string(m.slot.portName(portSlot)).c_str(),
                   message.error().message.c_str());
      std::_Exit(3);
    }
    m.current[static_cast<std::size_t>(portSlot)] = std::move(*message);
  }
  const uint64_t now = nowNs();
  m.slot.addWait(now - waitStart);
  if (m.trace != nullptr) {
    m.traceEvent(ipc::TraceKind::Wait, waitStart, now);
    for (const int portSlot : m.waitOrder) {
      const auto stamps = m.current[static_cast<std::size_t>(portSlot)]->stamps();
      m.traceEvent(ipc::TraceKind::Received, now, now, msg::fnv1a32(stamps.source),
                   stamps.iteration);
    }
  }
  m.iterationStartNs = now;
  if (!m.waitOrder.empty()) {
    const auto stamps = m.current[static_cast<std::size_t>(m.waitOrder.front())]->stamps();
    m.simTime = stamps.simTime;
    m.timeStep = stamps.timeStep;
  }
  m.inIteration = true;
  // FlowVR's timing: the signal leaves as the iteration begins, so that a producer paced by it
  // computes its next iteration while this one runs.
  if (m.slot.endItAfterWait()) m.sendEndIt();
  m.setState(ipc::ModuleState::Computing);
  return true;
}

const Message& Module::get(const InputPort& port) const {
  VRFLOW_ASSERT(port.module_ == this && port.slot_ >= 0, "port of another module or before init()");
  return impl_->current[static_cast<std::size_t>(port.slot_)];
}

OutgoingMessage Module::newMessage(std::size_t sizeHint) {
  auto impl = std::make_unique<OutgoingMessage::Impl>(impl_->segment, sizeHint);
  auto& builder = impl->builder;
  builder.setSource(impl_->id);
  builder.setIteration(impl_->iteration);
  builder.setSimTime(impl_->simTime);
  builder.setTimeStep(impl_->timeStep);
  return OutgoingMessage(std::move(impl));
}

Status Module::put(const OutputPort& port, OutgoingMessage&& message) {
  VRFLOW_ASSERT(port.module_ == this && port.slot_ >= 0, "port of another module or before init()");
  auto& builder = message.impl_->builder;
  builder.setSendTimeNs(wallNs());
  const std::size_t used = builder.finish();
  if (used == 0 || message.impl_->sink.data() == nullptr) {
    Error error{"shared memory exhausted while building a message for '" + port.name_ +
                "' (raise vrflow run --shm-size)"};
    impl_->fail(error.message);
    return error;
  }
  const uint64_t handle = message.impl_->sink.take(used);
  if (!impl_->push(port.slot_, handle)) {
    impl_->segment.release(handle);
    return makeError("run stopped");
  }
  return {};
}

Result<Message> Module::seal(OutgoingMessage&& message) {
  auto& builder = message.impl_->builder;
  const std::size_t used = builder.finish();
  if (used == 0 || message.impl_->sink.data() == nullptr) {
    Error error{"shared memory exhausted while building a message (raise vrflow run --shm-size)"};
    impl_->fail(error.message);
    return error;
  }
  return Message::adopt(impl_->segment, message.impl_->sink.take(used));
}

Status Module::put(const OutputPort& port, const Message& message) {
  VRFLOW_ASSERT(port.module_ == this && port.slot_ >= 0, "port of another module or before init()");
  if (!message.valid()) return makeError("cannot forward an empty message");
  impl_->segment.retain(message.handle());
  if (!impl_->push(port.slot_, message.handle())) {
    impl_->segment.release(message.handle());
    return makeError("run stopped");
  }
  return {};
}

const std::string& Module::id() const {
  return impl_->id;
}
uint64_t Module::iteration() const {
  return impl_->iteration;
}
double Module::simTime() const {
  return impl_->simTime;
}
double Module::timeStep() const {
  return impl_->timeStep;
}
bool Module::stopRequested() const {
  return impl_->stopRequested();
}

const Parameters& Module::params() const {
  return impl_->params;
}

uint64_t Module::newId() {
  VRFLOW_ASSERT(impl_->initialized, "newId() before init()");
  auto id = impl_->ids->next();
  if (!id) exitOnParameterError(Error{"module '" + impl_->id + "': " + id.error().message});
  return *id;
}

int Module::exitStatus() const {
  return impl_->failed ? 1 : 0;
}

}  // namespace vrflow
