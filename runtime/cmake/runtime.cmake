pkg_check_modules(SODIUM REQUIRED IMPORTED_TARGET libsodium)

# The runtime proper: shared memory, module API, daemon and filters, the run supervisor.
vrflow_add_library(runtime
  SOURCES
    src/ipc/doorbell.cpp
    src/ipc/segment.cpp
    src/module/message.cpp
    src/module/module.cpp
    src/daemon/filter.cpp
    src/daemon/filter_spec.cpp
    src/daemon/filter_registry.cpp
    src/daemon/compose.cpp
    src/daemon/builtin_filters.cpp
    src/daemon/filters/common.cpp
    src/daemon/filters/forward.cpp
    src/daemon/filters/merge.cpp
    src/daemon/filters/gate.cpp
    src/daemon/filters/latest.cpp
    src/daemon/filters/max_frequency.cpp
    src/daemon/filters/multi_rate.cpp
    src/daemon/filters/route.cpp
    src/daemon/filters/multiplex.cpp
    src/daemon/filters/rotate.cpp
    src/daemon/filters/scatter.cpp
    src/daemon/filters/stamp_filter.cpp
    src/daemon/filters/type_filter.cpp
    src/daemon/plugin_loader.cpp
    src/daemon/testing/filter_harness.cpp
    src/daemon/graph.cpp
    src/daemon/daemon.cpp
    src/net/control.cpp
    src/net/frame.cpp
    src/net/secret.cpp
    src/net/transport.cpp
    src/run/spawn.cpp
    src/run/report.cpp
    src/run/trace.cpp
    src/run/runner.cpp
  PUBLIC_DEPS vrflow::message vrflow::app vrflow::base Threads::Threads
  PRIVATE_DEPS nlohmann_json::nlohmann_json PkgConfig::SODIUM ${CMAKE_DL_LIBS})

# The programs that load filter plugins export the whole runtime (docs/filters.md, "Plugins").
vrflow_add_plugin_host(vrflow SOURCES tools/vrflow_main.cpp DEPS CLI11::CLI11)
vrflow_add_plugin_host(vrflow-daemon SOURCES tools/daemon_main.cpp tools/control_link.cpp
  DEPS CLI11::CLI11)
