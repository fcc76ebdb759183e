#!/usr/bin/env bash
# Set up, build and run the whole test suite (what CI runs): the release build's
# tests, the same suite built with AddressSanitizer and UndefinedBehaviorSanitizer,
# and the libFuzzer targets of the readers for 60 s each (docs/robustness.md).
set -euo pipefail
cd "$(dirname "$0")/.."
LO_SETUP_TESTS=1 bash tools/build.sh
# Tests in parallel, one per core (they write to their own folders).
(cd build && ctest --output-on-failure --timeout 600 --parallel "$(nproc)")

# The whole suite again under the sanitizers, in its own build folder; any
# report fails its test. Leak checking is off: OpenVDB, Mesa and TBB keep
# process-lifetime caches that LeakSanitizer would report. Tests labelled
# release-only (tests/CMakeLists.txt says which and why) run in the release
# pass above only.
# -O1 -g1: line tables for the reports' stacks, without the full debug
# information that made this build the longest step of CI.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLO_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DLO_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan --parallel "$(nproc)"
(cd build-asan && ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure --timeout 900 --parallel "$(nproc)" -LE release-only)

# Fuzzing: each libFuzzer target for 60 s; a finding fails the run.
bash tools/fuzz.sh 60
