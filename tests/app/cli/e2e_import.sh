#!/usr/bin/env bash
# End-to-end check of `delineo-cli import PROJECT --outlines FILE`: a simulated scene's true footprints,
# shifted as an outdated map would be, become pending buildings with their source id; importing
# them again adds nothing; `run` outlines them and the export carries source_id beside each
# outline, closer to the truth than the map was. Bad input (missing file, an id field no outline
# has, a project that does not exist) exits 3 naming the problem; bad usage (no --outlines) exits 2.
# Usage: e2e_import.sh PATH/TO/delineo-cli WORKDIR      (needs jq)
set -u
E2E_NAME=e2e_import
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"
if ! command -v jq >/dev/null; then echo "e2e_import: jq is required"; exit 1; fi

S=$WORK/scene
expect_rc simulate 0 "$CLI" simulate --out "$S" --width 320 --height 240 --buildings 3 --trees 2 --seed 2
jq -n --arg l "$S/left.tif" --arg r "$S/right.tif" '{format: "delineo-project", version: 1, name: "import",
  images: {left: $l, right: $r}, buildings: []}' >"$WORK/p.delineo.json"

# The map: the true footprints shifted by (4, -3) px as an outdated map would be, with a ref id
# and nothing else (no roof interval: run proposes it).
jq '.features |= [to_entries[] | .value.properties = {ref: ("B" + (.key | tostring))}
     | .value.geometry.coordinates |= map(map([.[0] + 4, .[1] - 3])) | .value]' "$S/footprints_gt.geojson" >"$WORK/map.geojson"
n=$(jq '.features | length' "$WORK/map.geojson")
[[ $n -gt 0 ]] || fail "no footprint in the map"

expect_rc import 0 "$CLI" import "$WORK/p.delineo.json" --outlines "$WORK/map.geojson" --id-field ref
expect_in "$WORK/import.out" "import: $n of $n polygon\(s\) of .*map.geojson added as pending buildings" "every polygon added"
[[ $(jq '[.buildings[] | select(.status == "pending" and (.sourceId | startswith("B")))] | length' "$WORK/p.delineo.json") == "$n" ]] \
  || fail "the pending buildings do not carry their source id"
[[ $(jq -r '.buildings[0].history[0].action' "$WORK/p.delineo.json") == imported ]] || fail "no 'imported' history entry"
expect_rc import_again 0 "$CLI" import "$WORK/p.delineo.json" --outlines "$WORK/map.geojson"
expect_in "$WORK/import_again.out" "0 of $n .*; $n already buildings of the project" "a second import adds nothing"

expect_rc run 0 "$CLI" run "$WORK/p.delineo.json" --quiet
out=$(dirname "$WORK/p.delineo.json")/output/buildings.geojson
[[ $(jq '[.features[] | .properties.source_id | strings | startswith("B")] | length' "$out") == "$n" ]] \
  || fail "the export does not carry source_id"
expect_rc eval_map 0 "$CLI" eval-footprints --pred "$WORK/map.geojson" --truth "$S/footprints_gt.geojson" --json "$WORK/map_eval.json"
expect_rc eval_run 0 "$CLI" eval-footprints --pred "$out" --truth "$S/footprints_gt.geojson" --json "$WORK/run_eval.json"
above "$(mean_iou "$WORK/run_eval.json")" "$(mean_iou "$WORK/map_eval.json")" \
  || fail "the outlines ($(mean_iou "$WORK/run_eval.json")) are not closer to the truth than the map ($(mean_iou "$WORK/map_eval.json"))"

# ---- bad input ---------------------------------------------------------------------------------
expect_rc missing_file 3 "$CLI" import "$WORK/p.delineo.json" --outlines "$WORK/nope.geojson"
expect_in "$WORK/missing_file.err" "nope.geojson" "the missing file is named"
expect_rc wrong_field 3 "$CLI" import "$WORK/p.delineo.json" --outlines "$WORK/map.geojson" --id-field osm_id
expect_in "$WORK/wrong_field.err" "no outline has the attribute \"osm_id\" \(they have: ref\)" "the wrong field is named"
expect_rc missing_project 3 "$CLI" import "$WORK/none.delineo.json" --outlines "$WORK/map.geojson"
expect_rc no_outlines 2 "$CLI" import "$WORK/p.delineo.json"

exit $((failures > 0))
