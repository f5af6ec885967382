#include "vrflow/message/ids.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <thread>

namespace vrflow::msg {
namespace {

TEST(Ids, PackPrefixInHighBitsAndCounterInLowBits) {
  const std::uint64_t id = makeId(0x0A000007u, 42);
  EXPECT_EQ(id, 0x0A0000070000002Aull);
  EXPECT_EQ(prefixOf(id), 0x0A000007u);
  EXPECT_EQ(counterOf(id), 42u);
}

TEST(Ids, RoundTripExtremeValues) {
  const std::uint64_t id = makeId(0xFFFFFFFFu, 0xFFFFFFFFu);
  EXPECT_EQ(prefixOf(id), 0xFFFFFFFFu);
  EXPECT_EQ(counterOf(id), 0xFFFFFFFFu);
  EXPECT_EQ(makeId(0, 0), kNullId);
}

TEST(Ids, Fnv1aGivesItsKnownValues) {
  EXPECT_EQ(fnv1a32(""), 0x811C9DC5u);
  EXPECT_EQ(fnv1a32("a"), 0xE40C292Cu);
  EXPECT_EQ(fnv1a32("foobar"), 0xBF9CF968u);
}

TEST(IdPrefixes, AModuleWithoutACollisionHasTheHashOfItsId) {
  const auto prefixes = idPrefixes({"bodies", "net", "fluid/block0"});
  ASSERT_EQ(prefixes.size(), 3u);
  EXPECT_EQ(prefixes[0], fnv1a32("bodies"));
  EXPECT_EQ(prefixes[1], fnv1a32("net"));
  EXPECT_EQ(prefixes[2], fnv1a32("fluid/block0"));
}

TEST(IdPrefixes, DependOnTheSetOfIdsNotOnTheirOrder) {
  const std::vector<std::string> ids{"user", "cam0", "cam1", "sil0", "hull/slab0", "view"};
  const auto prefixes = idPrefixes(ids);
  std::vector<std::string> reversed(ids.rbegin(), ids.rend());
  const auto again = idPrefixes(reversed);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(prefixes[i], again[ids.size() - 1 - i]) << ids[i];
  }
}

// "pyqjpcv" and "xgoik67" have the same FNV-1a 32 (0x90cdc5ea).
TEST(IdPrefixes, CollidingIdsGetDistinctPrefixesTheSmallestKeepingItsHash) {
  ASSERT_EQ(fnv1a32("pyqjpcv"), fnv1a32("xgoik67"));
  const std::uint32_t hash = fnv1a32("pyqjpcv");
  for (const auto& ids : {std::vector<std::string>{"xgoik67", "pyqjpcv", "other"},
                          std::vector<std::string>{"other", "pyqjpcv", "xgoik67"}}) {
    const auto prefixes = idPrefixes(ids);
    std::map<std::string, std::uint32_t> byId;
    for (std::size_t i = 0; i < ids.size(); ++i) byId[ids[i]] = prefixes[i];
    EXPECT_EQ(byId["pyqjpcv"], hash);
    EXPECT_EQ(byId["xgoik67"], hash + 1);  // the next value no module's hash names
    EXPECT_EQ(byId["other"], fnv1a32("other"));
  }
}

TEST(IdPrefixes, ManyModulesGetDistinctNonZeroPrefixes) {
  std::vector<std::string> ids;
  for (int i = 0; i < 20000; ++i) ids.push_back("module" + std::to_string(i));
  ids.push_back("pyqjpcv");
  ids.push_back("xgoik67");
  const auto prefixes = idPrefixes(ids);
  const std::set<std::uint32_t> distinct(prefixes.begin(), prefixes.end());
  EXPECT_EQ(distinct.size(), ids.size());
  EXPECT_FALSE(distinct.contains(0u));
}

TEST(IdSource, CountsFromOneUnderItsPrefix) {
  IdSource ids(0xABCD0123u);
  EXPECT_EQ(*ids.next(), makeId(0xABCD0123u, 1));
  EXPECT_EQ(*ids.next(), makeId(0xABCD0123u, 2));
}

TEST(IdSource, ThreadsNeverGetTheSameId) {
  IdSource ids(7);
  constexpr int kPerThread = 20000;
  std::vector<std::uint64_t> a(kPerThread), b(kPerThread);
  std::thread first([&] {
    for (auto& id : a) id = *ids.next();
  });
  for (auto& id : b) id = *ids.next();
  first.join();
  std::set<std::uint64_t> all(a.begin(), a.end());
  all.insert(b.begin(), b.end());
  EXPECT_EQ(all.size(), 2u * kPerThread);
}

TEST(IdSource, ExhaustionIsOneClearErrorAndStaysOne) {
  IdSource ids(5, kIdsPerModule);
  const auto last = ids.next();
  ASSERT_TRUE(last.ok());
  EXPECT_EQ(counterOf(*last), 0xFFFFFFFFu);
  const auto past = ids.next();
  ASSERT_FALSE(past.ok());
  EXPECT_NE(past.error().message.find("ran out of object ids"), std::string::npos);
  EXPECT_FALSE(ids.next().ok());
}

}  // namespace
}  // namespace vrflow::msg
