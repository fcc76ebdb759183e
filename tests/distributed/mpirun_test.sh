#!/usr/bin/env bash
# The distributed bake under mpirun (localhost, oversubscribed): the .vdb
# bytes of `mpirun -np N lightoctree bake` equal those of the one-process
# bake for N = 1, 2, 3, 4, on the Cornell box and the dragon; a rank killed
# mid-bake makes mpirun exit non-zero and leaves no output file; ranks started
# with different settings or output names, or one whose scene is damaged,
# refuse together.
# Usage: mpirun_test.sh MPIEXEC LIGHTOCTREE SHARED_SCENES OUTPUT_DIR
set -euo pipefail
MPIEXEC=$1 CLI=$2 SCENES=$3 OUT=$4
rm -rf "$OUT" && mkdir -p "$OUT"
# OpenMPI refuses root unless told; CI containers run as root.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Containers often forbid the cross-process memory reads OpenMPI's shared-memory
# transport uses for large messages (ptrace scope): copy through the segment.
export OMPI_MCA_btl_vader_single_copy_mechanism=none
MPI=("$MPIEXEC" --oversubscribe --bind-to none)

failures=0
same_bytes() {  # name scene args...
  local name=$1 scene=$2
  shift 2
  "$CLI" bake "$scene" -o "$OUT/$name-single.vdb" -q "$@"
  for np in 1 2 3 4; do
    "${MPI[@]}" -np $np "$CLI" bake "$scene" -o "$OUT/$name-np$np.vdb" -q "$@"
    if cmp -s "$OUT/$name-single.vdb" "$OUT/$name-np$np.vdb"; then
      echo "ok: $name, $np ranks: the one-process bake's bytes"
    else
      echo "FAIL: $name, $np ranks: $OUT/$name-np$np.vdb differs from $OUT/$name-single.vdb"
      failures=$((failures + 1))
    fi
  done
}
same_bytes cornell "$SCENES/composed/cornell-box.glb" --depth 6 --photons 150000 --knn 100
same_bytes dragon "$SCENES/composed/cornell-dragon.glb" --depth 5 --photons 60000 --knn 60 --tiles 2

# A rank killed between the photon exchange and the gather (a lost machine).
set +e
LIGHTOCTREE_TEST_HOOKS=1 LIGHTOCTREE_KILL_RANK=1 "${MPI[@]}" -x LIGHTOCTREE_TEST_HOOKS \
  -x LIGHTOCTREE_KILL_RANK -np 2 "$CLI" bake \
  "$SCENES/composed/cornell-box.glb" -o "$OUT/killed.vdb" -q --depth 6 --photons 150000 \
  >"$OUT/killed.log" 2>&1
rc=$?
set -e
leftovers=$(find "$OUT" -name '.killed.vdb.*' | wc -l)
if [ $rc -ne 0 ] && [ ! -e "$OUT/killed.vdb" ] && [ "$leftovers" -eq 0 ]; then
  echo "ok: a killed rank: mpirun exits $rc, no output file"
else
  echo "FAIL: a killed rank: mpirun exited $rc; output file present: $([ -e "$OUT/killed.vdb" ] && echo yes || echo no), temporary files: $leftovers"
  cat "$OUT/killed.log"
  failures=$((failures + 1))
fi
# The hook alone, left in a job script's environment, kills no rank (H16-3-1).
set +e
LIGHTOCTREE_KILL_RANK=1 "${MPI[@]}" -x LIGHTOCTREE_KILL_RANK -np 2 "$CLI" bake \
  "$SCENES/composed/cornell-box.glb" -o "$OUT/unkilled.vdb" -q --depth 4 --photons 20000 \
  >"$OUT/unkilled.log" 2>&1
rc=$?
set -e
if [ $rc -eq 0 ] && [ -e "$OUT/unkilled.vdb" ]; then
  echo "ok: LIGHTOCTREE_KILL_RANK without LIGHTOCTREE_TEST_HOOKS=1 kills no rank"
else
  echo "FAIL: LIGHTOCTREE_KILL_RANK alone: mpirun exited $rc"
  cat "$OUT/unkilled.log"
  failures=$((failures + 1))
