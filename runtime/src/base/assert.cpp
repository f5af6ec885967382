#include "vrflow/base/assert.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace vrflow {
namespace {

void defaultHandler(const char* expression, const char* message, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: vrflow bug: assertion '%s' failed: %s\n", file, line, expression,
               message);
  std::abort();
}

std::atomic<AssertHandler> gHandler{&defaultHandler};

}  // namespace

AssertHandler setAssertHandler(AssertHandler handler) {
  return gHandler.exchange(handler);
}

void assertFailed(const char* expression, const char* message, const char* file, int line) {
  gHandler.load()(expression, message, file, line);
  std::abort();  // a handler must not return
}

}  // namespace vrflow
