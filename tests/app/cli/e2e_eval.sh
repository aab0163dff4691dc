#!/usr/bin/env bash
# End-to-end checks of `delineo-cli eval-disparity` and `eval-footprints` on tiny hand-made
# inputs with known metrics. Rasters are ESRI ASCII grids (.asc, read by GDAL) and outlines are
# GeoJSON in pixel coordinates, so the script needs no other tool than bash and grep.
#
# Usage: e2e_eval.sh DELINEO_CLI WORK_DIR
# Exit status 0 when every check passes; otherwise 1, with one line per failed check on stderr.
set -u
E2E_NAME=e2e_eval
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"

grid() {  # grid FILE NCOLS NROWS VALUES...
  local file=$1 cols=$2 rows=$3
  shift 3
  {
    printf 'ncols %s\nnrows %s\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n' "$cols" "$rows"
    local i=0
    for v in "$@"; do
      printf '%s' "$v"
      i=$((i + 1))
      if ((i % cols == 0)); then printf '\n'; else printf ' '; fi
    done
  } >"$file"
}

# --- eval-disparity ------------------------------------------------------------------------------
# Truth: 0 and nodata are unknown (7 evaluated pixels); prediction errors on them are
# 0, 0.6, 1.5, (no prediction), 0, 0, 5.
grid "$WORK/truth.asc" 3 3 1 2 3 4 0 6 -9999 8 9
grid "$WORK/pred.asc" 3 3 1 2.6 4.5 -9999 5 6 1 8 14
grid "$WORK/roof.asc" 3 3 1 1 1 0 0 0 0 0 0

expect_rc disparity 0 "$CLI" eval-disparity --pred "$WORK/pred.asc" --truth "$WORK/truth.asc" \
  --truth-zero-unknown true --roof-mask "$WORK/roof.asc" --json "$WORK/disparity.json"
J=$WORK/disparity.json
expect_in "$J" '"evaluated_pixels": 7,' "disparity evaluated pixels"
expect_in "$J" '"density": 0\.857142' "disparity density 6/7"
expect_in "$J" '"bad_0_5": 0\.5,' "disparity bad-0.5"
expect_in "$J" '"bad_1": 0\.33333' "disparity bad-1"
expect_in "$J" '"bad_2": 0\.16666' "disparity bad-2"
expect_in "$J" '"bad_2_all": 0\.28571' "disparity bad-2 counting unpredicted pixels"
expect_in "$J" '"rms": 2\.14514' "disparity rms sqrt(27.61/6)"
expect_in "$J" '"roof": \{' "disparity roof sub-object"
expect_in "$J" '"bad_1": 0\.33333' "roof bad-1"
expect_in "$WORK/disparity.out" 'bad-2' "human table on stdout"

# The file declares a nodata value, so by default (auto) 0 is a true disparity: 8 pixels.
expect_rc disparity_auto 0 "$CLI" eval-disparity --pred "$WORK/pred.asc" --truth "$WORK/truth.asc" \
  --json "$WORK/disparity_auto.json"
expect_in "$WORK/disparity_auto.json" '"evaluated_pixels": 8,' "auto zero rule with declared nodata"

# 16-bit style truth (value = 256 d) with --truth-scale 1/256 and a mask excluding one pixel.
grid "$WORK/truth256.asc" 2 2 256 512 768 1024
grid "$WORK/pred_scaled.asc" 2 2 1 2 3 9
grid "$WORK/mask.asc" 2 2 1 1 1 0
expect_rc disparity_scale 0 "$CLI" eval-disparity --pred "$WORK/pred_scaled.asc" \
  --truth "$WORK/truth256.asc" --truth-scale 1/256 --mask "$WORK/mask.asc" --json "$WORK/scale.json"
expect_in "$WORK/scale.json" '"rms": 0\.0$' "truth scale 1/256 with mask"
expect_in "$WORK/scale.json" '"evaluated_pixels": 3,' "mask restricts the pixels"

