#pragma once

namespace vrflow {

/// Called when a precondition is broken (a bug, not a user error). The default prints the
/// location and aborts; tests may replace it.
using AssertHandler = void (*)(const char* expression, const char* message, const char* file,
                               int line);

/// Installs a new assert handler and returns the previous one.
AssertHandler setAssertHandler(AssertHandler handler);

/// Reports a broken precondition through the installed handler.
[[noreturn]] void assertFailed(const char* expression, const char* message, const char* file,
                               int line);

}  // namespace vrflow

/// Checks a precondition in every build type; a failure is a bug in the caller.
#define VRFLOW_ASSERT(cond, msg) \
  ((cond) ? static_cast<void>(0) : ::vrflow::assertFailed(#cond, msg, __FILE__, __LINE__))
