# What `cmake --install` puts in a prefix besides the targets (whose rules sit beside them): the
# public headers, the schemas, the CMake package and the pkg-config files, and the Debian package
# settings of `cpack -G DEB`. The layout is fixed (bin/, lib/, include/, share/vrflow/), not
# GNUInstallDirs': the programs find their libraries through $ORIGIN/../lib and what ships with
# them through <bin>/../share/vrflow and <bin>/../lib/vrflow, so the tree is relocatable
# (docs/install.md).
include(CMakePackageConfigHelpers)

# The public headers: the module SDK and the filter SDK (docs/architecture.md, "The ABI of what
# outside code links"). A header of those layers is public unless its top comment says it is
# internal to vrflow; the headers of net/, run/ and launcher/ are never installed.
set(vrflow_sdk_folders base message ipc module app daemon)
set(vrflow_include_root ${PROJECT_SOURCE_DIR}/runtime/include)
foreach(folder IN LISTS vrflow_sdk_folders)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE ${vrflow_include_root}
    ${vrflow_include_root}/vrflow/${folder}/*.hpp)
  foreach(header IN LISTS headers)
    file(STRINGS ${vrflow_include_root}/${header} top LIMIT_COUNT 12)
    if(top MATCHES "[Ii]nternal to vrflow")
      continue()
    endif()
    cmake_path(GET header PARENT_PATH header_folder)
    install(FILES ${vrflow_include_root}/${header} DESTINATION include/${header_folder})
  endforeach()
endforeach()

# The schemas of the files vrflow reads and writes (XSDs and JSON Schemas).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/runtime/schema/ DESTINATION share/vrflow/schema
  FILES_MATCHING PATTERN "*.xsd" PATTERN "*.json")

# find_package(vrflow): the exported layers and the package functions (vrflow_package.cmake).
install(EXPORT vrflowTargets NAMESPACE vrflow:: DESTINATION lib/cmake/vrflow)
set(VRFLOW_INSTALL_LIBDIR lib)
set(VRFLOW_INSTALL_SCHEMADIR share/vrflow/schema)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vrflowConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/vrflowConfig.cmake INSTALL_DESTINATION lib/cmake/vrflow
  PATH_VARS VRFLOW_INSTALL_LIBDIR VRFLOW_INSTALL_SCHEMADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/vrflowConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/vrflowConfig.cmake
  ${PROJECT_BINARY_DIR}/cmake/vrflowConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/vrflow_package.cmake ${PROJECT_SOURCE_DIR}/cmake/vrflow_check_package.cmake
  DESTINATION lib/cmake/vrflow)

# pkg-config: vrflow (a module) and vrflow-filter (a filter plugin); both relocatable.
foreach(pc vrflow vrflow-filter)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/cmake/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/cmake/${pc}.pc DESTINATION lib/pkgconfig)
endforeach()

include(vrflow_deb)
