#!/usr/bin/env bash
# End-to-end check of the scene analysis commands on a small simulated scene with a 10 % slope:
# `dem` from the true disparity, `segment` (its four outputs, the classes against the truth),
# `detect` (one proposal per building, attributes `delineate --init` reads), then `delineate`
# from the proposals scored by eval-footprints; `run --detect` on the sample project (its outlines
# and LoD1 blocks); and the usage, input and output errors with their exit codes.
#
# Usage: e2e_segment.sh DELINEO_CLI WORK_DIR      (needs jq)
# Exit status 0 when every check passes; otherwise 1, with one line per failed check on stderr.
set -u
E2E_NAME=e2e_segment
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"

S=$WORK/scene
expect_rc simulate 0 "$CLI" simulate --out "$S" --width 400 --height 300 --buildings 4 --trees 4 --slope 10 --seed 3
TRUTHS=$(count "$S/footprints_gt.geojson" '"type": "Feature"')
[[ $TRUTHS -ge 3 ]] || fail "simulated scene has $TRUTHS buildings, expected at least 3"
expect_rc dem 0 "$CLI" dem --disparity "$S/disparity_gt.tif" --scene "$S/scene.json" --out "$WORK/dem.tif" --quiet

# 1. segment: four files; building pixels where the truth has roofs.
expect_rc segment 0 "$CLI" segment --dem "$WORK/dem.tif" --image "$S/left.tif" --scene "$S/scene.json" \
  --disparity "$S/disparity_gt.tif" --out "$WORK/seg"
expect_in "$WORK/segment.err" "ground and terrain model" "progress names the ground stage"
expect_in "$WORK/segment.out" "rounds \(stable\)" "the labelling settles"
for f in dtm.tif ndsm.tif labels.tif objects.geojson; do [[ -s $WORK/seg/$f ]] || fail "segment wrote no $f"; done
expect_in "$WORK/seg/objects.geojson" '"class": "building"' "objects carry their class"
for key in area_m2 mean_height_m max_height_m roof_disparity_min ground_disparity; do
  expect_in "$WORK/seg/objects.geojson" "\"$key\": " "objects carry $key"
done
# The DTM follows the terrain: compared with the true DEM, the error is the objects' heights,
# so its median (ground pixels are most of the scene) is small.
expect_rc dtm_eval 0 "$CLI" eval-disparity --pred "$WORK/seg/dtm.tif" --truth "$S/dem_gt.tif" \
  --truth-zero-unknown false --json "$WORK/dtm.json"
MEDIAN=$(tr -d '\n ' <"$WORK/dtm.json" | grep -Eo '"median_abs_error":[0-9.eE+-]+' | head -1 | cut -d: -f2)
above 0.3 "$MEDIAN" || fail "DTM median error $MEDIAN m against the true DEM is not under 0.3 m"

# 2. detect: one proposal per building; delineate takes the file unchanged.
expect_rc detect 0 "$CLI" detect --dem "$WORK/dem.tif" --image "$S/left.tif" --scene "$S/scene.json" \
  --disparity "$S/disparity_gt.tif" --out "$WORK/init.geojson" --objects "$WORK/objects.geojson" --quiet
PROPOSED=$(count "$WORK/init.geojson" '"type": "Feature"')
[[ $PROPOSED == "$TRUTHS" ]] || fail "$PROPOSED proposals for $TRUTHS buildings"
for key in id roof_disparity_min roof_disparity_max; do
  [[ $(count "$WORK/init.geojson" "\"$key\": ") == "$PROPOSED" ]] || fail "attribute $key missing on some proposals"
done
[[ -s $WORK/objects.geojson ]] || fail "detect --objects wrote nothing"
expect_rc delineate 0 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --init "$WORK/init.geojson" \
  --out "$WORK/outlines.geojson" --quiet
expect_rc eval 0 "$CLI" eval-footprints --pred "$WORK/outlines.geojson" --truth "$S/footprints_gt.geojson" \
  --json "$WORK/eval.json"
