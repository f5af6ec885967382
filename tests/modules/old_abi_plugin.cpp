// A filter plugin built for ABI 1, before the version was in the entry point's name: it exports
// vrflowFilterPluginAbi() (returning 1) and vrflowRegisterFilters. The loader must refuse it
// with a message naming the file and both versions, and never call vrflowRegisterFilters.
#include <cstdint>
#include <cstdlib>

extern "C" __attribute__((visibility("default"))) std::uint32_t vrflowFilterPluginAbi() {
  return 1;
}

extern "C" __attribute__((visibility("default"))) void vrflowRegisterFilters(void*, void*) {
  std::abort();
}
