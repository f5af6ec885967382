# The node package SDK in CMake: build module executables and filter plugins, check a package's
# manifest at build time and put both where `vrflow` finds them, in the build tree and installed.
# The same file serves vrflow's own tree (nodes/, examples/), a project that adds vrflow as a
# subdirectory, and a project that finds an installed vrflow (find_package(vrflow)); see
# docs/install.md.
#
# The build tree of the calling project gets the layout of an installed tree (VRFLOW_LAYOUT_DIR,
# default CMAKE_BINARY_DIR): module executables in bin/, manifests in
# share/vrflow/<GROUP>/<NAME>/vrflow-package.xml, composites in share/vrflow/composites/, filter
# plugins in lib/vrflow/filters/. A manifest's bare executable names resolve against the bin/ of
# the layout it sits in (docs/application-format.md), so the package works from the build tree
# (`vrflow --packages <build>/share/vrflow/packages`) and from the install prefix alike.

# Where this file is, for the check script beside it (a global property: the functions are also
# called from projects above vrflow's own directory scope).
set_property(GLOBAL PROPERTY VRFLOW_PACKAGE_CMAKE_DIR ${CMAKE_CURRENT_LIST_DIR})
find_program(VRFLOW_XMLLINT xmllint)
if(NOT VRFLOW_XMLLINT)
  message(WARNING "xmllint was not found (Debian: libxml2-utils): vrflow_add_package checks "
                  "manifests without the package schema")
endif()

# The root of the calling project's build layout (bin/, lib/, share/vrflow/).
function(_vrflow_layout_dir out)
  if(DEFINED VRFLOW_LAYOUT_DIR)
    set(${out} ${VRFLOW_LAYOUT_DIR} PARENT_SCOPE)
  else()
    set(${out} ${CMAKE_BINARY_DIR} PARENT_SCOPE)
  endif()
endfunction()

# vrflow's own targets get vrflow's warning settings; a user's targets keep the user's.
function(_vrflow_own_settings target)
  get_property(own_source GLOBAL PROPERTY VRFLOW_OWN_SOURCE_DIR)
  if(own_source AND TARGET vrflow_warnings)
    cmake_path(IS_PREFIX own_source ${CMAKE_CURRENT_SOURCE_DIR} NORMALIZE inside)
    if(inside)
      target_link_libraries(${target} PRIVATE vrflow_warnings)
    endif()
  endif()
  # Installed where the installed vrflow's libraries are not beside it: find them by RPATH.
  if(DEFINED VRFLOW_LIBRARY_DIR)
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "$ORIGIN/../lib;${VRFLOW_LIBRARY_DIR}")
  endif()
endfunction()

# vrflow_add_module(NAME SOURCES ... [DEPS ...]): a module executable NAME, linked with
# vrflow::module (and DEPS), built into the layout's bin/. Name it in a package's manifest
# (executable="NAME") and list it in that package's vrflow_add_package(... MODULES NAME).
function(vrflow_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "vrflow_add_module(${name}): no SOURCES")
  endif()
  _vrflow_layout_dir(layout)
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow::module ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${layout}/bin)
  _vrflow_own_settings(${name})
endfunction()

