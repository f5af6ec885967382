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

# vrflow_add_library(NAME SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...] [INCLUDE dir])
function(vrflow_add_library name)
  cmake_parse_arguments(ARG "" "INCLUDE" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(vrflow_${name} STATIC ${ARG_SOURCES})
  add_library(vrflow::${name} ALIAS vrflow_${name})
  set_target_properties(vrflow_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON OUTPUT_NAME vrflow_${name})
  if(NOT ARG_INCLUDE)
    set(ARG_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  target_include_directories(vrflow_${name} PUBLIC ${ARG_INCLUDE} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(vrflow_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE vrflow_warnings ${ARG_PRIVATE_DEPS})
endfunction()

# vrflow_add_executable(NAME SOURCES ... [DEPS ...])
function(vrflow_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow_warnings ${ARG_DEPS})
endfunction()

# vrflow_add_test(NAME SOURCES ... DEPS ... LABELS ...): one GoogleTest executable, registered
# with CTest test by test, with the given labels.
function(vrflow_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow_warnings ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  # Tests find the commands beside their own executable (build/bin) and the sources here.
  target_compile_definitions(${name} PRIVATE VRFLOW_TEST_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  gtest_discover_tests(${name}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
endfunction()

# vrflow_install_package(NAME MANIFEST): puts a node package's manifest where the `vrflow`
# command finds it (<build>/share/vrflow/packages/NAME/); executables stay in <build>/bin.
function(vrflow_install_package name manifest)
  configure_file(${manifest} ${PROJECT_BINARY_DIR}/share/vrflow/packages/${name}/vrflow-package.xml COPYONLY)
endfunction()
