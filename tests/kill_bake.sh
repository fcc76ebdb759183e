#!/usr/bin/env bash
# Kill safety (docs/robustness.md): a bake that replaces an existing OUT.vdb
# is killed (SIGINT, SIGTERM, SIGKILL) at several moments. Afterwards OUT.vdb
# is either the old file or the new one, complete (inspect passes); after
# SIGINT and SIGTERM no temporary file is left beside it.
# Usage: kill_bake.sh LIGHTOCTREE SCENE WORKDIR
set -u
set -m  # job control: a background bake gets SIGINT (without it, bash ignores it there)
cli=$1 scene=$2 dir=$3
mkdir -p "$dir"
out="$dir/out.vdb"
"$cli" bake "$scene" -o "$dir/old.vdb" --depth 4 --photons 20000 --knn 40 --quiet || exit 1
old_sum=$(cksum < "$dir/old.vdb")
failures=0
for sig in INT TERM KILL; do
  for delay in 0.05 0.4 0.9 1.3 1.7 2.2; do
    cp "$dir/old.vdb" "$out"
    rm -f "$dir"/.out.vdb.*.tmp
    "$cli" bake "$scene" -o "$out" --depth 7 --photons 1200000 --quiet &
    pid=$!
    sleep "$delay"
    kill -s "$sig" "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    if ! "$cli" inspect "$out" > /dev/null 2>&1; then
      echo "SIG$sig after ${delay}s: $out is not a complete VDL file"
      failures=$((failures + 1))
    fi
    sum=$(cksum < "$out")
    if [ "$sum" = "$old_sum" ]; then state=old; else state=new; fi
    leftovers=$(ls -A "$dir" | grep -c '^\.out\.vdb\..*\.tmp$')
    if [ "$sig" != KILL ] && [ "$leftovers" -ne 0 ]; then
      echo "SIG$sig after ${delay}s: $leftovers temporary file(s) left"
      failures=$((failures + 1))
    fi
    echo "SIG$sig after ${delay}s: out.vdb is the $state file, complete; $leftovers temporary file(s)"
  done
done
[ "$failures" -eq 0 ] && echo "kill safety: all runs left a complete file" || exit 1
