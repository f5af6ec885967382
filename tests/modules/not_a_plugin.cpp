// A shared library that is no filter plugin: it exports neither vrflowFilterPluginAbi nor
// vrflowRegisterFilters. The loader must refuse it with a message, not crash.
extern "C" int vrflowTestingAnswer() {
  return 42;
}
