#!/usr/bin/env bash
# Names and side files (docs/robustness.md, family 7 of the third hardening
# list): non-UTF-8 paths in JSON reports, output names up to the file
# system's limit, and a side file that fails after the .vdb was written.
# Usage: hostile_names.sh LIGHTOCTREE SCENE WORKDIR
set -u
cli=$1 scene=$2 dir=$3
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
quick=(--depth 3 --photons 20000 --quiet)

# 1. A folder whose name is not UTF-8: the JSON reports are written, valid
#    JSON, with the bytes replaced (U+FFFD), and the .vdb beside them.
odd=$(printf 'odd-\xff\xfe')
mkdir "$odd"
"$cli" bake "$scene" -o "$odd/a.vdb" --stats-json "$odd/a.json" "${quick[@]}" || fail "bake into a non-UTF-8 folder"
python3 -c 'import json, os, sys; d = json.load(open(os.fsencode(sys.argv[1]), "rb")); assert d["output"].startswith("odd-\ufffd"), d["output"]' \
  "$odd/a.json" || fail "--stats-json under a non-UTF-8 path is not valid JSON naming the output"
"$cli" reference "$scene" -o "$odd/r.exr" --width 16 --height 12 --spp 2 --quiet || fail "reference into a non-UTF-8 folder"
"$cli" compare "$odd/r.exr" "$odd/r.exr" --json "$odd/c.json" > /dev/null || fail "compare --json under a non-UTF-8 path"
python3 -c 'import json, os, sys; json.load(open(os.fsencode(sys.argv[1]), "rb"))' "$odd/c.json" ||
  fail "compare --json under a non-UTF-8 path is not valid JSON"

# 2. Output names of 250 and 255 bytes (the OS takes them) are written; 256
#    is refused at once, before the bake.
for length in 250 255; do
  name=$(printf 'n%.0s' $(seq 1 $((length - 4)))).vdb
  "$cli" bake "$scene" -o "$name" "${quick[@]}" || fail "an output name of $length bytes"
  [ -f "$name" ] || fail "no file of $length bytes"
done
name=$(printf 'n%.0s' $(seq 1 252)).vdb
msg=$("$cli" bake "$scene" -o "$name" --depth 7 --photons 2000000 2>&1)
rc=$?
[ "$rc" -eq 2 ] || [ "$rc" -eq 1 ] || fail "a 256-byte name: exit $rc"
echo "$msg" | grep -q "is 256 bytes long" || fail "a 256-byte name: '$msg'"
# Refused before any work: the error is all the command said (no stage, no progress).
[ "$(echo "$msg" | wc -l)" -eq 1 ] || fail "a 256-byte name: work was done before the refusal: '$msg'"
ls -A | grep -q '\.tmp$' && fail "temporary files left: $(ls -A | grep '\.tmp$')"

# 3. A side file that cannot be written (the file size limit lets the .vdb
#    through but not the larger photon map): the old .vdb stays, nothing new
#    appears, exit 1.
"$cli" bake "$scene" -o out.vdb --depth 3 --photons 60000 --quiet || fail "the first bake"
before=$(cksum < out.vdb)
(trap '' XFSZ; ulimit -f 1000; "$cli" bake "$scene" -o out.vdb --depth 3 --photons 60000 --seed 7 --quiet \
  --photon-map pm.vdb --stats-json s.json)
rc=$?
[ "$rc" -eq 1 ] || fail "a photon map beyond the file size limit: exit $rc, expected 1"
[ "$(cksum < out.vdb)" = "$before" ] || fail "out.vdb was replaced although its photon map failed"
[ -e pm.vdb ] || [ -e s.json ] && fail "a side file of the failed set appeared"
ls -A | grep -q '\.tmp$' && fail "temporary files left: $(ls -A | grep '\.tmp$')"

# 4. A file name with a newline and a terminal escape that does not exist:
#    the parser's own "File does not exist" quotes it escaped, as every other
#    error (it turned the terminal red).
odd=$(printf 'a\nb\033[31m.gltf')
msg=$("$cli" bake "$odd" -o x.vdb --quiet 2>&1)
rc=$?
[ "$rc" -eq 2 ] || fail "a missing scene with control characters: exit $rc"
printf '%s' "$msg" | grep -qF 'File does not exist: a\x0ab\x1b[31m.gltf' ||
  fail "the parser's message does not escape the name: '$(printf '%s' "$msg" | od -c | head -3)'"
printf '%s' "$msg" | grep -q "$(printf '\033')" && fail "a raw escape reached the terminal"
[ "$(printf '%s\n' "$msg" | wc -l)" -eq 2 ] || fail "the name's newline reached the terminal: '$msg'"

# 9. Inputs and output folders that are not what they are named as: each
#    refused with its own reason (CLI11 said "File does not exist" of a loop
#    of links, and an output folder that is a file "does not exist", H14-2-1).
echo x > afile
ln -s loop loop
ln -s /nonexistent/target dangling
mkdir -p afolder
for probe in "render loop|'loop' is a loop of symbolic links" \
             "render dangling|'dangling' is a symbolic link to nothing" \
             "render afolder|'afolder' is a folder, not a file"; do
  input=${probe%%|*} expected=${probe#*|}
  msg=$("$cli" ${input% *} "${input#* }" -o out.exr 2>&1)
  rc=$?
  [ "$rc" -eq 2 ] && grep -qF "$expected" <<<"$msg" || fail "${input}: exit $rc: $msg"
done
msg=$("$cli" reference "$scene" -o afile/o.exr --width 8 --height 8 --spp 1 2>&1)
rc=$?
[ "$rc" -eq 1 ] && grep -qF "folder 'afile' is a file, not a folder" <<<"$msg" ||
  fail "an output folder that is a file: exit $rc: $msg"

[ "$failures" -eq 0 ] && echo "hostile names: all checks passed" || exit 1
