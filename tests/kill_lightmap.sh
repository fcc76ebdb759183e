#!/usr/bin/env bash
# Kill safety of a multi-file output (docs/robustness.md): a lightmap export
# (glTF, .bin, five pages, five chart images, preview: 13 files) replacing an
# earlier one-page set is killed (SIGINT, SIGTERM, SIGKILL) at set moments:
# while tracing, after the 1st, 7th and 13th file of the set is written (the
# test hook LIGHTOCTREE_PAUSE_SET, with LIGHTOCTREE_TEST_HOOKS=1, pauses
# there), and in the middle of the renames. Afterwards the files are the old set or the new set, whole: never
# a mix, never a page without its glTF; after SIGINT and SIGTERM no temporary
# file. A signal that arrives during the renames waits for them (the new set).
# Usage: kill_lightmap.sh LIGHTOCTREE SCENE WORKDIR
set -u
set -m  # job control: a background job gets SIGINT (without it, bash ignores it there)
cli=$1 scene=$2 dir=$3
rm -rf "$dir" && mkdir -p "$dir" || exit 1
"$cli" bake "$scene" -o "$dir/grid.vdb" --depth 5 --photons 50000 --quiet || exit 1
old=(--texel-size 0.004 --content indirect --preview-unlit --chart-image --quiet)
new=(--texel-size 0.004 --atlas 256 --content full --direct-samples 16 --preview-unlit --chart-image --quiet)
sums() { (cd "$1" && for f in lm*; do echo "$f $(cksum < "$f")"; done); }
mkdir "$dir/old" "$dir/new"
"$cli" lightmap "$scene" "$dir/grid.vdb" -o "$dir/old/lm.gltf" "${old[@]}" || exit 1
"$cli" lightmap "$scene" "$dir/grid.vdb" -o "$dir/new/lm.gltf" "${new[@]}" || exit 1
old_sums=$(sums "$dir/old") new_sums=$(sums "$dir/new")
n_new=$(ls "$dir/new" | wc -l)
echo "old set: $(ls "$dir/old" | wc -l) files; new set: $n_new files"
[ "$n_new" -ge 8 ] || { echo "the new set should have many files"; exit 1; }
out="$dir/run"
failures=0
for sig in INT TERM KILL; do
  for moment in trace add:1 add:7 "add:$n_new" commit; do
    [ "$sig" = KILL ] && [ "$moment" = commit ] && continue  # SIGKILL cannot wait: the one window left
    rm -rf "$out" && cp -r "$dir/old" "$out"
    pause=$moment
    [ "$moment" = trace ] && pause=none
    # Emptied here, not only by the child's redirection: the loop below may
    # read the file before the child has opened it, and must not find the
    # previous run's pause there.
    : > "$dir/stderr"
    LIGHTOCTREE_TEST_HOOKS=1 LIGHTOCTREE_PAUSE_SET=$pause "$cli" lightmap "$scene" "$dir/grid.vdb" -o "$out/lm.gltf" "${new[@]}" \
      2> "$dir/stderr" &
    pid=$!
    if [ "$moment" = trace ]; then
      sleep 0.3
    else
      # Wait for the pause as long as the export runs (a loaded machine may
      # take minutes to trace), up to 5 minutes.
      for _ in $(seq 1 3000); do
        grep -q "paused at .*PAUSE_SET)" "$dir/stderr" && break  # the whole line
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
      done
      if ! grep -q "paused at $moment" "$dir/stderr"; then
        echo "SIG$sig at $moment: never paused; the export's messages:"
        sed 's/^/  | /' "$dir/stderr"
        failures=$((failures + 1))
      fi
    fi
    # A machine fast enough to finish the export within the 0.3 s of the
    # "trace" moment leaves nothing to kill: the new set, whole, is right then.
    finished=0
    kill -0 "$pid" 2>/dev/null || finished=1
    kill -s "$sig" "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    leftovers=$(ls -A "$out" | grep -c '\.tmp$')
    state=$(sums "$out" | grep -v '\.tmp ')
    expected=old
    [ "$moment" = commit ] && expected=new
    if [ "$finished" -eq 1 ]; then
      echo "SIG$sig at $moment: the export finished before the signal (nothing to kill)"
      expected=new
    fi
    if [ "$state" = "$old_sums" ]; then
      what=old
    elif [ "$state" = "$new_sums" ]; then
      what=new
    else
      what=mixed
      echo "$state"
    fi
    if [ "$what" != "$expected" ]; then
      echo "SIG$sig at $moment: FAILED: the $what set, expected the $expected one"
      failures=$((failures + 1))
    fi
    if [ "$sig" != KILL ] && [ "$leftovers" -ne 0 ]; then
      echo "SIG$sig at $moment: FAILED: $leftovers temporary file(s) left"
      failures=$((failures + 1))
    fi
    echo "SIG$sig at $moment: the $what set; $leftovers temporary file(s)"
  done
done
[ "$failures" -eq 0 ] && echo "kill safety: every run left one whole set" || exit 1