# Bad inputs.
grid "$WORK/small.asc" 2 2 1 1 1 1
expect_rc disparity_size 3 "$CLI" eval-disparity --pred "$WORK/small.asc" --truth "$WORK/truth.asc"
expect_in "$WORK/disparity_size.err" 'small\.asc' "size mismatch names the prediction"
expect_in "$WORK/disparity_size.err" 'truth\.asc' "size mismatch names the truth"
expect_rc disparity_mask_size 3 "$CLI" eval-disparity --pred "$WORK/pred.asc" --truth "$WORK/truth.asc" \
  --mask "$WORK/small.asc"
expect_rc disparity_missing 3 "$CLI" eval-disparity --pred "$WORK/nope.tif" --truth "$WORK/truth.asc"
expect_in "$WORK/disparity_missing.err" 'nope\.tif' "missing file is named"
expect_rc disparity_usage 2 "$CLI" eval-disparity --pred "$WORK/pred.asc"
expect_rc disparity_scale_usage 2 "$CLI" eval-disparity --pred "$WORK/pred.asc" --truth "$WORK/truth.asc" \
  --truth-scale 1/0
printf 'not a raster\n' >"$WORK/garbage.tif"
expect_rc disparity_garbage 3 "$CLI" eval-disparity --pred "$WORK/garbage.tif" --truth "$WORK/truth.asc"

# --- eval-footprints -----------------------------------------------------------------------------
square() {  # square ID X0 Y0 SIDE → a GeoJSON feature
  local x1=$(($2 + $4)) y1=$(($3 + $4))
  printf '{"type":"Feature","properties":{"id":"%s"},"geometry":{"type":"Polygon","coordinates":[[[%s,%s],[%s,%s],[%s,%s],[%s,%s],[%s,%s]]]}}' \
    "$1" "$2" "$3" "$x1" "$3" "$x1" "$y1" "$2" "$y1" "$2" "$3"
}
collection() { printf '{"type":"FeatureCollection","features":[%s]}\n' "$(IFS=,; echo "$*")"; }
collection "$(square A 0 0 10)" "$(square B 100 100 10)" >"$WORK/truth.geojson"
collection "$(square p1 5 0 10)" "$(square p2 300 300 10)" >"$WORK/pred.geojson"

expect_rc footprints 0 "$CLI" eval-footprints --pred "$WORK/pred.geojson" --truth "$WORK/truth.geojson" \
  --json "$WORK/footprints.json"
F=$WORK/footprints.json
expect_in "$F" '"iou": 0\.33333' "footprint IoU of squares offset by half"
expect_in "$F" '"p1": 100\.0' "footprint p1 = 100 % for a half shift"
expect_in "$F" '"hausdorff": 5\.0' "footprint Hausdorff = shift"
expect_in "$F" '"polis": 2\.5' "footprint PoLiS = shift / 2"
expect_in "$F" '"truth_id": "A"' "footprint truth id from the id attribute"
expect_in "$F" '"pred_id": "p1"' "footprint pred id from the id attribute"
tr -d ' \n' <"$F" >"$WORK/footprints.flat"
expect_in "$WORK/footprints.flat" '"missed":\["B"\]' "missed truths"
expect_in "$WORK/footprints.flat" '"false":\["p2"\]' "false predictions"
expect_in "$WORK/footprints.flat" '"mean":\{[^}]*"corner_rms"' "mean object keys"

printf '{"type":"FeatureCollection",' >"$WORK/broken.geojson"
expect_rc footprints_broken 3 "$CLI" eval-footprints --pred "$WORK/broken.geojson" --truth "$WORK/truth.geojson"
expect_rc footprints_missing 3 "$CLI" eval-footprints --pred "$WORK/none.geojson" --truth "$WORK/truth.geojson"
expect_rc footprints_param 3 "$CLI" eval-footprints --pred "$WORK/pred.geojson" --truth "$WORK/truth.geojson" \
  --match-iou 2
expect_rc footprints_usage 2 "$CLI" eval-footprints --truth "$WORK/truth.geojson"

if ((failures > 0)); then
  echo "e2e_eval: $failures check(s) failed" >&2
  exit 1
fi
echo "e2e_eval: all checks passed"
