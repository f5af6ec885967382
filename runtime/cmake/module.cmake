# vrflow::module (libvrflow_module.so): all that a module executable links. The module API, the
# message builder and checked reader, the module's side of shared memory (segment, rings,
# doorbells), and the base utilities every layer shares. One copy per process of the object type
# registry and of the other process-wide state: every layer above links this library.
vrflow_add_library(module SHARED
  SOURCES
    ${vrflow_base_sources}
    ${vrflow_message_sources}
    src/ipc/doorbell.cpp
    src/ipc/segment.cpp
    src/ipc/join_contract.cpp
    src/ipc/module_slot.cpp
    src/module/message.cpp
    src/module/module.cpp
  PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src/module
  PUBLIC_DEPS Threads::Threads
  PRIVATE_DEPS PkgConfig::XXHASH Eigen3::Eigen)