fi
# Two ranks in one mpirun, each with its own `bake` arguments (paths without
# spaces): every rank refuses before any work, together and ending normally
# (no MPI_ABORT banner), the log matching PATTERN; none of FILES written.
refuse_together() {  # name what pattern "rank 0's arguments" "rank 1's arguments" files...
  local name=$1 what=$2 pattern=$3 first=$4 second=$5
  shift 5
  set +e
  # shellcheck disable=SC2086  # each rank's arguments split into words
  "${MPI[@]}" -np 1 "$CLI" bake $first -q : -np 1 "$CLI" bake $second -q >"$OUT/$name.log" 2>&1
  local rc=$?
  set -e
  local written=""
  for file in "$@"; do
    if [ -e "$file" ]; then written="$written $file"; fi
  done
  if [ $rc -ne 0 ] && [ -z "$written" ] && grep -q "$pattern" "$OUT/$name.log" &&
     ! grep -q "MPI_ABORT" "$OUT/$name.log"; then
    echo "ok: $what: mpirun exits $rc, the rank named, no output file"
  else
    echo "FAIL: $what: mpirun exited $rc; written:${written:- nothing}"
    cat "$OUT/$name.log"
    failures=$((failures + 1))
  fi
}
box="$SCENES/composed/cornell-box.glb"
# Different settings: they hung in a collective of unequal sizes, or failed in OpenMPI.
refuse_together disagree "ranks with different settings" "the settings of rank(s) 1 differ from rank 0's" \
  "$box -o $OUT/disagree.vdb --depth 4 --photons 3000" \
  "$box -o $OUT/disagree.vdb --depth 4 --photons 4000" "$OUT/disagree.vdb"
# Different output names: rank 0 alone writes, so the other's name was dropped without a word.
refuse_together outputs "ranks given different -o" "the output files (-o, --stats-json) given to rank(s) 1 differ" \
  "$box -o $OUT/rank0.vdb --depth 4 --photons 3000" \
  "$box -o $OUT/rank1.vdb --depth 4 --photons 3000" "$OUT/rank0.vdb" "$OUT/rank1.vdb"
# Rank 1 given an output in a folder it lacks: only rank 0 checks the outputs
# it writes (another machine may lack the folder), so rank 1 reaches the
# agreement, where it was ended by its own check, unheard.
refuse_together nofolder "rank 1 given -o in a missing folder" "the output files (-o, --stats-json) given to rank(s) 1 differ" \
  "$box -o $OUT/nofolder0.vdb --depth 4 --photons 3000" \
  "$box -o $OUT/missing/nofolder0.vdb --depth 4 --photons 3000" "$OUT/nofolder0.vdb"
# A rank whose copy of the scene is damaged (a machine with another copy): it
# aborted the job before it said why (rank 0's copy read well, and rank 0 alone
# speaks); rank 0 now gives the failing rank's words.
printf '{"asset": {"version": "2.0"}, "meshes": [' >"$OUT/damaged.gltf"
refuse_together damaged "a rank with a damaged scene" "lightoctree: error: rank 1: .*damaged.gltf: invalid glTF" \
  "$box -o $OUT/damaged.vdb --depth 4 --photons 3000" \
  "$OUT/damaged.gltf -o $OUT/damaged.vdb --depth 4 --photons 3000" "$OUT/damaged.vdb"
# A rank that runs no bake (--version, bake --help) beside one that bakes: the
# baking rank waited for it in MPI_Init until killed (H10-3-23). Every rank
# now refuses at once, rank 0 naming what rank 1 was given.
for given in --version "bake --help"; do
  set +e
  timeout -s KILL 120 "${MPI[@]}" -np 1 "$CLI" bake "$box" -o "$OUT/alone.vdb" --depth 4 \
    --photons 3000 -q : -np 1 "$CLI" $given >"$OUT/alone.log" 2>&1
  rc=$?
  set -e
  if [ $rc -ne 0 ] && [ $rc -ne 137 ] && [ ! -e "$OUT/alone.vdb" ] &&
     grep -q "rank 1: \`lightoctree $given\` given, not \`bake\`" "$OUT/alone.log"; then
    echo "ok: rank 1 given $given beside a bake: mpirun exits $rc, the rank named"
  else
    echo "FAIL: rank 1 given $given beside a bake: mpirun exited $rc (137: killed, hung)"
    cat "$OUT/alone.log"
    failures=$((failures + 1))
  fi
done
# Outside mpirun, a size variable left in a job script's environment: MPI
# finds the process alone, and the command runs (H12-2-36..38: it refused).
for variable in OMPI_COMM_WORLD_SIZE PMI_SIZE PMIX_SIZE; do
  if out=$(env "$variable=2" timeout 120 "$CLI" --version 2>&1) && [ -n "$out" ]; then
    echo "ok: $variable=2 outside mpirun: --version runs"
  else
    echo "FAIL: $variable=2 outside mpirun: --version: $out"
    failures=$((failures + 1))
  fi
done
exit $failures
