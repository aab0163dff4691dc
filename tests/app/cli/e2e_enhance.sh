#!/usr/bin/env bash
# End-to-end checks of `delineo-cli enhance` on a hand-made georeferenced DEM: a 4 x 4 px roof at
# 10 m whose walls are 1 px ramps at 5 m, on flat ground at 0 m. The enhanced DEM must be the box
# with vertical walls (compared with eval-disparity, whose RMS works on any float raster), keep
# the input's georeferencing, and bad inputs must give the documented exit codes.
#
# Usage: e2e_enhance.sh DELINEO_CLI WORK_DIR
# Exit status 0 when every check passes; otherwise 1, with one line per failed check on stderr.
set -u
E2E_NAME=e2e_enhance
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"

inbox() { (($1 >= 4 && $1 <= 7 && $2 >= 4 && $2 <= 7)); }
nearbox() { (($1 >= 3 && $1 <= 8 && $2 >= 3 && $2 <= 8)); }
ramped() { if inbox "$1" "$2"; then echo 10; elif nearbox "$1" "$2"; then echo 5; else echo 0; fi; }
sharp() { if inbox "$1" "$2"; then echo 10; else echo 0; fi; }
grid12 "$WORK/dem.asc" ramped
grid12 "$WORK/expected.asc" sharp

# The roof's outline in map coordinates (pixels 4..8 in x and y).
feature() {  # feature X0 Y0 X1 Y1 (map coordinates)
  printf '{"type":"FeatureCollection","features":[{"type":"Feature","properties":{"id":1},'
  printf '"geometry":{"type":"Polygon","coordinates":[[[%s,%s],[%s,%s],[%s,%s],[%s,%s],[%s,%s]]]}}]}\n' \
    "$1" "$2" "$3" "$2" "$3" "$4" "$1" "$4" "$1" "$2"
}
feature 1002 2004 1004 2002 >"$WORK/roof.geojson"
feature 900 1900 901 1901 >"$WORK/far.geojson"

expect_rc enhance 0 "$CLI" enhance --dem "$WORK/dem.asc" --footprints "$WORK/roof.geojson" \
  --out "$WORK/enhanced.tif"
expect_in "$WORK/enhance.out" 'with 1 footprints' "summary names the footprint count"
expect_in "$WORK/enhance.err" 'enhancing' "progress on stderr"
expect_rc compare 0 "$CLI" eval-disparity --pred "$WORK/enhanced.tif" --truth "$WORK/expected.asc" \
  --json "$WORK/compare.json"
expect_in "$WORK/compare.json" '"rms": 0\.0$' "enhanced DEM is the box with vertical walls"
expect_in "$WORK/compare.json" '"evaluated_pixels": 144,' "every pixel has a height"
# Unenhanced, the same comparison sees the ramp (so the check above can fail).
expect_rc compare_input 0 "$CLI" eval-disparity --pred "$WORK/dem.asc" --truth "$WORK/expected.asc" \
  --json "$WORK/compare_input.json"
grep -Eq '"rms": 0\.0$' "$WORK/compare_input.json" && fail "the input DEM should differ from the box"
# The output keeps the georeferencing: the map-coordinate footprint still falls on it.
expect_rc georeferenced 0 "$CLI" enhance --dem "$WORK/enhanced.tif" --footprints "$WORK/roof.geojson" \
  --out "$WORK/again.tif" --quiet
[[ -s $WORK/georeferenced.err ]] && fail "--quiet should leave stderr empty"

# Bad inputs and usage.
expect_rc outside 3 "$CLI" enhance --dem "$WORK/dem.asc" --footprints "$WORK/far.geojson" --out "$WORK/x.tif"
expect_in "$WORK/outside.err" 'far\.geojson.*covers no pixel' "a footprint off the DEM names the file"
expect_rc missing 3 "$CLI" enhance --dem "$WORK/nope.tif" --footprints "$WORK/roof.geojson" --out "$WORK/x.tif"
expect_in "$WORK/missing.err" 'nope\.tif' "missing DEM is named"
printf 'not a raster\n' >"$WORK/garbage.tif"
expect_rc garbage 3 "$CLI" enhance --dem "$WORK/garbage.tif" --footprints "$WORK/roof.geojson" --out "$WORK/x.tif"
expect_rc bad_param 3 "$CLI" enhance --dem "$WORK/dem.asc" --footprints "$WORK/roof.geojson" \
  --out "$WORK/x.tif" --large-window 8
expect_rc no_out 2 "$CLI" enhance --dem "$WORK/dem.asc" --footprints "$WORK/roof.geojson"
expect_rc unknown_flag 2 "$CLI" enhance --dem "$WORK/dem.asc" --footprints "$WORK/roof.geojson" \
  --out "$WORK/x.tif" --frobnicate 1

if ((failures > 0)); then
  echo "e2e_enhance: $failures check(s) failed" >&2
  exit 1
fi
echo "e2e_enhance: all checks passed"
