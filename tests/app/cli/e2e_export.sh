#!/usr/bin/env bash
# End-to-end check of `delineo-cli export PROJECT --out FILE`: on the sample project after
# `run --detect`, CityJSON blocks on the ground next to each building (measuredHeight = roof -
# base) with the terrain (every triangle facing up, every index a vertex), the ground level's
# elevation added to every z, --roof-levels off (one block per building, the same file on the
# sample's one-level roofs), outlines by extension; bad input (missing or corrupt project, an
# output folder that does not exist, a wrong extension, a terrain step or roof-levels value out of
# its domain) exits 3 naming the file (a bad step has none), bad usage (unknown status, --terrain
# with outlines, no --out) exits 2.
# Usage: e2e_export.sh PATH/TO/delineo-cli WORKDIR      (needs jq)
E2E_NAME=e2e_export
source "$(dirname "$0")/e2e_lib.sh"
if ! command -v jq >/dev/null; then echo "e2e_export: jq is required"; exit 1; fi

expect_rc run_sample 0 "$CLI" run --sample "$WORK/sample" --detect --quiet
project="$WORK/sample/sample.delineo.json"
[[ -s $project ]] || { echo "e2e_export: no sample project"; exit 1; }

# ---- CityJSON with terrain --------------------------------------------------------------------
city="$WORK/sample/out.city.json"
expect_rc export_city 0 "$CLI" export "$project" --out "$city" --status all --terrain --quiet
expect_in "$WORK/export_city.out" "building\(s\) written to .*out.city.json, on the ground next to each; terrain: [0-9]+ vertices, [0-9]+ triangles" \
  "export reports the blocks and the terrain"
# jq_true NAME FILTER: the filter on $city must print true.
jq_true() { [[ $(jq -r "$2" "$city" 2>/dev/null) == true ]] || fail "$1 ($2)"; }
jq_true buildings '[.CityObjects[] | select(.type == "Building")] | length > 0'
jq_true bases '[.CityObjects[] | select(.type == "Building") | .attributes | has("ground_height_m")] | all'
jq_true measured_height '[.CityObjects[] | select(.type == "Building") | .attributes
  | (.measuredHeight - (.roof_height_m - .ground_height_m)) | fabs < 1e-6] | all'
# The blocks' lowest z is their base or, where the terrain along the outline is lower, below it
# (transform applied, 1 mm); never above the base.
jq_true foot_not_above_base '. as $c | [.CityObjects[] | select(.type == "Building")
  | ([.geometry[0].boundaries[][][][] | $c.vertices[.][2] * $c.transform.scale[2] + $c.transform.translate[2]] | min)
    - .attributes.ground_height_m < 0.001] | all'
jq_true terrain_type '.CityObjects.terrain.type == "TINRelief" and .CityObjects.terrain.geometry[0].type == "CompositeSurface"'
jq_true terrain_triangles '[.CityObjects.terrain.geometry[0].boundaries[] | length == 1 and (.[0] | length) == 3] | all'
jq_true indices_valid '(.vertices | length) as $n | [.CityObjects[].geometry[0].boundaries | .. | numbers | . >= 0 and . < $n] | all'
# Every terrain triangle faces up: z of (b - a) x (c - a) > 0 (x and y share their scale).
jq_true terrain_up '.vertices as $v | [.CityObjects.terrain.geometry[0].boundaries[][0]
  | [$v[.[0]], $v[.[1]], $v[.[2]]] as [$a, $b, $c]
  | ($b[0] - $a[0]) * ($c[1] - $a[1]) - ($c[0] - $a[0]) * ($b[1] - $a[1]) > 0] | all'
triangles=$(jq '.CityObjects.terrain.geometry[0].boundaries | length' "$city")
expect_in "$WORK/export_city.out" " $triangles triangles" "the printed triangle count is the file's"

# ---- roof levels: off writes one block per building; the sample's roofs have one level each -----
off="$WORK/sample/off.city.json"
expect_rc export_off 0 "$CLI" export "$project" --out "$off" --status all --terrain --roof-levels off --quiet
[[ $(jq '[.CityObjects[] | select(.type == "BuildingPart" or has("children"))] | length' "$off") == 0 ]] \
  || fail "--roof-levels off wrote BuildingParts"
