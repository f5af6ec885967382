#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "vrflow/ipc/block_ref.hpp"
#include "vrflow/ipc/module_slot_daemon.hpp"
#include "vrflow/ipc/module_slot_user.hpp"
#include "vrflow/ipc/segment.hpp"

namespace vrflow::ipc {
namespace {

constexpr int64_t kPollNs = 1'000'000;

// A segment whose control table has one module, "m", with an input port "in" (port 0) and an
// output port "out" (port 1), both connected; the table is published unless told otherwise.
struct OneModule {
  explicit OneModule(bool publish = true) {
    auto created = Segment::create(8 << 20);
    EXPECT_TRUE(created.ok());
    segment = std::move(*created);
    auto made = ControlTableDaemon::create(segment, 1);
    EXPECT_TRUE(made.ok());
    table = *made;
    daemon = table.slot(0);
    daemon.describe("m", "local", 0x12345678u, 0, false);
    EXPECT_TRUE(daemon.setParams("gain=2\n").ok());
    auto in = daemon.addPort("in", true, false, true, 4);
    auto out = daemon.addPort("out", false, false, true, 4);
    EXPECT_TRUE(in.ok() && out.ok());
    input = *in;
    output = *out;
    if (publish) table.publish();
  }
  uint64_t block(const char* text) {
    const uint64_t handle = segment.allocate(std::strlen(text));
    std::memcpy(segment.payload(handle), text, std::strlen(text));
    segment.block(handle).used = std::strlen(text);
    return handle;
  }
  Segment segment;
  ControlTableDaemon table;
  ModuleSlotDaemon daemon;
  RingRef input, output;
};

TEST(ModuleSlot, AModuleFindsWhatTheDaemonSetUp) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok()) << user.error().message;
  EXPECT_EQ(user->id(), "m");
  EXPECT_EQ(user->idPrefix(), 0x12345678u);
  EXPECT_EQ(user->portCount(), 2);
  EXPECT_EQ(user->findPort("in", true), 0);
  EXPECT_EQ(user->findPort("out", false), 1);
  EXPECT_EQ(user->findPort("in", false), -1);
  EXPECT_TRUE(user->portConnected(1));
  EXPECT_EQ(user->paramsBlock(), "gain=2\n");
  EXPECT_EQ(user->traceRing(), nullptr);
}

TEST(ModuleSlot, JoiningBeforeTheTableIsPublishedOrOutOfRangeIsAnError) {
  OneModule unpublished(false);
  auto early = ModuleSlotUser::join(unpublished.segment, 0);
  ASSERT_FALSE(early.ok());
  EXPECT_NE(early.error().message.find("the segment has no control table"), std::string::npos);
  OneModule run;
  for (const long index : {-1L, 1L}) {
    auto outside = ModuleSlotUser::join(run.segment, index);
    ASSERT_FALSE(outside.ok()) << index;
    EXPECT_NE(outside.error().message.find("module index out of range"), std::string::npos);
  }
}

TEST(ModuleSlot, WhatTheModulePutsTheDaemonPopsAndTheCountersSaySo) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  const uint64_t handle = run.block("hello");
  ASSERT_TRUE(user->put(1, handle, kPollNs));
  uint64_t popped = 0;
  ASSERT_TRUE(run.output.pop(popped));
  EXPECT_EQ(popped, handle);
  EXPECT_EQ(run.daemon.state(), ModuleState::Putting);
  run.segment.release(popped);
}

TEST(ModuleSlot, TakeReturnsAMessageThenSaysWhyNoneWillCome) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  const uint64_t handle = run.block("x");
  ASSERT_TRUE(run.input.push(handle));
  uint64_t taken = 0;
  EXPECT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::Message);
  EXPECT_EQ(taken, handle);
  EXPECT_EQ(run.daemon.state(), ModuleState::Waiting);
  EXPECT_EQ(run.daemon.waitingPort(), 0);
  EXPECT_EQ(run.daemon.portName(run.daemon.waitingPort()), "in");
  run.segment.release(taken);

  run.daemon.closeInput(0);
  EXPECT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::EndOfInput);
  run.daemon.markUnneeded();
  EXPECT_TRUE(run.daemon.unneeded());
  EXPECT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::Unneeded);
  run.segment.header().stopRequested.store(1);
  EXPECT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::RunStopped);
}

