#pragma once

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "vrflow/daemon/testing/filter_harness.hpp"

namespace vrflow::testing {

using daemon::testing::FilterHarness;
using Params = std::map<std::string, std::string>;

/// The harness of filter `type` with `params`; fails the test when it cannot be made.
inline std::unique_ptr<FilterHarness> harness(const std::string& type, const Params& params = {}) {
  auto made = FilterHarness::create(type, params);
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().message);
  return made.ok() ? std::move(*made) : nullptr;
}

/// Why filter `type` refuses `params` (empty when it accepts them).
inline std::string refusal(const std::string& type, const Params& params) {
  auto made = FilterHarness::create(type, params);
  return made.ok() ? std::string() : made.error().message;
}

/// The number of chunks of `message`.
inline std::uint32_t chunksOf(const daemon::MessageRef& message) {
  const auto view = message.view();
  return view.ok() ? view->chunkCount() : 0;
}

}  // namespace vrflow::testing
