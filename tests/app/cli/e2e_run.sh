#!/usr/bin/env bash
# End-to-end check of `delineo-cli run PROJECT` on a project with pending buildings: a simulated
# pair, a project file written here with two rough rectangles (one with a roof interval, one
# without, so the proposed interval is used), then: the run computes the disparity, delineates
# both buildings, exports them (outlines and LoD1 blocks) and saves the project; a second run
# changes nothing; box-fitting as the project's method (a building's own method wins); a
# building without a roof height is left out of the blocks, a degenerate outline stops them
# (exit 4); a corrupt project, an unknown method and a missing image give exit code 3 naming
# the file.
# Usage: e2e_run.sh PATH/TO/delineo-cli WORKDIR      (needs jq)
set -uo pipefail
cli="$1"
work="$2"
rm -rf "$work"
mkdir -p "$work"
failures=0
passed=0

fail() { echo "FAIL $*"; failures=$((failures + 1)); }
pass() { echo "ok   $*"; passed=$((passed + 1)); }

# run_cli NAME EXPECTED_CODE STDERR_NEEDLE -- command...: exit code and stderr checked.
run_cli() {
  local name="$1" want="$2" needle="$3"
  shift 4
  "$@" >"$work/$name.out" 2>"$work/$name.err"
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    fail "$name: exit $rc, expected $want"; sed 's/^/  | /' "$work/$name.err" | tail -8; return 1
  fi
  if [ -n "$needle" ] && ! grep -qiF -- "$needle" "$work/$name.err"; then
    fail "$name: stderr lacks '$needle'"; sed 's/^/  | /' "$work/$name.err" | tail -8; return 1
  fi
  pass "$name"
}

# expect NAME JQ_FILTER FILE: the filter must print "true".
expect() {
  local name="$1" filter="$2" file="$3"
  if [ "$(jq -r "$filter" "$file" 2>/dev/null)" = "true" ]; then pass "$name"; else fail "$name ($filter)"; fi
}

if ! command -v jq >/dev/null; then echo "e2e_run: jq is required"; exit 1; fi
for command in simulate rough-init run; do
  if ! "$cli" --help | grep -q "^  $command "; then
    echo "e2e_run: this build has no '$command' command; nothing to test"
    exit 0
  fi
done

# ---- the scene and the project --------------------------------------------------------------
site="$work/site"
run_cli simulate 0 "" -- "$cli" simulate --out "$site" --seed 5 --width 256 --height 192 --buildings 3 --trees 1 \
  || exit 1
run_cli rough_init 0 "" -- "$cli" rough-init --truth "$site/footprints_gt.geojson" --grow 6 --out "$work/init.geojson" \
  || exit 1
count=$(jq '.features | length' "$work/init.geojson")
if [ "$count" -lt 2 ]; then fail "the simulated scene has $count building(s), need 2"; exit 1; fi

# Project file (docs/project-file.md), paths relative to its folder. Building 1 carries a roof
# interval around its true roof disparities; the others have none (`run` proposes one).
project="$site/site.delineo.json"
jq --argjson dmin "$(jq .disparity_min "$site/scene.json")" --argjson dmax "$(jq .disparity_max "$site/scene.json")" '
  { format: "delineo-project", version: 1, name: "e2e run",
    images: { left: "left.tif", right: "right.tif" },
    outputDir: "output",
    disparityRange: [$dmin, $dmax],
    heightModel: { groundDisparity: 8.0, metresPerPixel: 0.5, gsd: 0.25 },
    parameters: {},
    buildings: [ .features | to_entries[] | {
      id: (.key + 1),
      status: "pending",
      initial: [ .value.geometry.coordinates[0][:-1] ],
      outline: [],
      roofInterval: (if .key == 0 then [ (.value.properties.roof_disparity_min | floor) - 1,
                                         (.value.properties.roof_disparity_max | ceil) + 1 ] else null end),
      roofHeight: null, energy: null,
      history: [ { action: "picked", time: "2024-05-01T12:00:00Z", detail: "e2e" } ] } ] }
' "$work/init.geojson" >"$project"
expect project_written '.buildings | length >= 2' "$project"
given_interval=$(jq -c '.buildings[0].roofInterval' "$project")

# ---- first run: matching, both buildings, export, save ----------------------------------------
run_cli run_first 0 "disparity computed" -- "$cli" run "$project" --quiet
grep -q "$count building(s) delineated, 0 skipped" "$work/run_first.err" \
  && pass "run_first delineated $count" || fail "run_first summary: $(tail -1 "$work/run_first.err")"
