# One way to define a vrflow target. Every library gets a vrflow::<name> alias, our warning
# settings (through an INTERFACE target, so they never leak onto dependencies) and explicit sources.

add_library(vrflow_warnings INTERFACE)
target_compile_options(vrflow_warnings INTERFACE -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion)
# GCC 12 reports -Wrestrict inside libstdc++'s std::string concatenation at -O2/-O3, a known
# false positive (GCC bug 105651); it is not about our code.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(vrflow_warnings INTERFACE -Wno-restrict)
endif()
if(VRFLOW_WARNINGS_AS_ERRORS)
  target_compile_options(vrflow_warnings INTERFACE -Werror)
endif()
if(VRFLOW_HEAVY_VALIDATION)
  target_compile_definitions(vrflow_warnings INTERFACE VRFLOW_HEAVY_VALIDATION=1)
endif()

# The layers that outside code links (docs/install.md): installed with an export (vrflow::NAME in
# lib/cmake/vrflow/vrflowTargets.cmake). vrflow::module is the module SDK, vrflow::daemon the
# filter SDK; app and net are exported because the daemon's link interface names them.
set(VRFLOW_EXPORTED_LIBRARIES module app net daemon)

# vrflow_add_library(NAME [SHARED] SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...] [INCLUDE dir]
#                    [PRIVATE_INCLUDE dir]): SHARED makes one of vrflow's layers (docs/architecture.md),
# a shared library with a version and an soname (libvrflow_NAME.so.0), installed in <prefix>/lib;
# without it a static library, for what only one program or module links (a node package's
# solver), never installed.
function(vrflow_add_library name)
  cmake_parse_arguments(ARG "SHARED" "INCLUDE" "PRIVATE_INCLUDE;SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  if(ARG_SHARED)
    add_library(vrflow_${name} SHARED ${ARG_SOURCES})
    set_target_properties(vrflow_${name} PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
    # Calls inside a layer stay direct (no PLT indirection on the message path).
    target_compile_options(vrflow_${name} PRIVATE -fno-semantic-interposition)
    # A layer resolves every symbol against itself and the layers below it: an upward call
    # fails the link instead of waiting for the program that loads it (sanitizer builds leave
    # their runtime's symbols to the program).
    if(NOT CMAKE_BUILD_TYPE MATCHES "^(ASAN|TSAN)$")
      target_link_options(vrflow_${name} PRIVATE -Wl,--no-undefined)
    endif()
  else()
    add_library(vrflow_${name} STATIC ${ARG_SOURCES})
  endif()
  add_library(vrflow::${name} ALIAS vrflow_${name})
  set_target_properties(vrflow_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON OUTPUT_NAME vrflow_${name})
  if(NOT ARG_INCLUDE)
    set(ARG_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  if(NOT ARG_PRIVATE_INCLUDE)
    set(ARG_PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  endif()
  target_include_directories(vrflow_${name} PUBLIC $<BUILD_INTERFACE:${ARG_INCLUDE}>
    PRIVATE ${ARG_PRIVATE_INCLUDE})
  target_link_libraries(vrflow_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE vrflow_warnings ${ARG_PRIVATE_DEPS})
  if(name IN_LIST VRFLOW_EXPORTED_LIBRARIES)
    set_target_properties(vrflow_${name} PROPERTIES EXPORT_NAME ${name})
    target_compile_features(vrflow_${name} INTERFACE cxx_std_20)
    target_include_directories(vrflow_${name} INTERFACE $<INSTALL_INTERFACE:include>)
    install(TARGETS vrflow_${name} EXPORT vrflowTargets LIBRARY DESTINATION lib)
  elseif(ARG_SHARED)
    install(TARGETS vrflow_${name} LIBRARY DESTINATION lib NAMELINK_SKIP)
  endif()
endfunction()

# vrflow_add_executable(NAME SOURCES ... [DEPS ...])
function(vrflow_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow_warnings ${ARG_DEPS})
endfunction()

# vrflow_add_test(NAME SOURCES ... DEPS ... LABELS ... [RUN_SERIAL]): one GoogleTest executable,
# registered with CTest test by test, with the given labels.
function(vrflow_add_test name)
  cmake_parse_arguments(ARG "RUN_SERIAL" "TIMEOUT;PREFIX;RESOURCE_LOCK" "SOURCES;DEPS;LABELS"
                        ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow_warnings ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  # Tests find the commands beside their own executable (build/bin) and the sources here.
  target_compile_definitions(${name} PRIVATE VRFLOW_TEST_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  # PREFIX names a second build of the same tests apart from the first ("PREFIX.Suite.Test").
  # The runs the tests start keep their records and logs in the build, not in the user's home
  # (docs/operations.md).
  # RESOURCE_LOCK names something tests share (an X display number): ctest -j never runs two
  # tests holding the same lock at once.
  set(exclusive "")
  if(ARG_RESOURCE_LOCK)
    set(exclusive RESOURCE_LOCK ${ARG_RESOURCE_LOCK})
  endif()
  # RUN_SERIAL: ctest -j runs these tests alone (they watch state every run changes, such as
  # what a run's start clears from /dev/shm).
  if(ARG_RUN_SERIAL)
    list(APPEND exclusive RUN_SERIAL ON)
  endif()
  gtest_discover_tests(${name}
    TEST_PREFIX "${ARG_PREFIX}"
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
      ENVIRONMENT "XDG_STATE_HOME=${PROJECT_BINARY_DIR}/test-state" ${exclusive}
    DISCOVERY_TIMEOUT 60)
endfunction()

# vrflow_require(FOUND_VAR WHAT PACKAGES OPTION): stops the configuration when a dependency of a
# part that is switched on was not found, naming the Debian packages and the option that turns
# the part off (the build never drops a part silently).
function(vrflow_require found what packages option)
  if(NOT ${found})
    message(FATAL_ERROR "${what} was not found (Debian: ${packages}); install it (make deps) "
                        "or configure with -D${option}=OFF")
  endif()
endfunction()
