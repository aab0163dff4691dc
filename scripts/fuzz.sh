#!/usr/bin/env bash
# Runs each libFuzzer target of the fuzz build (build/fuzz/bin/fuzz_*) for SECONDS (default 10)
# from its seed corpus in tests/fuzz/corpus, new inputs going to a scratch folder (the committed
# corpus is left as it is). Stops at the first finding: the crashing input is written to
# build/fuzz/findings/. Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (docs/testing.md)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-10}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(geojson raster project cli_options); fi
export ASAN_OPTIONS="detect_leaks=1:suppressions=$root/tests/sanitizers/asan.supp"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/tests/sanitizers/ubsan.supp"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
findings="$root/build/fuzz/findings"
mkdir -p "$findings"
for target in "${targets[@]}"; do
  binary="$root/build/fuzz/bin/fuzz_$target"
  mkdir -p "$scratch/$target"
  echo "== fuzz_$target for ${seconds} s"
  # -rss_limit_mb: a reader that allocates from a declared size shows up as an out-of-memory.
  if ! "$binary" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=25 -print_final_stats=1 \
        -artifact_prefix="$findings/${target}-" "$scratch/$target" "$root/tests/fuzz/corpus/$target" \
        >"$scratch/$target.log" 2>&1; then
    tail -n 60 "$scratch/$target.log"
    echo "fuzz_$target found a problem: input in $findings/" >&2
    exit 1
  fi
  grep -E "^#[0-9]+ +DONE|stat::number_of_executed_units" "$scratch/$target.log" || true
done