IOU=$(mean_iou "$WORK/eval.json")
# Measured 0.785 (one L-shaped building at 0.50, the others 0.90-0.95); quality is the benches'
# business (docs/dem.md), the floor catches a broken chain.
above "$IOU" 0.7 || fail "mean IoU $IOU of the outlines from the proposals is not above 0.7"

# 3. run --detect on the sample project: proposals become buildings, outlined and exported.
expect_rc run_detect 0 "$CLI" run --sample "$WORK/sample" --detect --quiet
expect_in "$WORK/run_detect.err" "new building\(s\) proposed" "run reports the proposals"
for f in dtm.tif ndsm.tif labels.tif objects.geojson buildings.geojson buildings.city.json; do
  [[ -s $WORK/sample/output/$f ]] || fail "run --detect wrote no $f"
done
# The sample's LoD1 blocks: one Building per exported outline with a roof height.
WITH_HEIGHT=$(jq '[.features[] | select(.properties.roof_height_m != null)] | length' "$WORK/sample/output/buildings.geojson")
BLOCKS=$(jq '[.CityObjects[] | select(.type == "Building")] | length' "$WORK/sample/output/buildings.city.json")
[[ $WITH_HEIGHT -gt 0 && $BLOCKS == "$WITH_HEIGHT" ]] \
  || fail "buildings.city.json has $BLOCKS Building(s) for $WITH_HEIGHT outline(s) with a roof height"
expect_in "$WORK/sample/sample.delineo.json" '"detected"' "the proposals' history says where they come from"
# A second run proposes nothing new: the buildings are already there.
expect_rc run_again 0 "$CLI" run "$WORK/sample/sample.delineo.json" --detect --quiet
expect_in "$WORK/run_again.err" " 0 new building\(s\) proposed" "known buildings are not proposed twice"

# 4. Errors: usage 2, inputs and parameters 3, each naming what is wrong.
expect_rc no_gsd 2 "$CLI" segment --dem "$WORK/dem.tif" --image "$S/left.tif" --out "$WORK/x"
expect_in "$WORK/no_gsd.err" "gsd.*scene" "a missing ground sample distance says what to give"
expect_rc no_disparity 2 "$CLI" detect --dem "$WORK/dem.tif" --image "$S/left.tif" --gsd 0.25 --out "$WORK/x.geojson"
expect_rc missing_dem 3 "$CLI" segment --dem "$WORK/nope.tif" --image "$S/left.tif" --gsd 0.25 --out "$WORK/x"
expect_in "$WORK/missing_dem.err" "nope\.tif" "a missing DEM is named"
expect_rc small_image 0 "$CLI" simulate --out "$WORK/small" --width 128 --height 96 --buildings 1 --trees 0 --seed 1
expect_rc mismatched 3 "$CLI" segment --dem "$WORK/dem.tif" --image "$WORK/small/left.tif" --gsd 0.25 --out "$WORK/x"
expect_in "$WORK/mismatched.err" "small/left\.tif" "an image of another size is named"
expect_rc bad_param 3 "$CLI" segment --dem "$WORK/dem.tif" --image "$S/left.tif" --gsd 0.25 --out "$WORK/x" \
  --critical-height 1 --region-threshold 1
expect_in "$WORK/bad_param.err" "critical" "the broken rule names the parameter"
expect_rc bad_gsd 2 "$CLI" segment --dem "$WORK/dem.tif" --image "$S/left.tif" --gsd -1 --out "$WORK/x"
expect_rc over_input 3 "$CLI" detect --dem "$WORK/dem.tif" --image "$S/left.tif" --gsd 0.25 \
  --disparity "$S/disparity_gt.tif" --out "$WORK/dem.tif"

if ((failures > 0)); then
  echo "e2e_segment: $failures check(s) failed" >&2
  exit 1
fi
echo "e2e_segment: all checks passed"
