#include <algorithm>
#include <cstring>
#include <new>
#include <string>

#include "vrflow/ipc/module_slot_daemon.hpp"
#include "vrflow/ipc/module_slot_user.hpp"

namespace vrflow::ipc {
namespace {

void copyName(char (&dst)[kNameBytes], std::string_view src) {
  const std::size_t n = std::min<std::size_t>(src.size(), kNameBytes - 1);
  std::memcpy(dst, src.data(), n);
  dst[n] = '\0';
}

}  // namespace

Result<ModuleSlotUser> ModuleSlotUser::join(Segment& segment, long index) {
  const auto offset = segment.header().controlOffset;
  if (offset == 0 || !segment.contains(offset, sizeof(ControlTable))) {
    return makeError("cannot join the run: the segment has no control table");
  }
  const auto& table = *segment.at<ControlTable>(offset);
  if (index < 0 || index >= static_cast<long>(table.moduleCount)) {
    return makeError("cannot join the run: module index out of range");
  }
  return ModuleSlotUser(segment, segment.at<ModuleSlot>(table.modulesOffset)[index]);
}

int ModuleSlotUser::findPort(std::string_view name, bool input) const {
  for (uint32_t i = 0; i < slot_->portCount; ++i) {
    const auto& port = slot_->ports[i];
    if ((port.isInput != 0) == input && name == port.name) return static_cast<int>(i);
  }
  return -1;
}

std::string_view ModuleSlotUser::paramsBlock() const {
  // The daemon wrote the block; a slot pointing outside the segment reads as no bytes, which
  // the parameter codec refuses.
  if (!segment_->contains(slot_->paramsOffset, slot_->paramsBytes)) return {};
  return {segment_->at<char>(slot_->paramsOffset), slot_->paramsBytes};
}

TraceRing* ModuleSlotUser::traceRing() const {
  if (slot_->traceOffset == 0 || !segment_->contains(slot_->traceOffset, sizeof(TraceRing))) {
    return nullptr;
  }
  return segment_->at<TraceRing>(slot_->traceOffset);
}

void ModuleSlotDaemon::describe(std::string_view id, std::string_view host, uint32_t idPrefix,
                                uint64_t iterationLimit, bool endItAfterWait) {
  copyName(slot_->id, id);
  copyName(slot_->host, host);
  slot_->idPrefix = idPrefix;
  slot_->iterationLimit = iterationLimit;
  slot_->endItAfterWait = endItAfterWait ? 1 : 0;
}

Status ModuleSlotDaemon::addTraceRing() {
  const uint64_t offset = segment_->reserve(sizeof(TraceRing));
  if (offset == 0) return makeError("shared-memory segment too small for tracing");
  new (segment_->at<void>(offset)) TraceRing();
  slot_->traceOffset = offset;
  return {};
}

Status ModuleSlotDaemon::setParams(std::string_view text) {
  const uint64_t offset = segment_->reserve(text.size() + 1, 8);
  if (offset == 0) return makeError("shared-memory segment too small");
  char* out = segment_->at<char>(offset);
  std::memcpy(out, text.data(), text.size());
  out[text.size()] = '\0';
  slot_->paramsOffset = offset;
  slot_->paramsBytes = static_cast<uint32_t>(text.size());
  return {};
}

Result<RingRef> ModuleSlotDaemon::addPort(std::string_view name, bool isInput, bool stampsOnly,
                                          bool connected, uint32_t ringCapacity) {
  if (slot_->portCount >= static_cast<uint32_t>(kMaxPortsPerModule)) {
    return makeError("more than " + std::to_string(kMaxPortsPerModule) + " ports");
  }
  PortSlot& port = slot_->ports[slot_->portCount];
  copyName(port.name, name);
  port.isInput = isInput ? 1 : 0;
  port.stampsOnly = stampsOnly ? 1 : 0;
  port.connected = connected ? 1 : 0;
  port.ringOffset = segment_->reserve(Ring::bytesFor(ringCapacity));
  if (port.ringOffset == 0) return makeError("shared-memory segment too small for rings");
  auto* ring = new (segment_->at<void>(port.ringOffset)) Ring();
  ring->init(ringCapacity);
  ++slot_->portCount;
  return RingRef(ring);
}

int ModuleSlotDaemon::waitingPort() const {
  const int port = slot_->waitingPort.load();
  const auto count = std::min<uint32_t>(slot_->portCount, kMaxPortsPerModule);
  return port >= 0 && port < static_cast<int>(count) ? port : -1;
}

std::string ModuleSlotDaemon::portName(int port) const {
  const char* name = slot_->ports[port].name;
  return std::string(name, strnlen(name, kNameBytes));
}

TraceRing* ModuleSlotDaemon::traceRing() const {
  return slot_->traceOffset == 0 ? nullptr : segment_->at<TraceRing>(slot_->traceOffset);
}

Result<ControlTableDaemon> ControlTableDaemon::create(Segment& segment, uint32_t moduleCount) {
  const uint64_t tableOffset = segment.reserve(sizeof(ControlTable));
  const uint64_t slotsOffset = segment.reserve(sizeof(ModuleSlot) * moduleCount);
  if (tableOffset == 0 || (slotsOffset == 0 && moduleCount != 0)) {
    return makeError("shared-memory segment too small for the control table");
  }
  ControlTableDaemon owner;
  owner.segment_ = &segment;
  owner.offset_ = tableOffset;
  owner.table_ = new (segment.at<void>(tableOffset)) ControlTable();
  owner.table_->moduleCount = moduleCount;
  owner.table_->modulesOffset = slotsOffset;
  for (uint32_t m = 0; m < moduleCount; ++m)
    new (segment.at<ModuleSlot>(slotsOffset) + m) ModuleSlot();
  return owner;
}

void ControlTableDaemon::publish() const {
  segment_->header().controlOffset = offset_;
}

}  // namespace vrflow::ipc
