# `cmake --install build --prefix P` (and `make install PREFIX=P`) puts the Python package
# vrflow into the interpreter's package folder under P: with Debian's python3 (it has the
# deb_system scheme) P/lib/python3/dist-packages/vrflow, which Debian's interpreter searches
# when P is /usr (the .deb); with another interpreter its posix_prefix purelib,
# P/lib/python3.X/site-packages/vrflow. VRFLOW_PYTHON_INSTALL_DIR, relative to the prefix,
# names another folder. The installed package
# finds P/bin (its programs) through _layout.py, relative, so the tree stays relocatable.
if(NOT VRFLOW_PYTHON_INSTALL_DIR)
  execute_process(
    COMMAND ${Python3_EXECUTABLE} -c
      "import sysconfig; s = 'deb_system' if 'deb_system' in sysconfig.get_scheme_names() else 'posix_prefix'; print(sysconfig.get_path('purelib', s, vars={'base': '', 'platbase': ''}).lstrip('/'))"
    OUTPUT_VARIABLE vrflow_python_site OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
  set(VRFLOW_PYTHON_INSTALL_DIR ${vrflow_python_site} CACHE STRING
    "Folder of the Python package vrflow in an installed tree, relative to the prefix")
endif()
if(IS_ABSOLUTE "${VRFLOW_PYTHON_INSTALL_DIR}")
  message(FATAL_ERROR "VRFLOW_PYTHON_INSTALL_DIR must be relative to the prefix, got ${VRFLOW_PYTHON_INSTALL_DIR}")
endif()
set(vrflow_python_dest ${VRFLOW_PYTHON_INSTALL_DIR}/vrflow)

install(DIRECTORY ${VRFLOW_PYTHON_PACKAGE_DIR}/ DESTINATION ${vrflow_python_dest}
  FILES_MATCHING PATTERN "*.py"
  PATTERN "__pycache__" EXCLUDE
  PATTERN "_layout.py" EXCLUDE)
file(RELATIVE_PATH vrflow_python_bin /prefix/${vrflow_python_dest} /prefix/bin)
file(RELATIVE_PATH vrflow_python_lib /prefix/${vrflow_python_dest} /prefix/lib)
file(WRITE ${PROJECT_BINARY_DIR}/python/install/_layout.py
  "# Written by CMake: where vrflow's programs are, from this folder.\nBIN_DIR = \"${vrflow_python_bin}\"\n")
install(FILES ${PROJECT_BINARY_DIR}/python/install/_layout.py DESTINATION ${vrflow_python_dest})

# Every extension of the package (vrflow._app, ...), with an RPATH to the installed libraries.
get_property(vrflow_python_extensions GLOBAL PROPERTY VRFLOW_PYTHON_EXTENSIONS)
foreach(extension IN LISTS vrflow_python_extensions)
  set_target_properties(${extension} PROPERTIES INSTALL_RPATH "$ORIGIN/${vrflow_python_lib}")
  install(TARGETS ${extension} LIBRARY DESTINATION ${vrflow_python_dest})
endforeach()
