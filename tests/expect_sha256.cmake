# Fails unless FILE's SHA-256 is HASH. Used to pin the bytes of the default
# bake of the bundled Cornell box: a refactoring must not change them. When a
# change of the bake's output is intended, say so in the commit and put the
# new hash (printed below) in tests/CMakeLists.txt.
file(SHA256 "${FILE}" actual)
if(NOT actual STREQUAL HASH)
  message(FATAL_ERROR "${FILE}: SHA-256 ${actual}, expected ${HASH}: the bake's output bytes changed")
endif()
message(STATUS "${FILE}: SHA-256 ${actual} as expected")
