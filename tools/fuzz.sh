#!/usr/bin/env bash
# Fuzzes the readers of untrusted input with libFuzzer (clang, AddressSanitizer and
# UndefinedBehaviorSanitizer): the glTF loader, the OBJ loader, the .vdb reader and
# the image decoders (tests/fuzz/). Builds the targets into build-fuzz/, makes the seed corpus
# (tests/fuzz/seeds/, the scenes of data/, small bakes made with build/tools/lightoctree)
# and runs each target for SECONDS (default 60). A finding (crash, sanitizer report,
# an exception other than InputError, timeout, out of memory) fails the script and
# leaves its input in out/fuzz/findings/. Prints executions per target and writes
# them to out/fuzz/summary.md. Run `tools/build.sh` first (the seeds need the CLI).
#   tools/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
out=out/fuzz

CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DLO_FUZZ=ON -DLO_BUILD_TESTS=OFF -DLO_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz --parallel "$(nproc)" --target fuzz_gltf fuzz_obj fuzz_vdb fuzz_image

rm -rf "$out/seeds" "$out/findings"
mkdir -p "$out/findings"
for t in gltf obj vdb image; do mkdir -p "$out/seeds/$t" "$out/corpus/$t" "$out/tmp/$t"; done
cp tests/fuzz/seeds/gltf/* data/*.gltf "$out/seeds/gltf/"
cp tests/fuzz/seeds/obj/* "$out/seeds/obj/"
cp tests/fuzz/seeds/image/* data/*.hdr "$out/seeds/image/"
L=build/tools/lightoctree
"$L" bake data/cornell-box.gltf -o "$out/seeds/vdb/d2.vdb" --depth 2 --photons 2000 --knn 20 \
  --photon-map "$out/seeds/vdb/photons.vdb" --quiet
"$L" bake data/cornell-box.gltf -o "$out/seeds/vdb/d2-sh1.vdb" --depth 2 --photons 2000 --knn 20 \
  --representation sh1 --quiet
"$L" reference data/cornell-box.gltf -o "$out/seeds/image/cornell.exr" --width 8 --height 6 --spp 1 --quiet
"$L" convert "$out/seeds/vdb/d2.vdb" -o "$out/seeds/vdb/d2-half.vdb" --half --quiet 2>/dev/null ||
  "$L" convert "$out/seeds/vdb/d2.vdb" -o "$out/seeds/vdb/d2-half.vdb" --half >/dev/null

summary="$out/summary.md"
{
  echo "| target | seconds | executions | executions/s | corpus | findings |"
  echo "|---|---:|---:|---:|---:|---:|"
} > "$summary"
status=0
for t in gltf obj vdb image; do
  case $t in gltf) maxlen=16384 ;; obj) maxlen=4096 ;; vdb) maxlen=65536 ;; image) maxlen=16384 ;; esac
  log="$out/$t.log"
  echo "== fuzz_$t for ${seconds} s"
  set +e
  # A damaged .vdb that makes OpenVDB loop is refused at the readers' time
  # limit (10 s per try, docs/robustness.md), twice per input (readVdlGrid,
  # inspect): a slow unit up to the libFuzzer time-out is that limit working;
  # past it, the time-out is a finding.
  TMPDIR="$out/tmp/$t" ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
    "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=60 \
    -report_slow_units=60 -rss_limit_mb=4096 \
    -max_len="$maxlen" -detect_leaks=0 -print_final_stats=1 \
    -artifact_prefix="$out/findings/$t-" "$out/corpus/$t" "$out/seeds/$t" > "$log" 2>&1
  code=$?
  set -e
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  corpus=$(ls "$out/corpus/$t" | wc -l)
  findings=$(ls "$out/findings" | grep -c "^$t-" || true)
  rate=$(awk -v r="${runs:-0}" -v s="$seconds" 'BEGIN { printf "%.0f", r / s }')
  echo "| fuzz_$t | $seconds | ${runs:-?} | $rate | $corpus | $findings |" >> "$summary"
  if [ "$code" -ne 0 ] || [ "$findings" -ne 0 ]; then
    echo "fuzz_$t: finding (exit $code); see $log and $out/findings/" >&2
    tail -40 "$log" >&2
    status=1
  fi
done
cat "$summary"
exit $status