[[ $(jq '[.CityObjects[] | select(.type == "Building") | has("geometry")] | all' "$off") == true ]] \
  || fail "--roof-levels off left a building without its block"
cmp -s "$city" "$off" || fail "roof levels on changed the blocks of one-level roofs"
jq '.parameters["roof-levels"] = {"roof-levels": "off"}' "$project" >"$WORK/sample/off.delineo.json"
expect_rc export_off_project 0 "$CLI" export "$WORK/sample/off.delineo.json" --out "$WORK/sample/off2.city.json" --status all --terrain --quiet
cmp -s "$off" "$WORK/sample/off2.city.json" || fail "the project's roof-levels off differs from --roof-levels off"
expect_rc bad_roof_levels 3 "$CLI" export "$project" --out "$WORK/x.city.json" --roof-levels maybe
expect_in "$WORK/bad_roof_levels.err" "roof-levels = 'maybe' is not one of on\|off" "the bad value is named"

# ---- the ground level's elevation raises every z, not the attributes ----------------------------
jq '.heightModel.groundElevation = 250' "$project" >"$WORK/sample/elevated.delineo.json"
elevated="$WORK/sample/elevated.city.json"
expect_rc export_elevated 0 "$CLI" export "$WORK/sample/elevated.delineo.json" --out "$elevated" --status all --terrain --quiet
lift=$(jq -n --slurpfile a "$city" --slurpfile b "$elevated" '($b[0].metadata.geographicalExtent[2] - $a[0].metadata.geographicalExtent[2]) * 1000 | round')
[[ $lift == 250000 ]] || fail "groundElevation 250 m moved the lowest z by $lift mm"
[[ $(jq -n --slurpfile a "$city" --slurpfile b "$elevated" '[$a[0].CityObjects[] | .attributes.ground_height_m] == [$b[0].CityObjects[] | .attributes.ground_height_m]') == true ]] \
  || fail "groundElevation changed the attributes"
expect_in "$elevated" "\\+ 250 m, the ground level's elevation" "the title says what the z are"

# ---- outlines by extension, statuses ------------------------------------------------------------
expect_rc export_geojson 0 "$CLI" export "$project" --out "$WORK/sample/out.geojson" --status automatic,accepted
automatic=$(jq '[.buildings[] | select(.status == "automatic" or .status == "accepted")] | length' "$project")
[[ $(jq '.features | length' "$WORK/sample/out.geojson") == "$automatic" ]] || fail "the GeoJSON does not hold the $automatic buildings"
expect_rc export_accepted 0 "$CLI" export "$project" --out "$WORK/sample/accepted.city.json" --quiet
expect_in "$WORK/export_accepted.out" "^export: 0 building\(s\) written" "by default only accepted buildings (none yet)"

# ---- errors -----------------------------------------------------------------------------------
expect_rc missing_project 3 "$CLI" export "$WORK/nope.delineo.json" --out "$WORK/x.city.json"
expect_in "$WORK/missing_project.err" "nope.delineo.json" "the missing project is named"
expect_rc bad_status 2 "$CLI" export "$project" --out "$WORK/x.city.json" --status finished
expect_in "$WORK/bad_status.err" "unknown status 'finished'" "the bad status is named"
expect_rc no_folder 3 "$CLI" export "$project" --out "$WORK/no/such/folder/x.city.json"
expect_in "$WORK/no_folder.err" "x.city.json" "the unusable output is named"
expect_rc wrong_extension 3 "$CLI" export "$project" --out "$WORK/sample/left.tif"
expect_in "$WORK/wrong_extension.err" "left.tif" "the output of the wrong kind is named"
expect_rc terrain_geojson 2 "$CLI" export "$project" --out "$WORK/x.geojson" --terrain
expect_rc no_out 2 "$CLI" export "$project"
expect_rc bad_step 3 "$CLI" export "$project" --out "$WORK/x.city.json" --terrain --terrain-step -1
[[ ! -e $WORK/x.city.json ]] || fail "a refused export wrote x.city.json"
echo "{" >"$WORK/corrupt.delineo.json"
expect_rc corrupt_project 3 "$CLI" export "$WORK/corrupt.delineo.json" --out "$WORK/x.city.json"
expect_in "$WORK/corrupt_project.err" "corrupt.delineo.json" "the corrupt project is named"

echo "e2e_export: $failures failure(s)"
[[ $failures == 0 ]]
