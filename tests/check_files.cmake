# cmake -DFILES=a;b -DABSENT=c -P check_files.cmake: every FILES entry exists and
# is not empty, and ABSENT does not exist.
foreach(f ${FILES})
  if(NOT EXISTS "${f}")
    message(FATAL_ERROR "expected output missing: ${f}")
  endif()
  file(SIZE "${f}" size)
  if(size EQUAL 0)
    message(FATAL_ERROR "expected output is empty: ${f}")
  endif()
endforeach()
if(ABSENT AND EXISTS "${ABSENT}")
  message(FATAL_ERROR "file should not exist: ${ABSENT}")
endif()
