# cmake -DPACKAGE=name -DMANIFEST=file -DOUTPUT=file -DSCHEMA=xsd -DXMLLINT=program
#       -DEXECUTABLES=a;b -P vrflow_check_package.cmake
# The build-time check of vrflow_add_package (vrflow_package.cmake): the manifest is valid against
# the package schema, declares package PACKAGE, and names as executables only files the package
# builds (EXECUTABLES, bare names); then it is copied to OUTPUT. Each error names file:line.
cmake_minimum_required(VERSION 3.25)

# Errors go to stderr as written (FATAL_ERROR would rewrap them), then the build stops.
function(fail text)
  message(NOTICE "${text}")
  message(FATAL_ERROR "package '${PACKAGE}': its manifest ${MANIFEST} is not right (above)")
endfunction()

if(XMLLINT AND SCHEMA)
  execute_process(COMMAND ${XMLLINT} --noout --schema ${SCHEMA} ${MANIFEST}
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    fail("${err}${MANIFEST}: error: not a valid vrflow package manifest (schema ${SCHEMA})")
  endif()
endif()

file(READ ${MANIFEST} text)

# The 1-based line of `offset` in `text`.
function(line_of offset out)
  string(SUBSTRING "${text}" 0 ${offset} before)
  string(REGEX MATCHALL "\n" newlines "${before}")
  list(LENGTH newlines count)
  math(EXPR line "${count} + 1")
  set(${out} ${line} PARENT_SCOPE)
endfunction()

set(errors "")
string(FIND "${text}" "<package" start)
if(start EQUAL -1 OR NOT text MATCHES "<package[ \t\r\n][^>]*name=\"([^\"]*)\"")
  fail("${MANIFEST}:1: error: no <package name=\"...\"> element")
endif()
if(NOT CMAKE_MATCH_1 STREQUAL PACKAGE)
  line_of(${start} line)
  string(APPEND errors "${MANIFEST}:${line}: error: the manifest declares package "
         "'${CMAKE_MATCH_1}', but vrflow_add_package names it '${PACKAGE}'\n")
endif()

set(rest "${text}")
set(consumed 0)
while(TRUE)
  string(FIND "${rest}" "executable=\"" at)
  if(at EQUAL -1)
    break()
  endif()
  math(EXPR value_at "${at} + 12")
  string(SUBSTRING "${rest}" ${value_at} -1 rest)
  string(FIND "${rest}" "\"" value_end)
  string(SUBSTRING "${rest}" 0 ${value_end} executable)
  math(EXPR offset "${consumed} + ${at}")
  math(EXPR consumed "${consumed} + ${value_at}")
  if(NOT executable IN_LIST EXECUTABLES)
    line_of(${offset} line)
    if(EXECUTABLES)
      string(REPLACE ";" ", " built "${EXECUTABLES}")
    else()
      set(built "nothing: give vrflow_add_package(${PACKAGE} ... MODULES target...)")
    endif()
    string(APPEND errors "${MANIFEST}:${line}: error: executable '${executable}' is not built by "
           "package '${PACKAGE}' (its MODULES build: ${built})\n")
  endif()
endwhile()

if(errors)
  fail("${errors}")
endif()
configure_file(${MANIFEST} ${OUTPUT} COPYONLY)
