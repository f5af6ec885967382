// A shared library that is no filter plugin: it exports no vrflowFilterPluginV<ABI> entry point
// of any version. The loader must refuse it with a message, not crash.
extern "C" int vrflowTestingAnswer() {
  return 42;
}
