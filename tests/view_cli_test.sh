#!/usr/bin/env bash
# view_cli_test.sh [--clean DIR] [--expect FILE]... [--absent FILE]... [--output REGEX] -- COMMAND...
# Runs COMMAND under xvfb-run (`lightoctree view` needs a display; Xvfb gives a
# virtual one with Mesa's software GL), then checks that every --expect file
# exists and is not empty, no --absent file exists, and the output matches
# --output (grep -E). Exits 77, which ctest reads as "skipped"
# (SKIP_RETURN_CODE), when xvfb-run is not installed.
set -u
clean=() expect=() absent=() regex=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  case "$1" in
    --clean) clean+=("$2"); shift 2 ;;
    --expect) expect+=("$2"); shift 2 ;;
    --absent) absent+=("$2"); shift 2 ;;
    --output) regex="$2"; shift 2 ;;
    *) echo "view_cli_test.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
shift
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "xvfb-run is not installed (Debian: xvfb): skipped"
  exit 77
fi
for d in "${clean[@]+"${clean[@]}"}"; do rm -rf "$d"; done
log=$(xvfb-run -a -s "-screen 0 1280x1024x24" "$@" 2>&1)
rc=$?
printf '%s\n' "$log"
if [ $rc -ne 0 ]; then
  echo "view_cli_test.sh: exit $rc: $*" >&2
  exit 1
fi
for f in "${expect[@]+"${expect[@]}"}"; do
  [ -s "$f" ] || { echo "view_cli_test.sh: expected output missing or empty: $f" >&2; exit 1; }
done
for f in "${absent[@]+"${absent[@]}"}"; do
  [ ! -e "$f" ] || { echo "view_cli_test.sh: should not exist: $f" >&2; exit 1; }
done
if [ -n "$regex" ] && ! printf '%s\n' "$log" | grep -Eq "$regex"; then
  echo "view_cli_test.sh: output does not match '$regex'" >&2
  exit 1
fi
exit 0
