# cmake -DCLI=exe -DARGS=a|b|c -DREGEX=re -DNO_FILE=path -P expect_error.cmake
# Passes when the command exits with a non-zero code (not a crash), prints a
# message matching REGEX, and leaves no NO_FILE (nor a temporary file of it,
# .NAME.*.tmp beside it: core/file.h) behind.
string(REPLACE "|" ";" args "${ARGS}")
# -DMEMORY_LIMIT=bytes: run as on a machine with that much memory available.
if(MEMORY_LIMIT)
  set(ENV{LIGHTOCTREE_MEMORY_LIMIT} "${MEMORY_LIMIT}")
endif()
file(REMOVE "${NO_FILE}" "${NO_FILE}.tmp")
execute_process(COMMAND "${CLI}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc MATCHES "^[0-9]+$")
  message(FATAL_ERROR "command crashed (${rc}): ${CLI} ${args}\n${out}${err}")
endif()
if(rc EQUAL 0)
  message(FATAL_ERROR "command succeeded but should have failed: ${CLI} ${args}\n${out}${err}")
endif()
# -DRC=n: the exit status must be exactly n.
if(DEFINED RC AND NOT rc EQUAL RC)
  message(FATAL_ERROR "exit status ${rc}, expected ${RC}: ${CLI} ${args}\n${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "message does not match '${REGEX}':\n${out}${err}")
endif()
get_filename_component(no_dir "${NO_FILE}" DIRECTORY)
get_filename_component(no_name "${NO_FILE}" NAME)
file(GLOB leftovers "${no_dir}/.${no_name}.*.tmp")
if(EXISTS "${NO_FILE}" OR leftovers)
  message(FATAL_ERROR "a failed run left ${NO_FILE} ${leftovers} behind")
endif()
# -DKEEP=path -DKEEP_TEXT=text: a file the command must leave as it was.
if(KEEP)
  file(READ "${KEEP}" kept)
  if(NOT kept STREQUAL KEEP_TEXT)
    message(FATAL_ERROR "a failed run changed ${KEEP}: '${kept}'")
  endif()
endif()
message(STATUS "exit ${rc}: ${err}")
