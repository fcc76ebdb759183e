# Fails unless FILE_A and FILE_B have the same SHA-256: the default bake of
# the bundled Cornell box must give the same bytes whatever the thread count.
# (Its bytes are not pinned to one hash: Embree picks its kernels by the CPU,
# and glibc its libm variants, so the bytes differ between machines; on one
# machine they never change with the thread count.)
file(SHA256 "${FILE_A}" a)
file(SHA256 "${FILE_B}" b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "${FILE_A}: SHA-256 ${a}\n${FILE_B}: SHA-256 ${b}\nthe bake's bytes depend on the thread count")
endif()
message(STATUS "${FILE_A} and ${FILE_B}: SHA-256 ${a}, equal")
