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
#include <vector>

#include "shm_sink.hpp"
#include "vrflow/base/assert.hpp"
#include "vrflow/ipc/control.hpp"
#include "vrflow/ipc/ring.hpp"
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

// The slot index of this module in the run's control table. A module started alone gets it in
// VRFLOW_MODULE_INDEX; the modules of one MPI job share one mpirun and get the indices of all
// of them in rank order (VRFLOW_MODULE_INDICES), this process's rank choosing its own.
Result<long> moduleIndexFromEnvironment() {
  const char* indices = std::getenv("VRFLOW_MODULE_INDICES");
  if (indices == nullptr) {
    const char* index = std::getenv("VRFLOW_MODULE_INDEX");
    if (index == nullptr) {
      return makeError(
          "this program is a vrflow module: start it through an application "
          "(`vrflow run APP.xml`), not by hand");
    }
    return std::atol(index);
  }
  const char* rankText = nullptr;
  const char* rankName = nullptr;
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK"}) {
    if ((rankText = std::getenv(name)) != nullptr) {
      rankName = name;
      break;
    }
  }
  const std::string job = std::getenv("VRFLOW_MPI_JOB") != nullptr
                              ? " '" + std::string(std::getenv("VRFLOW_MPI_JOB")) + "'"
                              : std::string();
  if (rankText == nullptr) {
    return makeError("cannot join the run: this process is a module of MPI job" + job +
                     " (VRFLOW_MODULE_INDICES=" + indices +
                     ") but has no MPI rank (neither OMPI_COMM_WORLD_RANK nor PMIX_RANK is set): "
                     "its ranks are started by the runtime's mpirun");
  }
  std::vector<long> list;
  for (const char* p = indices; *p != '\0';) {
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(p, &end, 10);
    if (end == p || errno != 0 || value < 0 || (*end != ',' && *end != '\0')) {
      return makeError(std::string("cannot join the run: malformed VRFLOW_MODULE_INDICES '") +
                       indices + "' (expected slot indices separated by ',')");
    }
    list.push_back(value);
    p = *end == ',' ? end + 1 : end;
  }
  char* end = nullptr;
  errno = 0;
  const long rank = std::strtol(rankText, &end, 10);
  if (end == rankText || *end != '\0' || errno != 0 || rank < 0 ||
      rank >= static_cast<long>(list.size())) {
    return makeError("cannot join the run: MPI rank " + std::string(rankText) + " (" + rankName +
                     ") is not a rank of MPI job" + job + ", which has " +
                     std::to_string(list.size()) + " module(s) (VRFLOW_MODULE_INDICES=" + indices +
                     "): start the job with as many ranks as modules");
  }
  return list[static_cast<std::size_t>(rank)];
}

// The slot of this process's module, marked when operator new finds no memory (the runtime
// then names its memory limit as the cause of the module's end).
std::atomic<ipc::ModuleSlot*> slotToMarkOutOfMemory{nullptr};

void markOutOfMemory() {
  if (auto* slot = slotToMarkOutOfMemory.load()) slot->outOfMemory.store(1);
  std::set_new_handler(nullptr);  // operator new now throws std::bad_alloc
}

}  // namespace

struct OutgoingMessage::Impl {
  Impl(ipc::Segment& segment, std::size_t hint) : sink(segment, hint), builder(sink) {}
  detail::ShmSink sink;
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
  ipc::ModuleSlot* slot = nullptr;
  std::atomic<uint32_t> idNext{0};  // this module's own block of ids (ipc::kIdBlockBits)
  uint32_t idEnd = 0;
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