grep -q '%$' "$work/run_first.err" && fail "--quiet still printed progress" || pass "--quiet prints no progress"
[ -s "$site/output/disparity.tif" ] && pass "disparity written" || fail "no output/disparity.tif"
[ -s "$site/output/buildings.geojson" ] && pass "outlines exported" || fail "no output/buildings.geojson"
expect export_has_all "(.features | length) == $count" "$site/output/buildings.geojson"
expect export_statuses '[.features[].properties.status] | all(. == "automatic")' "$site/output/buildings.geojson"
# The LoD1 blocks beside the outlines: one Building per exported outline with a roof height.
blocks="$site/output/buildings.city.json"
with_height=$(jq '[.features[] | select(.properties.roof_height_m != null)] | length' "$site/output/buildings.geojson")
grep -q "LoD1 blocks written to .*buildings.city.json" "$work/run_first.err" && pass "run_first reports the blocks" \
  || fail "run_first does not report buildings.city.json"
expect blocks_cityjson '.type == "CityJSON" and .version == "1.1"' "$blocks"
expect blocks_one_per_height "$with_height > 0 and ([.CityObjects[] | select(.type == \"Building\")] | length) == $with_height" "$blocks"
expect blocks_lod1_solids '[.CityObjects[].geometry[0] | .type == "Solid" and .lod == "1"] | all' "$blocks"
expect saved_disparity '.images.disparity == "output/disparity.tif"' "$project"
expect saved_statuses '[.buildings[].status] | all(. == "automatic")' "$project"
expect saved_outlines '[.buildings[].outline[0] | length] | all(. >= 4)' "$project"
expect saved_intervals '[.buildings[].roofInterval] | all(. != null and .[0] <= .[1])' "$project"
expect saved_given_interval_kept ".buildings[0].roofInterval == $given_interval" "$project"
expect saved_heights '[.buildings[].roofHeight] | all(. != null and . > 2)' "$project"
expect saved_energy '[.buildings[].energy] | all(. != null)' "$project"
expect saved_history '[.buildings[].history | map(.action) | index("delineated")] | all(. != null)' "$project"
# Each outline lies on its building: its vertex centroid is inside the operator's rectangle.
expect outlines_inside_rectangles '[.buildings[] |
    (.initial[0] | [(map(.[0]) | min), (map(.[1]) | min), (map(.[0]) | max), (map(.[1]) | max)]) as $box |
    (.outline[0] | [(map(.[0]) | add / length), (map(.[1]) | add / length)]) as $c |
    ($c[0] > $box[0] and $c[0] < $box[2] and $c[1] > $box[1] and $c[1] < $box[3])] | all' "$project"

# ---- second run: nothing pending, nothing recomputed ------------------------------------------
cp "$project" "$work/after_first.json"
disparity_time=$(stat -c %Y "$site/output/disparity.tif")
sleep 1
run_cli run_second 0 "disparity already present; 0 building(s) delineated" -- "$cli" run "$project" --quiet
cmp -s "$project" "$work/after_first.json" && pass "second run left the project unchanged" \
  || { fail "second run changed the project"; diff "$work/after_first.json" "$project" | head -10; }
[ "$(stat -c %Y "$site/output/disparity.tif")" = "$disparity_time" ] && pass "disparity not recomputed" \
  || fail "second run rewrote the disparity"

# ---- box-fitting as a project step: the project's method, a building's own method wins ----------
# Every building pending again; the project asks for box-fitting, building 1 for the active polygon.
jq '.method = "box-fitting" | .parameters.boxfit = {"min-area": 200}
    | .buildings |= map(.status = "pending" | .outline = [] | .energy = null | del(.energyTerms) | del(.method))
    | .buildings[0].method = "active-polygon"' "$work/after_first.json" >"$site/boxfit.delineo.json"
run_cli run_boxfit 0 "$((count - 1)) building(s) outlined by box-fitting" -- "$cli" run "$site/boxfit.delineo.json" --quiet
expect boxfit_methods '.buildings[0].method == "active-polygon" and ([.buildings[1:][].method] | all(. == "box-fitting"))' \
  "$site/boxfit.delineo.json"
expect boxfit_project_method '.method == "box-fitting"' "$site/boxfit.delineo.json"
expect boxfit_statuses '[.buildings[].status] | all(. == "automatic")' "$site/boxfit.delineo.json"
expect boxfit_history '[.buildings[1:][].history[-1].detail | startswith("delineo-cli run, box-fitting, ")] | all' \
  "$site/boxfit.delineo.json"
