#!/usr/bin/env bash
# End-to-end checks of `delineo-cli dem` on a hand-made georeferenced disparity map: ground at
# 4 px and a 4 x 4 px roof at 24 px (0.5 m per px: 0 m and 10 m), a no-data hole in the ground
# (merged: filled with the ground) and a no-data strip beside the roof's left wall (kept; filled
# with the ground under --fill). Heights are compared with eval-disparity (its RMS works on any
# float raster); the output keeps the map's georeferencing; bad inputs give the documented exit
# codes (2 usage, 3 input or output refused).
#
# Usage: e2e_dem.sh DELINEO_CLI WORK_DIR
# Exit status 0 when every check passes; otherwise 1, with one line per failed check on stderr.
set -u
E2E_NAME=e2e_dem
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"

inbox() { (($1 >= 4 && $1 <= 7 && $2 >= 4 && $2 <= 7)); }
hole() { (($1 >= 9 && $1 <= 10 && $2 >= 1 && $2 <= 2)); }
wall() { (($1 == 3 && $2 >= 4 && $2 <= 7)); }
disparity() { if hole "$1" "$2" || wall "$1" "$2"; then echo -9999; elif inbox "$1" "$2"; then echo 24; else echo 4; fi; }
heights() { if inbox "$1" "$2"; then echo 10; else echo 0; fi; }
grid12 "$WORK/disparity.asc" disparity
grid12 "$WORK/expected.asc" heights
printf '{"width":12,"height":12,"disparity_min":0,"disparity_max":30,"gsd_m":0.5,"metres_per_disparity":0.5,"ground_disparity":4,"seed":1}\n' \
  >"$WORK/scene.json"

compare() {  # compare NAME DEM: eval-disparity of DEM against the expected heights
  expect_rc "$1" 0 "$CLI" eval-disparity --pred "$2" --truth "$WORK/expected.asc" --truth-zero-unknown false \
    --json "$WORK/$1.json"
}

expect_rc dem 0 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 --ground-disparity 4 \
  --out "$WORK/dem.tif"
expect_in "$WORK/dem.out" '2 gaps, 1 merged \(4 px\), 1 kept \(4 px\)' "summary counts the gaps"
expect_in "$WORK/dem.err" 'heights and gaps' "progress on stderr"
compare compare "$WORK/dem.tif"
expect_in "$WORK/compare.json" '"rms": 0\.0,?$' "heights follow the model, the ground hole is merged"
expect_in "$WORK/compare.json" '"predicted_pixels": 140,?$' "the strip beside the wall stays no data"

expect_rc filled 0 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 --ground-disparity 4 \
  --out "$WORK/filled.tif" --fill --quiet
[[ -s $WORK/filled.err ]] && fail "--quiet should leave stderr empty"
expect_in "$WORK/filled.out" '4 px filled' "summary counts the filled pixels"
compare compare_filled "$WORK/filled.tif"
expect_in "$WORK/compare_filled.json" '"rms": 0\.0,?$' "the wall strip is filled with the ground"
expect_in "$WORK/compare_filled.json" '"predicted_pixels": 144,?$' "--fill leaves no gap"

# The scene's model gives the same DEM; a reference height shifts it.
expect_rc scene 0 "$CLI" dem --disparity "$WORK/disparity.asc" --scene "$WORK/scene.json" --out "$WORK/scene.tif"
compare compare_scene "$WORK/scene.tif"
expect_in "$WORK/compare_scene.json" '"rms": 0\.0,?$' "scene.json gives the model"
expect_rc shifted 0 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 --ground-disparity 4 \
  --reference-height 100 --out "$WORK/shifted.tif"
compare compare_shifted "$WORK/shifted.tif"
expect_in "$WORK/compare_shifted.json" '"mean_abs_error": 100\.0,?$' "the reference height is added"

# The output keeps the georeferencing: a footprint in map coordinates still falls on the roof.
printf '{"type":"FeatureCollection","features":[{"type":"Feature","properties":{"id":1},"geometry":{"type":"Polygon","coordinates":[[[1002,2004],[1004,2004],[1004,2002],[1002,2002],[1002,2004]]]}}]}\n' \
  >"$WORK/roof.geojson"
expect_rc georeferenced 0 "$CLI" enhance --dem "$WORK/dem.tif" --footprints "$WORK/roof.geojson" \
  --out "$WORK/enhanced.tif" --quiet

# Bad inputs and usage.
expect_rc no_model 2 "$CLI" dem --disparity "$WORK/disparity.asc" --out "$WORK/x.tif"
expect_in "$WORK/no_model.err" 'scene.*metres-per-pixel' "a missing model says what to give"
expect_rc both_models 2 "$CLI" dem --disparity "$WORK/disparity.asc" --scene "$WORK/scene.json" \
  --metres-per-pixel 0.5 --out "$WORK/x.tif"
expect_rc zero_scale 3 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0 --out "$WORK/x.tif"
expect_in "$WORK/zero_scale.err" 'metres-per-pixel' "a zero scale is named"
expect_rc missing 3 "$CLI" dem --disparity "$WORK/nope.tif" --metres-per-pixel 0.5 --out "$WORK/x.tif"
expect_in "$WORK/missing.err" 'nope\.tif' "a missing map is named"
printf 'not a raster\n' >"$WORK/garbage.tif"
expect_rc garbage 3 "$CLI" dem --disparity "$WORK/garbage.tif" --metres-per-pixel 0.5 --out "$WORK/x.tif"
expect_rc missing_scene 3 "$CLI" dem --disparity "$WORK/disparity.asc" --scene "$WORK/none.json" --out "$WORK/x.tif"
expect_in "$WORK/missing_scene.err" 'none\.json' "a missing scene.json is named"
expect_rc bad_param 3 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 --out "$WORK/x.tif" \
  --min-border-pixels 0
expect_rc no_out 2 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5
expect_rc unknown_flag 2 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 --out "$WORK/x.tif" \
  --frobnicate 1
# Outputs are checked before any work (the output policy): a missing folder, the input itself.
expect_rc unwritable 3 "$CLI" dem --disparity "$WORK/disparity.asc" --metres-per-pixel 0.5 \
  --out "$WORK/no/such/folder/x.tif"
cp "$WORK/dem.tif" "$WORK/input.tif"
expect_rc onto_input 3 "$CLI" dem --disparity "$WORK/input.tif" --metres-per-pixel 0.5 --out "$WORK/input.tif"
cmp -s "$WORK/dem.tif" "$WORK/input.tif" || fail "writing onto the input must leave it untouched"

if ((failures > 0)); then
  echo "e2e_dem: $failures check(s) failed" >&2
  exit 1
fi
echo "e2e_dem: all checks passed"
