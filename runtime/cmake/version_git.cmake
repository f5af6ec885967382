# Run at build time (cmake -P) by the target vrflow_version_git: writes OUT, a header defining
# VRFLOW_GIT_DESCRIBE as `git describe --always --dirty --tags` of SOURCE_DIR (empty outside a
# git checkout or without git), and touches it only when the text changed, so that a build at
# the same commit recompiles nothing.
find_program(GIT_EXECUTABLE git)
set(describe "")
if(GIT_EXECUTABLE)
  execute_process(COMMAND ${GIT_EXECUTABLE} describe --always --dirty --tags
    WORKING_DIRECTORY ${SOURCE_DIR} OUTPUT_VARIABLE describe RESULT_VARIABLE failed
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(failed)
    set(describe "")
  endif()
endif()
set(text "#define VRFLOW_GIT_DESCRIBE \"${describe}\"\n")
set(old "")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