expect boxfit_heights '[.buildings[].roofHeight] | all(. != null and . > 2)' "$site/boxfit.delineo.json"
expect boxfit_outlines_inside_rectangles '[.buildings[1:][] |
    (.initial[0] | [(map(.[0]) | min), (map(.[1]) | min), (map(.[0]) | max), (map(.[1]) | max)]) as $box |
    (.outline[0] | [(map(.[0]) | add / length), (map(.[1]) | add / length)]) as $c |
    (.outline[0] | length >= 4) and ($c[0] > $box[0] and $c[0] < $box[2] and $c[1] > $box[1] and $c[1] < $box[3])] | all' \
  "$site/boxfit.delineo.json"
expect boxfit_export_methods '[.features[].properties.method] | (.[0] == "active-polygon" and (.[1:] | all(. == "box-fitting")))' \
  "$site/output/buildings.geojson"
# Box-fitting needs heights: without a DEM nor a height model the building is skipped (exit 4).
jq '.heightModel.metresPerPixel = 0 | .buildings[1].status = "pending" | .buildings[1].outline = []' \
  "$site/boxfit.delineo.json" >"$site/noheights.delineo.json"
run_cli run_boxfit_no_heights 4 "box-fitting needs heights" -- "$cli" run "$site/noheights.delineo.json" --quiet
expect noheights_still_pending '.buildings[1].status == "pending"' "$site/noheights.delineo.json"
# An unknown method is a corrupt project (exit 3), named.
jq '.method = "snakes"' "$site/boxfit.delineo.json" >"$site/badmethod.delineo.json"
run_cli run_bad_method 3 "method" -- "$cli" run "$site/badmethod.delineo.json" --quiet

# ---- exclusion mask (images.exclude): an empty one changes nothing; a mis-sized one is refused --
run_cli simulate_empty 0 "" -- "$cli" simulate --out "$work/empty" --seed 5 --width 256 --height 192 --buildings 0 --trees 0 \
  || exit 1
jq --arg mask "$work/empty/labels_gt.tif" \
  '.images.exclude = $mask | .buildings |= map(.status = "pending" | .outline = [])' \
  "$work/after_first.json" >"$site/masked.delineo.json"
run_cli run_masked 0 "disparity already present" -- "$cli" run "$site/masked.delineo.json" --quiet
expect masked_same_outlines "[.buildings[].outline] == $(jq -c '[.buildings[].outline]' "$work/after_first.json")" \
  "$site/masked.delineo.json"
run_cli simulate_small 0 "" -- "$cli" simulate --out "$work/small" --seed 5 --width 128 --height 96 --buildings 0 --trees 0 \
  || exit 1
jq --arg mask "$work/small/labels_gt.tif" '.images.exclude = $mask | .buildings[0].status = "pending"' \
  "$work/after_first.json" >"$site/badmask.delineo.json"
run_cli run_bad_mask 3 "small/labels_gt.tif" -- "$cli" run "$site/badmask.delineo.json" --quiet

# ---- bad projects: exit 3, the message names the file ----------------------------------------
printf '{"format": "delineo-project", "version": 1, "images": ' >"$work/corrupt.delineo.json"
run_cli run_corrupt 3 "corrupt.delineo.json" -- "$cli" run "$work/corrupt.delineo.json" --quiet
jq '.images.right = "gone.tif" | .buildings[0].status = "pending" | .buildings[0].outline = []' \
  "$project" >"$site/missing.delineo.json"
run_cli run_missing_image 3 "gone.tif" -- "$cli" run "$site/missing.delineo.json" --quiet
expect missing_project_untouched '.buildings[0].status == "pending"' "$site/missing.delineo.json"
run_cli run_no_project 3 "nope.delineo.json" -- "$cli" run "$work/nope.delineo.json" --quiet
run_cli run_usage 2 "" -- "$cli" run

# ---- what a run must never lose or overwrite --------------------------------------------------
# Bad parameters are found at load (exit 3), before any matching.
jq '.parameters.delineation = {"occlusion": -5} | .images.disparity = "" |
    .buildings |= map(.status = "pending" | .outline = [])' "$work/after_first.json" >"$site/badparams.delineo.json"
run_cli run_bad_params 3 "parameters.delineation" -- "$cli" run "$site/badparams.delineo.json" --quiet
grep -q "matching" "$work/run_bad_params.err" && fail "run_bad_params: matching ran before the check" \
  || pass "bad parameters found before matching"