# vrflow_add_package(NAME MANIFEST file MODULES target... [COMPOSITES file...] [GROUP folder]
#                    [NO_INSTALL]): the package NAME. At build time its manifest is checked
# against the package schema (xmllint) and for what it names: the package name must be NAME and
# each executable must be one of MODULES (built by vrflow_add_module); then it is copied to
# <layout>/share/vrflow/GROUP/NAME/vrflow-package.xml (GROUP: `packages` unless given). Building
# a module of MODULES checks and places the manifest first. COMPOSITES (NAME.vrc.xml files) go to
# <layout>/share/vrflow/composites/. Unless NO_INSTALL, `cmake --install` puts the manifest in
# <prefix>/share/vrflow/GROUP/NAME/, the executables in <prefix>/bin and the composites in
# <prefix>/share/vrflow/composites/, where the installed `vrflow` finds them.
function(vrflow_add_package name)
  cmake_parse_arguments(ARG "NO_INSTALL" "MANIFEST;GROUP" "MODULES;COMPOSITES" ${ARGN})
  if(NOT ARG_MANIFEST)
    message(FATAL_ERROR "vrflow_add_package(${name}): no MANIFEST")
  endif()
  if(NOT ARG_GROUP)
    set(ARG_GROUP packages)
  endif()
  cmake_path(ABSOLUTE_PATH ARG_MANIFEST BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
  _vrflow_layout_dir(layout)
  get_property(cmake_dir GLOBAL PROPERTY VRFLOW_PACKAGE_CMAKE_DIR)
  get_property(schema GLOBAL PROPERTY VRFLOW_PACKAGE_SCHEMA)
  set(placed ${layout}/share/vrflow/${ARG_GROUP}/${name}/vrflow-package.xml)
  set(executables "")
  foreach(module IN LISTS ARG_MODULES)
    list(APPEND executables "$<TARGET_FILE_NAME:${module}>")
  endforeach()
  add_custom_command(OUTPUT ${placed}
    COMMAND ${CMAKE_COMMAND} -DPACKAGE=${name} -DMANIFEST=${ARG_MANIFEST} -DOUTPUT=${placed}
      -DSCHEMA=${schema} -DXMLLINT=${VRFLOW_XMLLINT} "-DEXECUTABLES=${executables}"
      -P ${cmake_dir}/vrflow_check_package.cmake
    DEPENDS ${ARG_MANIFEST} ${schema} ${cmake_dir}/vrflow_check_package.cmake
    COMMENT "Checking the manifest of package ${name}"
    VERBATIM)
  set(composites "")
  foreach(file IN LISTS ARG_COMPOSITES)
    cmake_path(ABSOLUTE_PATH file BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
    cmake_path(GET file FILENAME file_name)
    set(copy ${layout}/share/vrflow/composites/${file_name})
    add_custom_command(OUTPUT ${copy} COMMAND ${CMAKE_COMMAND} -E copy ${file} ${copy}
      DEPENDS ${file} VERBATIM)
    list(APPEND composites ${copy})
  endforeach()
  add_custom_target(vrflow-package-${name} ALL DEPENDS ${placed} ${composites})
  foreach(module IN LISTS ARG_MODULES)
    add_dependencies(${module} vrflow-package-${name})
  endforeach()
  if(NOT ARG_NO_INSTALL)
    install(TARGETS ${ARG_MODULES} RUNTIME DESTINATION bin)
    install(FILES ${placed} DESTINATION share/vrflow/${ARG_GROUP}/${name})
    if(composites)
      install(FILES ${composites} DESTINATION share/vrflow/composites)
    endif()
  endif()
endfunction()

# vrflow_add_filter_plugin(NAME SOURCES ... [OUTPUT_DIRECTORY dir] [NO_INSTALL]): a filter
# plugin, a shared library that `vrflow` and `vrflow-daemon` load at run time. It links the filter
# SDK (vrflow::daemon, libvrflow_daemon.so), which the loading program links too: one copy of each
# registry. Built into <layout>/lib/vrflow/filters (or OUTPUT_DIRECTORY) and, unless NO_INSTALL,
# installed into <prefix>/lib/vrflow/filters: the folder beside bin/ where the programs look for
# the plugins that application files name.
function(vrflow_add_filter_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "OUTPUT_DIRECTORY" "SOURCES" ${ARGN})
  _vrflow_layout_dir(layout)
  if(NOT ARG_OUTPUT_DIRECTORY)
    set(ARG_OUTPUT_DIRECTORY ${layout}/lib/vrflow/filters)
  endif()
  add_library(${name} MODULE ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE vrflow::daemon)
  set_target_properties(${name} PROPERTIES PREFIX "lib" LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  _vrflow_own_settings(${name})
  if(NOT ARG_NO_INSTALL)
    install(TARGETS ${name} LIBRARY DESTINATION lib/vrflow/filters)
  endif()
endfunction()
