# vrflow/base/version.hpp (kVersion, versionText(), versionLine()) is generated from the project's
# version into the build tree; the `git describe` part is refreshed at every build by
# version_git.cmake into a private header that only src/base/version.cpp includes.
set(vrflow_generated_include ${PROJECT_BINARY_DIR}/generated/include)
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/src/base/version.hpp.in
  ${vrflow_generated_include}/vrflow/base/version.hpp @ONLY)
set(vrflow_version_git_header ${PROJECT_BINARY_DIR}/generated/private/vrflow_version_git.hpp)
add_custom_target(vrflow_version_git
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DOUT=${vrflow_version_git_header}
    -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/version_git.cmake
  BYPRODUCTS ${vrflow_version_git_header}
  COMMENT "vrflow version: git describe"
  VERBATIM)

# Every program that links vrflow::module answers `--version` (src/base/version.cpp, docs/report.md
# "Versions").
target_sources(vrflow_module PRIVATE src/base/version.cpp)
target_include_directories(vrflow_module
  PUBLIC $<BUILD_INTERFACE:${vrflow_generated_include}>
  PRIVATE ${PROJECT_BINARY_DIR}/generated/private)
add_dependencies(vrflow_module vrflow_version_git)
