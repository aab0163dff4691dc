#!/usr/bin/env bash
# Ctrl-C latency of the longest CLI steps: the time from SIGINT to the process's exit, for
# match on a 2000 x 2000 pair, delineate on a batch of 50 buildings and eval-footprints on a
# 45 000-vertex polygon. Prints one line per case; the target is 1 s (docs/conventions.md).
#
# Usage: tests/bench/cancel_latency.sh [DELINEO_CLI] [WORK_DIR]
set -u
cli=${1:-build/default/bin/delineo-cli}
work=${2:-/tmp/delineo-cancel-latency}
rm -rf "$work"
mkdir -p "$work"

# interrupt NAME DELAY_S COMMAND...: starts the command, sends SIGINT after DELAY_S seconds of
# progress output, prints the exit code and the latency in ms.
interrupt() {
  local name=$1 delay=$2
  shift 2
  "$@" >"$work/$name.out" 2>"$work/$name.err" &
  local pid=$!
  for _ in $(seq 600); do grep -q "%" "$work/$name.err" 2>/dev/null && break; sleep 0.05; done
  sleep "$delay"
  local start end
  start=$(date +%s%N)
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  local rc=$?
  end=$(date +%s%N)
  printf '%-28s exit %3d   latency %6.0f ms\n' "$name" "$rc" "$(((end - start) / 1000000))"
}

"$cli" simulate --out "$work/big" --width 2000 --height 2000 --buildings 50 --trees 20 --seed 3 --quiet \
  >/dev/null 2>&1 || "$cli" simulate --out "$work/big" --width 2000 --height 2000 --buildings 50 --trees 20 --seed 3 >/dev/null 2>&1
"$cli" rough-init --truth "$work/big/footprints_gt.geojson" --grow 10 --out "$work/init.geojson" >/dev/null 2>&1
echo "buildings in the batch: $(grep -c '"type": "Feature"' "$work/init.geojson")"

interrupt "match 2000x2000" 3 "$cli" match --left "$work/big/left.tif" --right "$work/big/right.tif" --out "$work/d.tif"
interrupt "delineate 50 buildings" 5 "$cli" delineate --left "$work/big/left.tif" --right "$work/big/right.tif" \
  --init "$work/init.geojson" --out "$work/o.geojson"

# A 45 000-vertex circle against itself, shifted: the footprint metrics' worst case the reader accepts.
awk 'BEGIN {
  n = 45000; printf "{\"type\":\"FeatureCollection\",\"features\":[{\"type\":\"Feature\",\"properties\":{},\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[";
  for (i = 0; i <= n; i++) { a = 6.283185307 * (i % n) / n; printf "%s[%.4f,%.4f]", (i ? "," : ""), 1000 + 900 * cos(a), 1000 + 900 * sin(a) }
  printf "]]}}]}\n" }' >"$work/circle.geojson"
awk 'BEGIN {
  n = 45000; printf "{\"type\":\"FeatureCollection\",\"features\":[{\"type\":\"Feature\",\"properties\":{},\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[";
  for (i = 0; i <= n; i++) { a = 6.283185307 * (i % n) / n; printf "%s[%.4f,%.4f]", (i ? "," : ""), 1003 + 900 * cos(a), 1000 + 900 * sin(a) }
  printf "]]}}]}\n" }' >"$work/circle2.geojson"
start=$(date +%s%N)
"$cli" eval-footprints --pred "$work/circle2.geojson" --truth "$work/circle.geojson" >"$work/eval.out" 2>"$work/eval.err" &
pid=$!
sleep 2
if kill -0 "$pid" 2>/dev/null; then
  interrupt_start=$(date +%s%N)
  kill -INT "$pid"
  wait "$pid"
  rc=$?
  printf '%-28s exit %3d   latency %6.0f ms\n' "eval 45k vertices" "$rc" "$((($(date +%s%N) - interrupt_start) / 1000000))"
else
  wait "$pid"
  rc=$?
  printf '%-28s exit %3d   finished in %6.0f ms (before the interrupt)\n' "eval 45k vertices" "$rc" "$((($(date +%s%N) - start) / 1000000))"
fi