  ipc::Ring& ring(int portSlot) { return *segment.at<ipc::Ring>(slot->ports[portSlot].ringOffset); }
  bool stopRequested() const {
    return segment.header().stopRequested.load(std::memory_order_acquire) != 0;
  }
  // The daemon found that every module this one's outputs reach has ended.
  bool unneeded() const { return slot->unneeded.load(std::memory_order_acquire) != 0; }
  int findPort(std::string_view name, bool input) const {
    for (uint32_t i = 0; i < slot->portCount; ++i) {
      const auto& port = slot->ports[i];
      if ((port.isInput != 0) == input && name == port.name) return static_cast<int>(i);
    }
    return -1;
  }
  void setState(ipc::ModuleState state, int port = -1) {
    slot->waitingPort.store(port, std::memory_order_relaxed);
    slot->state.store(static_cast<uint32_t>(state), std::memory_order_release);
  }
  // Pushes a handle on an output ring, sleeping while it is full. False if the run stops.
  bool push(int portSlot, uint64_t handle) {
    auto& port = slot->ports[portSlot];
    if (!port.connected) {
      segment.release(handle);  // nothing listens: dropped here, as the output filter would
      return true;
    }
    ipc::Ring& out = ring(portSlot);
    // Read before the push: from then on the daemon holds the block and may free it.
    const uint64_t bytes = segment.block(handle).used;
    // Traced: the send time is taken before the push (a receiver may wake at once), with the
    // stamps that name the message, which differ from this module's when it forwards one.
    TraceEvent sent{};
    if (trace != nullptr) sent = sentEvent(handle);
    segment.handOver(handle);
    setState(ipc::ModuleState::Putting, portSlot);
    while (!out.push(handle)) {
      const uint32_t seen = slot->bell.prepare();
      if (stopRequested()) return false;
      if (out.push(handle)) break;
      slot->bell.sleep(seen, kPollNs);
    }
    port.messages.fetch_add(1, std::memory_order_relaxed);
    port.bytes.fetch_add(bytes, std::memory_order_relaxed);
    segment.header().daemonBell.ring();
    if (trace != nullptr) trace->record(sent);
    setState(ipc::ModuleState::Computing);
    return true;
  }
  // Closes the iteration in progress (at the next wait(), or as the module leaves its loop).
  void endIteration() {
    const uint64_t now = nowNs();
    const uint64_t took = now - iterationStartNs;
    slot->computeNs.fetch_add(took, std::memory_order_relaxed);
    slot->histogram[ipc::histogramBucket(took)].fetch_add(1, std::memory_order_relaxed);
    traceEvent(ipc::TraceKind::Compute, iterationStartNs, now);
    if (slot->endItAfterWait == 0) sendEndIt();
    inIteration = false;
    ++iteration;
    slot->iterations.store(iteration, std::memory_order_release);
  }
  // The endIt signal of the iteration in progress, when the port is connected.
  void sendEndIt() {
    if (endItSlot >= 0 && slot->ports[endItSlot].connected) {
      detail::ShmSink sink(segment, 64);
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
    slot->endCause.store(static_cast<uint32_t>(cause), std::memory_order_release);
    current.clear();
    setState(ipc::ModuleState::Finished);
    segment.header().daemonBell.ring();
  }
};

bool InputPort::connected() const {
  return module_->impl_->slot && slot_ >= 0 && module_->impl_->slot->ports[slot_].connected;
}
bool OutputPort::connected() const {
  return module_->impl_->slot && slot_ >= 0 && module_->impl_->slot->ports[slot_].connected;
}

Module::Module() : impl_(std::make_unique<Impl>()) {
  impl_->params.setFailureHandler(&exitOnParameterError);  // also before init(): a bug to report
}

Module::~Module() {
  if (impl_->slot == nullptr) return;
  // Leaving the loop ends the iteration in progress: it counts (docs/module-api.md).
  if (impl_->inIteration) impl_->endIteration();
  impl_->finish(ipc::EndCause::LeftLoop);
}

InputPort& Module::addInput(std::string name) {
  VRFLOW_ASSERT(!impl_->initialized, "declare ports before init()");
  auto& port = impl_->inputs.emplace_back();
  port.name_ = std::move(name);
  port.module_ = this;
  return port;
}

OutputPort& Module::addOutput(std::string name) {
  VRFLOW_ASSERT(!impl_->initialized, "declare ports before init()");
  auto& port = impl_->outputs.emplace_back();
  port.name_ = std::move(name);
  port.module_ = this;
  return port;
}

Status Module::init() {
  Impl& m = *impl_;
  const char* fdText = std::getenv("VRFLOW_SEGMENT_FD");
  // A module started through mpirun (which closes inherited descriptors) opens the runtime's
  // descriptor by its /proc path instead.
  const char* pathText = std::getenv("VRFLOW_SEGMENT_PATH");
  if (fdText == nullptr && pathText == nullptr) {
    return makeError(
        "this program is a vrflow module: start it through an application "
        "(`vrflow run APP.xml`), not by hand");
  }
  const Result<long> found = moduleIndexFromEnvironment();
  if (!found) return found.error();
  const long index = *found;
  int fd = -1;
  if (fdText != nullptr) {
    fd = std::atoi(fdText);
  } else {
    fd = open(pathText, O_RDWR | O_CLOEXEC);
    if (fd < 0) {
      return makeError(std::string("cannot join the run: cannot open ") + pathText + ": " +
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
  const auto offset = m.segment.header().controlOffset;
  if (offset == 0 || !m.segment.contains(offset, sizeof(ipc::ControlTable))) {
    return makeError("cannot join the run: the segment has no control table");
  }
  const auto& table = *m.segment.at<ipc::ControlTable>(offset);
  if (index < 0 || index >= static_cast<long>(table.moduleCount)) {
    return makeError("cannot join the run: module index out of range");
  }
  m.slot = m.segment.at<ipc::ModuleSlot>(table.modulesOffset) + index;
  if (index < static_cast<long>(ipc::kIdBlockModules)) {
    const auto block = static_cast<uint32_t>(index + 1);
    m.idNext.store(block << ipc::kIdBlockBits);
    m.idEnd = (block + 1) << ipc::kIdBlockBits;
  }
  m.id = m.slot->id;
  m.slot->pid.store(static_cast<int32_t>(getpid()));
  slotToMarkOutOfMemory.store(m.slot);
  if (std::get_new_handler() == nullptr) std::set_new_handler(&markOutOfMemory);
  m.current.resize(m.slot->portCount);
  if (m.slot->traceOffset != 0 && m.segment.contains(m.slot->traceOffset, sizeof(ipc::TraceRing))) {
    m.trace = m.segment.at<ipc::TraceRing>(m.slot->traceOffset);
  }

  // Parameters: the typed set the daemon encoded (vrflow/base/parameters.hpp).
  if (!m.segment.contains(m.slot->paramsOffset, m.slot->paramsBytes)) {
    return makeError("cannot join the run: the parameter block lies outside the segment");
  }
  auto params = decodeParameters(
      std::string_view(m.segment.at<char>(m.slot->paramsOffset), m.slot->paramsBytes));
  if (!params) return makeError("cannot join the run: " + params.error().message);
  m.params = std::move(*params);
  m.params.setFailureHandler(&exitOnParameterError);

  // Match declared ports with the run's.
  std::vector<bool> declared(m.slot->portCount, false);
  for (auto& port : m.inputs) {
    port.slot_ = m.findPort(port.name_, true);
    if (port.slot_ < 0) {
      return makeError("module '" + m.id + "' declares input port '" + port.name_ +
                       "' that its package manifest does not list");
    }
    declared[static_cast<std::size_t>(port.slot_)] = true;
  }
  for (auto& port : m.outputs) {
    port.slot_ = m.findPort(port.name_, false);
    if (port.slot_ < 0) {
      return makeError("module '" + m.id + "' declares output port '" + port.name_ +
                       "' that its package manifest does not list");
    }
    declared[static_cast<std::size_t>(port.slot_)] = true;
  }
  for (uint32_t i = 0; i < m.slot->portCount; ++i) {
    const auto& port = m.slot->ports[i];
    const std::string_view name = port.name;
    const bool implicit = name == "beginIt" || name == "endIt";
    if (name == "endIt" && !port.isInput) m.endItSlot = static_cast<int>(i);
    if (!declared[i] && !implicit && port.connected) {
      return makeError("module '" + m.id + "' does not declare port '" + std::string(name) +
                       "' that the application connects");
    }
    if (port.isInput && port.connected) m.waitOrder.push_back(static_cast<int>(i));
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
  if (m.slot->iterationLimit != 0 && m.iteration >= m.slot->iterationLimit) {
    m.finish(ipc::EndCause::IterationLimit);
    return false;
  }
  // Waiting on an input sees a stop request; a module without connected inputs sees it here
  // (or it would run until killed).
  if (m.waitOrder.empty() && (m.stopRequested() || m.unneeded())) {
    m.finish(m.stopRequested() ? ipc::EndCause::RunStopped : ipc::EndCause::Unneeded);
    return false;
  }
  const uint64_t waitStart = nowNs();
  for (const int portSlot : m.waitOrder) {
    auto& port = m.slot->ports[portSlot];
    ipc::Ring& in = m.ring(portSlot);
    m.setState(ipc::ModuleState::Waiting, portSlot);
    uint64_t handle = 0;
    for (;;) {
      const uint32_t seen = m.slot->bell.prepare();
      if (m.stopRequested() || m.unneeded()) {
        m.finish(m.stopRequested() ? ipc::EndCause::RunStopped : ipc::EndCause::Unneeded);
        return false;
      }
      if (in.pop(handle)) break;
      if (port.closed.load(std::memory_order_acquire) != 0 && in.empty()) {
        m.finish(ipc::EndCause::EndOfInput);  // every upstream module has ended
        return false;
      }
      m.slot->bell.sleep(seen, kPollNs);
    }
    // Room freed on this ring: wake the daemon only if it is waiting for it.
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (port.wantsSpace.load(std::memory_order_seq_cst) != 0 && port.wantsSpace.exchange(0) != 0) {
      m.segment.header().daemonBell.ring();
    }
    auto message = Message::adopt(m.segment, handle);
    if (!message) {
      std::fprintf(stderr, "vrflow: module '%s': malformed message on input '%s': %s\n",
                   m.id.c_str(), port.name, message.error().message.c_str());
      std::_Exit(3);
    }
    m.current[static_cast<std::size_t>(portSlot)] = std::move(*message);
  }
  const uint64_t now = nowNs();
  m.slot->waitNs.fetch_add(now - waitStart, std::memory_order_relaxed);
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
  if (m.slot->endItAfterWait != 0) m.sendEndIt();
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
  const uint32_t next = impl_->idNext.fetch_add(1, std::memory_order_relaxed);
  if (next < impl_->idEnd) return msg::makeId(impl_->segment.header().hostId, next);
  return impl_->segment.newId();
}

int Module::exitStatus() const {
  return impl_->failed ? 1 : 0;
}

}  // namespace vrflow
