# Shared helpers of the delineo-cli end-to-end scripts (sourced, not run).
# The sourcing script sets E2E_NAME (prefix of failure lines) and WORK (scratch folder), and
# reads `failures` at the end.
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
