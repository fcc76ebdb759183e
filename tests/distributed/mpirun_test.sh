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
LIGHTOCTREE_KILL_RANK=1 "${MPI[@]}" -x LIGHTOCTREE_KILL_RANK -np 2 "$CLI" bake \
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
# Ranks started with different settings (one mpirun, two command lines):
# every rank refuses before any work, naming the rank; nothing is written
# (they hung in a collective of unequal sizes, or failed in OpenMPI).
set +e
"${MPI[@]}" -np 1 "$CLI" bake "$SCENES/composed/cornell-box.glb" -o "$OUT/disagree.vdb" -q \
  --depth 4 --photons 3000 : -np 1 "$CLI" bake "$SCENES/composed/cornell-box.glb" \
  -o "$OUT/disagree.vdb" -q --depth 4 --photons 4000 >"$OUT/disagree.log" 2>&1
rc=$?
set -e
if [ $rc -ne 0 ] && [ ! -e "$OUT/disagree.vdb" ] &&
   grep -q "the settings of rank(s) 1 differ from rank 0's" "$OUT/disagree.log"; then
  echo "ok: ranks with different settings: mpirun exits $rc, the rank named, no output file"
else
  echo "FAIL: ranks with different settings: mpirun exited $rc"
  cat "$OUT/disagree.log"
  failures=$((failures + 1))
fi
# Ranks given different output names: rank 0 alone writes, so the other's
# name was dropped without a word; now every rank refuses, neither written.
set +e
"${MPI[@]}" -np 1 "$CLI" bake "$SCENES/composed/cornell-box.glb" -o "$OUT/rank0.vdb" -q \
  --depth 4 --photons 3000 : -np 1 "$CLI" bake "$SCENES/composed/cornell-box.glb" \
  -o "$OUT/rank1.vdb" -q --depth 4 --photons 3000 >"$OUT/outputs.log" 2>&1
rc=$?
set -e
if [ $rc -ne 0 ] && [ ! -e "$OUT/rank0.vdb" ] && [ ! -e "$OUT/rank1.vdb" ] &&
   grep -q "the output files (-o, --stats-json) given to rank(s) 1 differ" "$OUT/outputs.log"; then
  echo "ok: ranks given different -o: mpirun exits $rc, the rank named, no output file"
else
  echo "FAIL: ranks given different -o: mpirun exited $rc"
  cat "$OUT/outputs.log"
  failures=$((failures + 1))
fi
# A rank whose copy of the scene is damaged (a machine with another copy):
# it aborted the job before it said why (rank 0's copy read well, and rank 0
# alone speaks). Now every rank refuses together, rank 0 giving the failing
# rank's words; nothing is written.
printf '{"asset": {"version": "2.0"}, "meshes": [' >"$OUT/damaged.gltf"
set +e
"${MPI[@]}" -np 1 "$CLI" bake "$SCENES/composed/cornell-box.glb" -o "$OUT/damaged.vdb" -q \
  --depth 4 --photons 3000 : -np 1 "$CLI" bake "$OUT/damaged.gltf" \
  -o "$OUT/damaged.vdb" -q --depth 4 --photons 3000 >"$OUT/damaged.log" 2>&1
rc=$?
set -e
if [ $rc -ne 0 ] && [ ! -e "$OUT/damaged.vdb" ] &&
   grep -q "lightoctree: error: rank 1: .*damaged.gltf: invalid glTF" "$OUT/damaged.log" &&
   ! grep -q "MPI_ABORT" "$OUT/damaged.log"; then
  echo "ok: a rank with a damaged scene: mpirun exits $rc, its message said, no output file"
else
  echo "FAIL: a rank with a damaged scene: mpirun exited $rc"
  cat "$OUT/damaged.log"
  failures=$((failures + 1))
fi
exit $failures