TEST(ModuleSlot, TakingFromAFullRingRingsTheDaemonOnlyWhenItAskedForRoom) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  auto& bell = run.segment.header().daemonBell;
  uint64_t taken = 0;
  ASSERT_TRUE(run.input.push(run.block("a")));
  uint32_t before = bell.prepare();
  ASSERT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::Message);
  run.segment.release(taken);
  EXPECT_EQ(bell.prepare(), before);  // nobody waited for room

  ASSERT_TRUE(run.input.push(run.block("b")));
  run.daemon.requestSpace(0);
  before = bell.prepare();
  ASSERT_EQ(user->take(0, taken, kPollNs), ModuleSlotUser::Take::Message);
  run.segment.release(taken);
  EXPECT_NE(bell.prepare(), before);
}

TEST(ModuleSlot, DrainingAnOutputRingWakesTheModuleOnlyWhenItWaitsForRoom) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  // Room on the ring: puts never ask for it, and draining rings nobody (a module that waits for
  // its inputs is not woken for nothing).
  for (const char* text : {"a", "b", "c", "d"}) ASSERT_TRUE(user->put(1, run.block(text), kPollNs));
  const uint32_t before = run.daemon.rings();
  uint64_t popped = 0;
  ASSERT_TRUE(run.output.pop(popped));
  run.segment.release(popped);
  run.daemon.outputDrained(1);
  EXPECT_EQ(run.daemon.rings(), before);
  EXPECT_FALSE(run.daemon.waitsForRoom(1));

  // A full ring: put() asks for room and sleeps (its timeout far away); draining wakes it.
  ASSERT_TRUE(user->put(1, run.block("e"), kPollNs));
  std::atomic<bool> putDone{false};
  std::thread module([&] {
    EXPECT_TRUE(user->put(1, run.block("f"), 60'000'000'000));
    putDone.store(true);
  });
  for (int i = 0; i < 10'000 && !run.daemon.waitsForRoom(1); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(run.daemon.waitsForRoom(1));
  EXPECT_FALSE(putDone.load());
  ASSERT_TRUE(run.output.pop(popped));
  run.segment.release(popped);
  run.daemon.outputDrained(1);
  module.join();  // hangs (a minute) when the drain does not wake it
  EXPECT_TRUE(putDone.load());
  EXPECT_NE(run.daemon.rings(), before);
  EXPECT_FALSE(run.daemon.waitsForRoom(1));
  while (run.output.pop(popped)) run.segment.release(popped);
}

TEST(ModuleSlot, TheDaemonReadsWhatTheModuleReports) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  EXPECT_EQ(run.daemon.state(), ModuleState::Starting);
  user->setPid(1234);
  user->addCompute(1000);
  user->addCompute(1000);
  user->addWait(500);
  user->setIterations(2);
  user->markOutOfMemory();
  user->finish(EndCause::IterationLimit);
  EXPECT_EQ(run.daemon.pid(), 1234);
  EXPECT_EQ(run.daemon.computeNs(), 2000u);
  EXPECT_EQ(run.daemon.histogramCount(histogramBucket(1000)), 2u);
  EXPECT_EQ(run.daemon.waitNs(), 500u);
  EXPECT_EQ(run.daemon.iterations(), 2u);
  EXPECT_TRUE(run.daemon.outOfMemory());
  EXPECT_TRUE(run.daemon.finished());
  EXPECT_EQ(run.daemon.endCause(), EndCause::IterationLimit);
  EXPECT_EQ(run.daemon.waitingPort(), -1);
}

TEST(ModuleSlot, AWaitingPortTheModuleScribbledOutOfRangeReadsAsNone) {
  OneModule run;
  auto user = ModuleSlotUser::join(run.segment, 0);
  ASSERT_TRUE(user.ok());
  user->setState(ModuleState::Waiting, 31);  // a port the module does not have
  EXPECT_EQ(run.daemon.waitingPort(), -1);
  user->setState(ModuleState::Waiting, 1);
  EXPECT_EQ(run.daemon.waitingPort(), 1);
}

TEST(BlockRef, CopiesShareTheBlockAndTheLastOneFreesIt) {
  auto segment = Segment::create(8 << 20);
  ASSERT_TRUE(segment.ok());
  const uint64_t handle = segment->allocate(100);
  {
    BlockRef first(&*segment, handle);
    BlockRef second = first;
    EXPECT_EQ(segment->block(handle).refs.load(), 2u);
    BlockRef moved = std::move(first);
    EXPECT_FALSE(first.valid());  // NOLINT(bugprone-use-after-move): checking the moved-from state
    EXPECT_EQ(segment->block(handle).refs.load(), 2u);
  }
  EXPECT_EQ(segment->header().inUseBytes.load(), 0u);
}

}  // namespace
}  // namespace vrflow::ipc
