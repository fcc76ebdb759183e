#!/usr/bin/env bash
# Every numeric flag of every command refuses NaN, the infinities and numbers
# single precision cannot hold (1e-300 became 0, 1e300 infinity, after the
# parse) before any work, naming the flag, exit 2 and nothing written
# (docs/robustness.md, "Numbers at the flags"). The flags are read from each command's --help, so
# a flag added later is tried too: a floating-point one must say "must be a
# finite number"; a whole-number one must refuse as well.
# Usage: numeric_flags.sh CLI SCENE OUT_DIR
set -u
cli=$1 scene=$2 out=$3
rm -rf "$out"
mkdir -p "$out"
failed=0 tried=0 flags=0
for cmd in bake render lightmap convert inspect reference compare sweep view; do
  # Arguments the parser takes (it checks only that inputs exist): the
  # refusal must come from the flag alone.
  case $cmd in
    bake) args=("$scene" -o "$out/x.vdb") ;;
    render) args=("$scene" "$scene" -o "$out/x.png") ;;
    view) args=("$scene" "$scene") ;;
    lightmap) args=("$scene" "$scene" -o "$out/x.glb") ;;
    convert) args=("$scene" -o "$out/x.vdb") ;;
    inspect) args=("$scene") ;;
    reference) args=("$scene" -o "$out/x.png") ;;
    compare) args=("$scene" "$scene" --diff "$out/x.png") ;;
    sweep) args=("$scene" --out "$out/sweep") ;;
  esac
  # "  --fov FLOAT:NUMBER from 1 to 179", "  --bounds FLOAT x 6", "  --knn INT:...":
  # the flag's long name, its type and how many numbers it takes.
  while read -r flag type count; do
    flags=$((flags + 1))
    # Hexadecimal (strtod and the parser's strtoll(s, 0) read it) and the
    # empty value are refused too, on every flag alike.
    for value in nan inf -inf 1e-300 1e300 0x10 ''; do
      joined=$value
      for ((i = 1; i < count; ++i)); do joined="$joined,1"; done
      given=("$flag=$joined")  # "--flag=-inf": not taken for a flag
      [ -z "$value" ] && given=("$flag" "$joined")  # "--flag=" is a missing value
      err=$("$cli" "$cmd" "${args[@]}" "${given[@]}" 2>&1 >/dev/null)
      rc=$?
      tried=$((tried + 1))
      expect="$flag"
      [ "$type" = FLOAT ] && [ -n "$value" ] && expect="$flag: must be a finite number"
      [ "$value" = 0x10 ] && expect="$flag: must be"
      if [ "$value" = 0x10 ] && ! grep -qF -- "decimal digits" <<<"$err"; then
        rc="$rc, no 'decimal'"
      fi
      if [ "$rc" != 2 ] || ! grep -qF -- "$expect" <<<"$err"; then
        echo "FAILED: $cmd $flag=$joined: exit $rc, expected 2 and '$expect': $err"
        failed=$((failed + 1))
      fi
      if ls "$out"/x.* "$out"/.x.* >/dev/null 2>&1 || [ -e "$out/sweep" ]; then
        echo "FAILED: $cmd $flag=$joined left a file behind"
        failed=$((failed + 1))
        rm -rf "$out"/x.* "$out"/.x.* "$out/sweep"
      fi
    done
  done < <("$cli" "$cmd" --help | sed -nE \
    's/^ +(-[A-Za-z],)?(--[a-z0-9-]+)(,--[a-z0-9-]+)* (FLOAT|INT|UINT)( x ([0-9]+))?.*/\2 \4 \6/p' |
    awk '{ print $1, $2, ($3 == "" ? 1 : $3) }')
done
# Leading zeros are decimal on every whole-number flag (the parser read "010"
# as octal 8 and refused "08"): the report records what was taken.
"$cli" reference "$scene" -o "$out/x.exr" --width 010 --height 08 --spp 01 --seed 017 \
  --json "$out/zeros.json" -q
if ! python3 -c 'import json, sys; f = json.load(open(sys.argv[1]))["figures"]
sys.exit((f["width"], f["height"], f["samples_per_pixel"]) != (10, 8, 1))' "$out/zeros.json"; then
  echo "FAILED: --width 010 --height 08 --spp 01 not 10 x 8 at 1 spp: $(cat "$out/zeros.json")"
  failed=$((failed + 1))
fi
rm -f "$out/x.exr" "$out/zeros.json"
"$cli" reference "$scene" -o "$out/a.exr" --width 4 --height 4 --spp 2 --seed 017 -q
"$cli" reference "$scene" -o "$out/b.exr" --width 4 --height 4 --spp 2 --seed 17 -q
if ! cmp -s "$out/a.exr" "$out/b.exr"; then
  echo "FAILED: --seed 017 is not --seed 17"
  failed=$((failed + 1))
fi
rm -f "$out/a.exr" "$out/b.exr"
# A sky image whose brightest texel above the horizon is 1e30 W/(m^2 sr)
# (finite, as sky images must be): the bake's sky power overflowed and it
# refused late, while reference drew it. Both refuse it now, alike.
python3 - "$out/bright.hdr" <<'PY'
import sys
# Radiance RGBE, flat rows (width < 8): texel = m * 2^(e - 136); 202 * 2^92 = 1.0e30.
texels = bytes([202, 202, 202, 228]) + bytes([128, 128, 128, 129]) * 7
open(sys.argv[1], "wb").write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n" + texels)
PY
bake_err=$("$cli" bake "$scene" -o "$out/x.vdb" --sky-image "$out/bright.hdr" 2>&1 >/dev/null)
bake_rc=$?
ref_err=$("$cli" reference "$scene" -o "$out/x.png" --width 8 --height 8 --spp 1 \
  --sky-image "$out/bright.hdr" 2>&1 >/dev/null)
ref_rc=$?
if [ "$bake_rc" -ne 1 ] || [ "$ref_rc" -ne 1 ] || [ "$bake_err" != "$ref_err" ] ||
  ! grep -qF "the sky's radiance reaches 1.0" <<<"$bake_err"; then
  echo "FAILED: a 1e30 sky: bake exit $bake_rc ($bake_err), reference exit $ref_rc ($ref_err)"
  failed=$((failed + 1))
fi
if ls "$out"/x.* >/dev/null 2>&1; then
  echo "FAILED: a refused sky left a file behind"
  failed=$((failed + 1))
fi
if [ "$flags" -lt 40 ]; then
  echo "FAILED: only $flags numeric flags found in the commands' --help (its format changed?)"
  failed=$((failed + 1))
fi
[ "$failed" -eq 0 ] && echo "numeric flags: $flags flags of 9 commands refuse nan, inf, -inf, 1e-300, 1e300, 0x10 and '' ($tried runs)"
exit "$failed"
