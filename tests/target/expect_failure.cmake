# cmake -DEXPECT_RC=<n> -DEXPECT_REGEX=<re> -P expect_failure.cmake -- <command...>
# Passes only when the command fails *in the expected way*: exit status EXPECT_RC and output
# matching EXPECT_REGEX. Plain WILL_FAIL would also pass on a crash, a timeout or a missing
# file, and so prove nothing about the check under test.
set(cmd "")
set(take OFF)
math(EXPR last "${CMAKE_ARGC} - 1")
foreach(i RANGE ${last})
  if(take)
    list(APPEND cmd "${CMAKE_ARGV${i}}")
  elseif(CMAKE_ARGV${i} STREQUAL "--")
    set(take ON)
  endif()
endforeach()
execute_process(COMMAND ${cmd} OUTPUT_VARIABLE out ERROR_VARIABLE out RESULT_VARIABLE rc)
message("${out}")
if(NOT rc STREQUAL "${EXPECT_RC}")
  message(FATAL_ERROR "expected exit status ${EXPECT_RC}, got '${rc}'")
endif()
if(NOT out MATCHES "${EXPECT_REGEX}")
  message(FATAL_ERROR "output does not match '${EXPECT_REGEX}'")
endif()
message(STATUS "failed as expected (status ${rc})")
