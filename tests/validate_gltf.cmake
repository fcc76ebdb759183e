# cmake -DNODE=node -DSCRIPT=validate_gltf.mjs -DMODULES=dir -DFILES=a.glb;b.gltf
#       -P validate_gltf.cmake
# Runs the Khronos glTF validator (tests/validate_gltf.mjs) on FILES and
# passes when none has an error. Node.js or the validator missing is a
# failure, not a skip: CI installs both (tools/setup.sh).
if(NOT NODE OR NODE MATCHES "NOTFOUND$")
  message(FATAL_ERROR "Node.js (node) was not found when cmake configured the build: "
                      "run tools/setup.sh, then configure again")
endif()
if(NOT EXISTS "${MODULES}/gltf-validator/package.json")
  message(FATAL_ERROR "the glTF validator is not installed (${MODULES}/gltf-validator): "
                      "run tools/setup.sh")
endif()
execute_process(COMMAND "${NODE}" "${SCRIPT}" --modules "${MODULES}" ${FILES}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glTF validation failed (exit ${rc})")
endif()
