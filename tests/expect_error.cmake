# cmake -DCLI=exe -DARGS=a|b|c -DREGEX=re -DNO_FILE=path -P expect_error.cmake
# Passes when the command exits with a non-zero code (not a crash), prints a
# message matching REGEX, and leaves no NO_FILE (nor NO_FILE.tmp) behind.
string(REPLACE "|" ";" args "${ARGS}")
file(REMOVE "${NO_FILE}" "${NO_FILE}.tmp")
execute_process(COMMAND "${CLI}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc MATCHES "^[0-9]+$")
  message(FATAL_ERROR "command crashed (${rc}): ${CLI} ${args}\n${out}${err}")
endif()
if(rc EQUAL 0)
  message(FATAL_ERROR "command succeeded but should have failed: ${CLI} ${args}\n${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "message does not match '${REGEX}':\n${out}${err}")
endif()
if(EXISTS "${NO_FILE}" OR EXISTS "${NO_FILE}.tmp")
  message(FATAL_ERROR "a failed run left ${NO_FILE} behind")
endif()
message(STATUS "exit ${rc}: ${err}")
