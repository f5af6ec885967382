pkg_check_modules(SODIUM REQUIRED IMPORTED_TARGET libsodium)

# vrflow::net (libvrflow_net.so): authenticated TCP links between host daemons, their frames, and
# the launcher <-> daemon control channel.
vrflow_add_library(net SHARED
  SOURCES
    src/net/control.cpp
    src/net/frame.cpp
    src/net/secret.cpp
    src/net/transport.cpp
    src/net/transport_links.cpp
    src/net/transport_io.cpp
  PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src/net
  PUBLIC_DEPS vrflow::app vrflow::module
  PRIVATE_DEPS PkgConfig::SODIUM)

# vrflow::daemon (libvrflow_daemon.so): one host's filter network, the built-in filters and the
# filter SDK that plugins link (docs/filters.md).
vrflow_add_library(daemon SHARED
  SOURCES
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
    src/daemon/daemon_build.cpp
    src/daemon/daemon_stats.cpp
    src/daemon/daemon_reach.cpp
  PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src/daemon
  PUBLIC_DEPS vrflow::net vrflow::app vrflow::module
  PRIVATE_DEPS ${CMAKE_DL_LIBS})

# vrflow::run (libvrflow_run.so): the supervisor of one host's share of a run: it starts the
# modules, watches them, and writes the report.
vrflow_add_library(run SHARED
  SOURCES
    src/run/prepare.cpp
    src/run/process.cpp
    src/run/spawn.cpp
    src/run/report.cpp
    src/run/trace.cpp
    src/run/runner.cpp
    src/run/supervisor.cpp
    src/run/stall_check.cpp
    src/run/live_stats.cpp
    src/run/progress.cpp
    src/run/events.cpp
    src/run/run_folders.cpp
    src/run/log.cpp
    src/run/module_logs.cpp
    src/run/module_output.cpp
    src/run/run_state.cpp
    src/run/registry.cpp
  PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src/run
  PUBLIC_DEPS vrflow::daemon vrflow::app vrflow::module
  PRIVATE_DEPS nlohmann_json::nlohmann_json spdlog::spdlog)
