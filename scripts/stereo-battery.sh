#!/usr/bin/env bash
# The stereo matcher's battery of simulated scenes (default noise), adaptive method only: one line
# per scene (density %, bad-1 %, roof RMS over all flat-roof matches px, RMS1 px, edge %, and the
# RMS over the sloped roof facets' matches px, a measure without a target), then,
# per group, how many scenes meet each target of the stereo issue (density >= 85 %, bad-1 <= 5 %,
# roof RMS <= 0.25 px, edge >= 90 %).
#   battery:  the 11 scenes the defaults were tuned on;
#   held-out: seeds 11-16 600², 6-8 1000²; seeds 13-15 600² and 6-8 1000² chose the weak-match
#             rejection beside steps (step-min-score);
#   fresh:    seeds 17-22 600², 9-11 1000², first run after that choice; seed 18 600² chose the
#             fill's plane margin;
#   fresh-2:  seeds 23-28 600², 12-14 1000², run to check the rejection's radius; seed 28 600²
#             chose the snapping's steepest line and the plain-pixel pass, seed 13 1000² the
#             fill's edges, seed 14 1000² the scan's grey map and the planes' least span;
#   fresh-3:  seeds 29-34 600², 15-17 1000², first run before anything was chosen on it; seeds
#             15-16 1000² then chose the contour-gap closing, the fill's value and the rejection
#             beside unmatched plain regions, seed 33 600² the facets' banded score;
#   fresh-4:  seeds 35-40 600², 18-20 1000², first run after those choices; seeds 35 600² and
#             18 1000² then chose the fill's edge decision and edge reach, seed 39 600² the
#             level plane rule, seeds 36 and 38 600² the roof planes and the banded score;
#   fresh-5:  seeds 41-46 600², 21-23 1000²; seed 41 600² chose the slanted facets, seed 44 600²
#             the roof planes;
#   fresh-6:  seeds 47-52 600², 24-26 1000², first run before anything was chosen on it; seed
#             24 1000² then chose the plane-within-matches rule, seed 49 600² the edges' share;
#   fresh-7:  seeds 53-58 600², 27-29 1000², run to check the speckle size chosen on the others;
#             seed 29 1000² then chose the edges' decision over the photometric limit;
#   fresh-8:  seeds 59-64 600², 30-32 1000², run to check the fill's edge decision;
#   fresh-9:  seeds 65-70 600², 33-35 1000², run to check the edges' share (no scene of it moved).
#   Other single scenes were looked at too (the commit messages name them): a group used to
#   choose a constant no longer measures generalisation alone. Judge a change on all eleven
#   groups, and keep them apart.
# Usage: scripts/stereo-battery.sh [BUILD_DIR] [extra bench_stereo arguments, e.g. --params '{}']
# A few minutes on 2 cores. Not a test: it prints numbers.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build/default"
if [[ $# -gt 0 && "$1" != --* ]]; then
  build="$1"
  shift
fi
bench="$build/tests/bench/bench_stereo"
if [[ ! -x "$bench" ]]; then
  echo "stereo-battery: $bench not found; build the 'bench_stereo' target first" >&2
  exit 2
fi

battery=("400|--size 400" "600|--size 600" "1000/128|--size 1000 --range 128"
  "2000/256|--size 2000 --range 256" "s2-600|--size 600 --seed 2" "s2-1000|--size 1000 --seed 2"
  "s3-600|--size 600 --seed 3" "s3-1000|--size 1000 --seed 3" "s4-600|--size 600 --seed 4"
  "s5-600|--size 600 --seed 5" "s6-600|--size 600 --seed 6")
heldout=("s11-600|--size 600 --seed 11" "s12-600|--size 600 --seed 12"
  "s13-600|--size 600 --seed 13" "s14-600|--size 600 --seed 14" "s15-600|--size 600 --seed 15"
  "s16-600|--size 600 --seed 16" "s6-1000|--size 1000 --seed 6" "s7-1000|--size 1000 --seed 7"
  "s8-1000|--size 1000 --seed 8")
fresh=("s17-600|--size 600 --seed 17" "s18-600|--size 600 --seed 18"
  "s19-600|--size 600 --seed 19" "s20-600|--size 600 --seed 20" "s21-600|--size 600 --seed 21"
  "s22-600|--size 600 --seed 22" "s9-1000|--size 1000 --seed 9" "s10-1000|--size 1000 --seed 10"
  "s11-1000|--size 1000 --seed 11")
fresh2=("s23-600|--size 600 --seed 23" "s24-600|--size 600 --seed 24"
  "s25-600|--size 600 --seed 25" "s26-600|--size 600 --seed 26" "s27-600|--size 600 --seed 27"
  "s28-600|--size 600 --seed 28" "s12-1000|--size 1000 --seed 12"
  "s13-1000|--size 1000 --seed 13" "s14-1000|--size 1000 --seed 14")
fresh3=("s29-600|--size 600 --seed 29" "s30-600|--size 600 --seed 30"
  "s31-600|--size 600 --seed 31" "s32-600|--size 600 --seed 32" "s33-600|--size 600 --seed 33"
  "s34-600|--size 600 --seed 34" "s15-1000|--size 1000 --seed 15"
  "s16-1000|--size 1000 --seed 16" "s17-1000|--size 1000 --seed 17")
fresh4=("s35-600|--size 600 --seed 35" "s36-600|--size 600 --seed 36"
  "s37-600|--size 600 --seed 37" "s38-600|--size 600 --seed 38" "s39-600|--size 600 --seed 39"
  "s40-600|--size 600 --seed 40" "s18-1000|--size 1000 --seed 18"
  "s19-1000|--size 1000 --seed 19" "s20-1000|--size 1000 --seed 20")
fresh5=("s41-600|--size 600 --seed 41" "s42-600|--size 600 --seed 42"
  "s43-600|--size 600 --seed 43" "s44-600|--size 600 --seed 44" "s45-600|--size 600 --seed 45"
  "s46-600|--size 600 --seed 46" "s21-1000|--size 1000 --seed 21"
  "s22-1000|--size 1000 --seed 22" "s23-1000|--size 1000 --seed 23")
fresh6=("s47-600|--size 600 --seed 47" "s48-600|--size 600 --seed 48"
  "s49-600|--size 600 --seed 49" "s50-600|--size 600 --seed 50" "s51-600|--size 600 --seed 51"
  "s52-600|--size 600 --seed 52" "s24-1000|--size 1000 --seed 24"
  "s25-1000|--size 1000 --seed 25" "s26-1000|--size 1000 --seed 26")
fresh7=("s53-600|--size 600 --seed 53" "s54-600|--size 600 --seed 54"
  "s55-600|--size 600 --seed 55" "s56-600|--size 600 --seed 56" "s57-600|--size 600 --seed 57"
  "s58-600|--size 600 --seed 58" "s27-1000|--size 1000 --seed 27"
  "s28-1000|--size 1000 --seed 28" "s29-1000|--size 1000 --seed 29")
fresh8=("s59-600|--size 600 --seed 59" "s60-600|--size 600 --seed 60"
  "s61-600|--size 600 --seed 61" "s62-600|--size 600 --seed 62" "s63-600|--size 600 --seed 63"
  "s64-600|--size 600 --seed 64" "s30-1000|--size 1000 --seed 30"
  "s31-1000|--size 1000 --seed 31" "s32-1000|--size 1000 --seed 32")
fresh9=("s65-600|--size 600 --seed 65" "s66-600|--size 600 --seed 66"
  "s67-600|--size 600 --seed 67" "s68-600|--size 600 --seed 68" "s69-600|--size 600 --seed 69"
  "s70-600|--size 600 --seed 70" "s33-1000|--size 1000 --seed 33"
  "s34-1000|--size 1000 --seed 34" "s35-1000|--size 1000 --seed 35")

run_group() {
  local name=$1
  shift
  local n=0 density=0 bad1=0 rms=0 edge=0
  printf '%s\n%-10s %9s %7s %9s %8s %7s %9s\n' "== $name" scene density% bad1% roofRMS RMS1 edge% \
    slopedRMS
  for entry in "$@"; do
    local label=${entry%%|*} args=${entry#*|} out line sloped
    # shellcheck disable=SC2086  # args is a list of words
    out=$("$bench" --no-data --methods adaptive --outline-diag $args "${extra[@]}")
    line=$(awk '/^  adaptive/{print $2, $3, $6, $7, $8}' <<<"$out")
    if [[ -z "$line" ]]; then
      echo "stereo-battery: no result for $label" >&2
      exit 1
    fi
    # The sloped roof facets' RMS (not a target; "-" when the scene has fewer than 100 matched).
    sloped=$(awk '/sloped-roof pixels/{gsub(",", ""); print ($5 >= 100) ? $7 : "-"}' <<<"$out")
    read -r d b r r1 e <<<"$line"
    printf '%-10s %9s %7s %9s %8s %7s %9s\n' "$label" "$d" "$b" "$r" "$r1" "$e" "${sloped:--}"
    n=$((n + 1))
    density=$((density + $(awk -v v="$d" 'BEGIN{print (v >= 85) ? 1 : 0}')))
    bad1=$((bad1 + $(awk -v v="$b" 'BEGIN{print (v <= 5) ? 1 : 0}')))
    rms=$((rms + $(awk -v v="$r" 'BEGIN{print (v <= 0.25) ? 1 : 0}')))
    edge=$((edge + $(awk -v v="$e" 'BEGIN{print (v >= 90) ? 1 : 0}')))
  done
  printf 'met on %d scenes: density %d, bad-1 %d, roof RMS %d, edge %d\n' \
    "$n" "$density" "$bad1" "$rms" "$edge"
}

extra=("$@")
run_group battery "${battery[@]}"
run_group held-out "${heldout[@]}"
run_group fresh "${fresh[@]}"
run_group fresh-2 "${fresh2[@]}"
run_group fresh-3 "${fresh3[@]}"
run_group fresh-4 "${fresh4[@]}"
run_group fresh-5 "${fresh5[@]}"
run_group fresh-6 "${fresh6[@]}"
run_group fresh-7 "${fresh7[@]}"
run_group fresh-8 "${fresh8[@]}"
run_group fresh-9 "${fresh9[@]}"
