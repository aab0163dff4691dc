# Shared helpers of the delineo-cli end-to-end scripts (sourced, not run), and their arguments.
# The sourcing script sets E2E_NAME (prefix of failure lines and usage), sources this file with
# its own arguments (DELINEO_CLI WORK_DIR: CLI and WORK, emptied here), and reads `failures` at
# the end.
CLI=${1:?usage: ${E2E_NAME}.sh DELINEO_CLI WORK_DIR}
WORK=${2:?usage: ${E2E_NAME}.sh DELINEO_CLI WORK_DIR}
rm -rf "$WORK"
mkdir -p "$WORK"
failures=0
fail() { echo "${E2E_NAME}: FAIL: $*" >&2; failures=$((failures + 1)); }

# expect_rc NAME EXPECTED_RC COMMAND...: runs the command, keeps stdout/stderr in $WORK/NAME.*.
expect_rc() {
  local name=$1 expected=$2
  shift 2
  "$@" >"$WORK/$name.out" 2>"$WORK/$name.err"
  local rc=$?
  [[ $rc == "$expected" ]] || fail "$name: exit $rc, expected $expected ($(head -c 300 "$WORK/$name.err"))"
}
# expect_in FILE PATTERN DESCRIPTION: an extended regular expression must match in FILE.
expect_in() { grep -Eq -- "$2" "$1" || fail "$3: '$2' not found in $1"; }

# count FILE PATTERN: number of matches of PATTERN in FILE (one feature per line in OGR GeoJSON).
count() { grep -Eo -- "$2" "$1" | wc -l; }
# mean_iou JSON: the "iou" value of the "mean" object of an eval-footprints report.
mean_iou() { tr -d '\n ' <"$1" | grep -Eo '"mean":\{[^}]*\}' | grep -Eo '"iou":[0-9.eE+-]+' | cut -d: -f2; }
# above VALUE FLOOR: true when VALUE > FLOOR (awk: bash has no floating point).
above() { awk -v v="$1" -v f="$2" 'BEGIN { exit !(v != "" && v + 0 > f + 0) }'; }

# grid12 FILE FUNCTION: a 12 x 12 ESRI ASCII grid of FUNCTION(col, row), 0.5 m cells, whose
# top-left corner is at map (1000, 2006); -9999 = no data.
grid12() {
  local file=$1 fn=$2
  {
    printf 'ncols 12\nnrows 12\nxllcorner 1000\nyllcorner 2000\ncellsize 0.5\nNODATA_value -9999\n'
    for ((r = 0; r < 12; r++)); do
      for ((c = 0; c < 12; c++)); do printf '%s ' "$($fn "$c" "$r")"; done
      printf '\n'
    done
  } >"$file"
}
