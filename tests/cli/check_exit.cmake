# Runs one command and checks its exit code, and optionally its output and files.
#
#   cmake [-DEXPECT_EXIT=N]              exit code expected (default 0)
#         [-DSTDERR_REGEX=RE]            stderr must match RE
#         [-DSTDOUT_REGEX=RE]            stdout must match RE
#         [-DSTDERR_NOT_REGEX=RE]        stderr must not match RE
#         [-DMAKE_DIRECTORY=DIR]         create DIR (and parents) first
#         [-DREMOVE=PATH]                remove PATH (file or folder) first
#         [-DEXPECT_EXISTS=P1|P2|...]    these paths must exist afterwards
#         [-DEXPECT_ABSENT=P1|P2|...]    these paths must not exist afterwards
#         -P check_exit.cmake -- COMMAND [ARGS...]
#
# A command killed by a signal (a crash) never passes. On failure the script
# prints the command, its exit code, stdout and stderr, and exits non-zero.

set(command "")
set(after_separator FALSE)
math(EXPR last "${CMAKE_ARGC} - 1")
foreach(i RANGE 0 ${last})
  if(after_separator)
    list(APPEND command "${CMAKE_ARGV${i}}")
  elseif("${CMAKE_ARGV${i}}" STREQUAL "--")
    set(after_separator TRUE)
  endif()
endforeach()
if(NOT command)
  message(FATAL_ERROR "check_exit.cmake: no command given (expected: -P check_exit.cmake -- COMMAND ARGS...)")
endif()
if(NOT DEFINED EXPECT_EXIT)
  set(EXPECT_EXIT 0)
endif()

if(DEFINED REMOVE AND NOT REMOVE STREQUAL "")
  file(REMOVE_RECURSE "${REMOVE}")
endif()
if(DEFINED MAKE_DIRECTORY AND NOT MAKE_DIRECTORY STREQUAL "")
  file(MAKE_DIRECTORY "${MAKE_DIRECTORY}")
endif()

execute_process(COMMAND ${command}
                RESULT_VARIABLE rc
                OUTPUT_VARIABLE out
                ERROR_VARIABLE err)

list(JOIN command " " shown)
set(problems "")
if(NOT "${rc}" STREQUAL "${EXPECT_EXIT}")
  string(APPEND problems "  exit code ${rc}, expected ${EXPECT_EXIT}\n")
endif()
if(DEFINED STDERR_REGEX AND NOT err MATCHES "${STDERR_REGEX}")
  string(APPEND problems "  stderr does not match '${STDERR_REGEX}'\n")
endif()
if(DEFINED STDOUT_REGEX AND NOT out MATCHES "${STDOUT_REGEX}")
  string(APPEND problems "  stdout does not match '${STDOUT_REGEX}'\n")
endif()
if(DEFINED STDERR_NOT_REGEX AND err MATCHES "${STDERR_NOT_REGEX}")
  string(APPEND problems "  stderr matches '${STDERR_NOT_REGEX}'\n")
endif()
if(DEFINED EXPECT_EXISTS)
  string(REPLACE "|" ";" paths "${EXPECT_EXISTS}")
  foreach(p IN LISTS paths)
    if(NOT EXISTS "${p}")
      string(APPEND problems "  missing output ${p}\n")
    endif()
  endforeach()
endif()
if(DEFINED EXPECT_ABSENT)
  string(REPLACE "|" ";" paths "${EXPECT_ABSENT}")
  foreach(p IN LISTS paths)
    if(EXISTS "${p}")
      string(APPEND problems "  ${p} exists but should not\n")
    endif()
  endforeach()
endif()

if(problems)
  message(FATAL_ERROR "command: ${shown}\n${problems}--- stdout ---\n${out}--- stderr ---\n${err}")
endif()
message(STATUS "ok (exit ${rc}): ${shown}")
