#!/usr/bin/env bash
# End-to-end check of `delineo-cli boxfit` on a small simulated scene: simulate, rough-init
# (bounding rectangles grown by 8 px), boxfit on the true DEM, eval-footprints. Checks the mean
# IoU against a floor, the output attributes and the boxes file; then a disparity map as input,
# the whole-image mode, and the usage, input and processing errors with their exit codes.
#
# Usage: e2e_boxfit.sh DELINEO_CLI WORK_DIR
# Exit status 0 when every check passes; otherwise 1, with one line per failed check on stderr.
set -u
E2E_NAME=e2e_boxfit
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"

S=$WORK/scene
# Seed 2 at 320x240 gives 3 flat-roofed buildings (U, rectangle and angled footprints).
expect_rc simulate 0 "$CLI" simulate --out "$S" --width 320 --height 240 --buildings 3 --trees 2 --seed 2
expect_rc rough_init 0 "$CLI" rough-init --truth "$S/footprints_gt.geojson" --out "$WORK/init.geojson" --grow 8
TRUTHS=$(count "$S/footprints_gt.geojson" '"type": "Feature"')
[[ $TRUTHS -ge 2 ]] || fail "simulated scene has $TRUTHS buildings, expected at least 2"

# 1. Batch on the true DEM: one outline per init with its attributes, the boxes beside.
OUT=$WORK/out.geojson
expect_rc boxfit 0 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --init "$WORK/init.geojson" \
  --out "$OUT" --boxes "$WORK/boxes.geojson"
expect_in "$WORK/boxfit.err" "box-fitting: boxes" "progress names the box-fitting stages"
[[ $(count "$OUT" '"type": "Feature"') == "$TRUTHS" ]] || fail "one outline per init expected"
for key in id method boxes area vertices energy roof_height_m status; do
  [[ $(count "$OUT" "\"$key\": ") == "$TRUTHS" ]] || fail "attribute $key missing on some outputs"
done
[[ $(count "$OUT" '"method": "box-fitting"') == "$TRUTHS" ]] || fail "method is not box-fitting"
expect_in "$OUT" '"boxes": [1-9][0-9]*' "box count is a positive integer"
BOXES=$(count "$WORK/boxes.geojson" '"type": "Feature"')
[[ $BOXES -ge $TRUTHS ]] || fail "boxes file has $BOXES boxes, expected at least one per building"
expect_in "$WORK/boxes.geojson" '"building_id": 1' "boxes carry their building's id"
expect_rc eval 0 "$CLI" eval-footprints --pred "$OUT" --truth "$S/footprints_gt.geojson" --json "$WORK/eval.json"
IOU=$(mean_iou "$WORK/eval.json")
# Measured 0.921 on this scene; the floor leaves a margin for changes of the simulator.
above "$IOU" 0.85 || fail "mean IoU $IOU is not above the floor 0.85"

# 2. A disparity map (here the simulator's) through the height model gives the same outlines.
M=$(grep -Eo '"metres_per_disparity": [0-9.]+' "$S/scene.json" | grep -Eo '[0-9.]+$')
expect_rc from_disparity 0 "$CLI" boxfit --disparity "$S/disparity_gt.tif" --metres-per-pixel "$M" \
  --image "$S/left.tif" --init "$WORK/init.geojson" --out "$WORK/disp.geojson" --quiet
[[ -s "$WORK/from_disparity.err" ]] && fail "--quiet still printed: $(head -c 200 "$WORK/from_disparity.err")"
expect_rc eval_disp 0 "$CLI" eval-footprints --pred "$WORK/disp.geojson" --truth "$S/footprints_gt.geojson" \
  --json "$WORK/eval_disp.json"
above "$(mean_iou "$WORK/eval_disp.json")" 0.85 || fail "IoU from the disparity map $(mean_iou "$WORK/eval_disp.json") below 0.85"

# 3. Whole image (no init): every building segment, at least the buildings' count minus one.
expect_rc whole 0 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --out "$WORK/whole.geojson"
[[ $(count "$WORK/whole.geojson" '"method": "box-fitting"') -ge $((TRUTHS - 1)) ]] || fail "whole-image mode found too few buildings"

# 4. Errors: usage (2), bad input naming the file (3), nothing found (4).
expect_rc no_height 2 "$CLI" boxfit --image "$S/left.tif" --roi 10,10,50,50 --out "$WORK/x.geojson"
expect_rc both_heights 2 "$CLI" boxfit --dem "$S/dem_gt.tif" --disparity "$S/disparity_gt.tif" \
  --image "$S/left.tif" --out "$WORK/x.geojson"
expect_rc init_and_roi 2 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --init "$WORK/init.geojson" \
  --roi 10,10,50,50 --out "$WORK/x.geojson"
expect_rc bad_param 3 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --angle-step 0 --out "$WORK/x.geojson"
# An id that is not a number is refused before any work, naming the feature (as delineate does).
sed -E '0,/"id": [0-9]+/s//"id": "first"/' "$WORK/init.geojson" >"$WORK/bad_id.geojson"
expect_rc bad_id 3 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --init "$WORK/bad_id.geojson" \
  --out "$WORK/x.geojson"
expect_in "$WORK/bad_id.err" "feature 1: property id" "a malformed id names the feature"
expect_rc small 0 "$CLI" simulate --out "$WORK/small" --width 200 --height 150 --buildings 1 --trees 0 --seed 3
expect_rc mismatched 3 "$CLI" boxfit --dem "$WORK/small/dem_gt.tif" --image "$S/left.tif" --out "$WORK/x.geojson"
expect_in "$WORK/mismatched.err" "small/dem_gt.tif" "the size error names the DEM"
expect_rc roi_outside 3 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --roi 900,900,40,40 --out "$WORK/x.geojson"
expect_rc flat_roi 4 "$CLI" boxfit --dem "$S/dem_gt.tif" --image "$S/left.tif" --roi 2,2,12,12 --out "$WORK/x.geojson"
expect_in "$WORK/flat_roi.err" "above the ground" "a ROI on the ground says nothing stands above it"

if ((failures > 0)); then
  echo "e2e_boxfit: $failures check(s) failed" >&2
  exit 1
fi
echo "e2e_boxfit: all checks passed (mean IoU $IOU over $TRUTHS buildings)"