# An output folder that would put disparity.tif on the left image: refused, the image untouched.
mkdir -p "$work/clash"
cp "$site/left.tif" "$work/clash/disparity.tif"
sum=$(sha1sum <"$work/clash/disparity.tif")
jq --arg d "$work/clash" '.images.left = ($d + "/disparity.tif") | .images.disparity = "" | .outputDir = $d' \
  "$work/after_first.json" >"$site/clash.delineo.json"
run_cli run_output_is_input 3 "input of this run" -- "$cli" run "$site/clash.delineo.json" --quiet
[ "$(sha1sum <"$work/clash/disparity.tif")" = "$sum" ] && pass "the clashing image is untouched" \
  || fail "run overwrote the left image"
# Unknown keys survive a save; the file mode is kept; a symlinked project stays a link.
jq '.buildings[0].status = "pending" | .buildings[0].outline = [] | .myTool = {"kept": 1} |
    .buildings[0].reviewer = "ann" | .parameters.delineation = {"future-parameter": 3}' \
  "$work/after_first.json" >"$site/real.delineo.json"
chmod 640 "$site/real.delineo.json"
ln -sf "real.delineo.json" "$site/link.delineo.json"
run_cli run_through_link_quiet_first 0 "" -- "$cli" run --quiet "$site/link.delineo.json"
[ -L "$site/link.delineo.json" ] && pass "the project link is still a link" || fail "run replaced the link by a file"
[ "$(stat -c %a "$site/real.delineo.json")" = "640" ] && pass "the project's mode is kept" \
  || fail "mode $(stat -c %a "$site/real.delineo.json"), expected 640"
expect unknown_keys_kept '.myTool.kept == 1 and .buildings[0].reviewer == "ann" and
    .parameters.delineation["future-parameter"] == 3 and .buildings[0].status == "automatic"' "$site/real.delineo.json"
# A read-only project is not overwritten.
jq '.buildings[0].status = "pending" | .buildings[0].outline = []' "$work/after_first.json" >"$site/locked.delineo.json"
chmod 444 "$site/locked.delineo.json"
run_cli run_read_only 3 "read-only" -- "$cli" run --quiet "$site/locked.delineo.json"
expect read_only_untouched '.buildings[0].status == "pending"' "$site/locked.delineo.json"
# The blocks leave out a building without a roof height, naming it; a degenerate outline stops
# the blocks only (exit 4, named), the outlines and the project are still written.
jq '.outputDir = "blocks-out" | .buildings[0].roofHeight = null | .buildings[0].status = "accepted"' \
  "$work/after_first.json" >"$site/noroof.delineo.json"
run_cli run_block_left_out 0 "not in buildings.city.json: building 1: no roof height" -- \
  "$cli" run "$site/noroof.delineo.json" --quiet
expect blocks_left_out "(.CityObjects | length) == $((count - 1)) and (.CityObjects | has(\"building-1\") | not)" \
  "$site/blocks-out/buildings.city.json"
jq '.outputDir = "degenerate-out" | .buildings[0].outline = [[[10,10],[20,20],[30,30]]] | .buildings[0].status = "accepted"' \
  "$work/after_first.json" >"$site/degenerate.delineo.json"
run_cli run_degenerate_block 4 "buildings.city.json not written: building 1's outline is degenerate" -- \
  "$cli" run "$site/degenerate.delineo.json" --quiet
[ -s "$site/degenerate-out/buildings.geojson" ] && [ ! -e "$site/degenerate-out/buildings.city.json" ] \
  && pass "a degenerate outline stops the blocks only" || fail "degenerate outline: wrong outputs"
expect degenerate_project_saved '.buildings[0].status == "accepted"' "$site/degenerate.delineo.json"

# --sample never replaces someone else's images; a relative folder works.
mkdir -p "$work/mine"
echo "my image" >"$work/mine/left.tif"
run_cli sample_over_user_files 3 "left.tif" -- "$cli" run --sample "$work/mine" --quiet
grep -q "my image" "$work/mine/left.tif" && pass "the user's left.tif is untouched" || fail "--sample replaced left.tif"
(cd "$work" && "$cli" run --sample rel-sample --quiet >"$work/sample_relative.out" 2>"$work/sample_relative.err") \
  && [ -s "$work/rel-sample/output/disparity.tif" ] && pass "run --sample with a relative folder" \
  || { fail "run --sample rel-sample"; tail -3 "$work/sample_relative.err"; }

echo "e2e_run: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
