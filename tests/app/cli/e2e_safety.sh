#!/usr/bin/env bash
# End-to-end checks of the output policy and of the numeric validation at the CLI's boundary
# (docs/conventions.md, "Outputs" and "Validation"): an output that is an input, a second
# output, a bad name or folder is refused before any work with exit 3 and the input untouched;
# a canceled run leaves the previous output as it was; non-finite or absurd numbers are refused.
#
# Usage: e2e_safety.sh DELINEO_CLI WORK_DIR
set -u
E2E_NAME=e2e_safety
source "$(dirname "${BASH_SOURCE[0]}")/e2e_lib.sh" "$@"
# unchanged NAME FILE: FILE still has the checksum kept in $WORK/NAME.sum.
keep() { sha1sum "$2" >"$WORK/$1.sum"; }
unchanged() { sha1sum -c --status "$WORK/$1.sum" || fail "$1: $2 was modified"; }

S=$WORK/scene
expect_rc simulate 0 "$CLI" simulate --out "$S" --width 320 --height 240 --buildings 3 --trees 2 --seed 2
expect_rc rough_init 0 "$CLI" rough-init --truth "$S/footprints_gt.geojson" --out "$WORK/init.geojson" --grow 8
keep left "$S/left.tif"
keep init "$WORK/init.geojson"
keep truth "$S/footprints_gt.geojson"

# Outputs that are inputs of the same run: refused before any work (exit 3), inputs untouched.
expect_rc match_out_is_left 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out "$S/left.tif"
expect_in "$WORK/match_out_is_left.err" "input of this run" "match --out = --left names the clash"
ln -s "$S/left.tif" "$WORK/link-to-left.tif"
expect_rc match_out_is_left_link 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out "$WORK/link-to-left.tif"
unchanged left "$S/left.tif"
expect_rc match_score_is_out 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out "$WORK/d.tif" --score "$WORK/d.tif"
expect_in "$WORK/match_score_is_out.err" "two outputs" "--score = --out names the clash"
expect_rc eval_json_is_truth 3 "$CLI" eval-footprints --pred "$WORK/init.geojson" --truth "$S/footprints_gt.geojson" --json "$S/footprints_gt.geojson"
expect_rc eval_disp_json_is_pred 3 "$CLI" eval-disparity --pred "$S/disparity_gt.tif" --truth "$S/disparity_gt.tif" --json "$S/scene.json" --mask "$S/scene.json"
unchanged truth "$S/footprints_gt.geojson"
expect_rc rough_init_out_is_truth 3 "$CLI" rough-init --truth "$S/footprints_gt.geojson" --out "$S/footprints_gt.geojson"
unchanged truth "$S/footprints_gt.geojson"
expect_rc delineate_out_is_init 3 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --init "$WORK/init.geojson" --out "$WORK/init.geojson"
unchanged init "$WORK/init.geojson"

# Bad output names are found before the work, not after it.
expect_rc out_missing_folder 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out "$WORK/no/such/d.tif"
expect_in "$WORK/out_missing_folder.err" "does not exist" "a missing output folder is named"
expect_rc out_png 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out "$WORK/d.png"
expect_in "$WORK/out_png.err" "\.tif" "a .png output is refused, saying .tif"
[[ -e $WORK/d.png ]] && fail "out_png: a file was written"
expect_rc out_empty 3 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --dmin 0 --dmax 40 --out ""
expect_rc out_shp 3 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --init "$WORK/init.geojson" --out "$WORK/o.shp"
for name in out_missing_folder out_png out_empty out_shp; do
  grep -q "%" "$WORK/$name.err" && fail "$name: work started before the output was checked"
done
echo '{"old": true}' >"$WORK/readonly.json"
chmod 444 "$WORK/readonly.json"
expect_rc json_read_only 3 "$CLI" eval-footprints --pred "$WORK/init.geojson" --truth "$S/footprints_gt.geojson" --json "$WORK/readonly.json"
expect_in "$WORK/readonly.json" '"old"' "a read-only report is not replaced"

# Numbers at the boundary: finite, in range, ordered.
expect_rc grow_nan 2 "$CLI" rough-init --truth "$S/footprints_gt.geojson" --out "$WORK/g.geojson" --grow nan
expect_rc grow_inf 2 "$CLI" rough-init --truth "$S/footprints_gt.geojson" --out "$WORK/g.geojson" --grow inf
[[ -e $WORK/g.geojson ]] && fail "rough-init --grow nan/inf wrote a file"
expect_rc roof_inf 2 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --roi 10,10,40,40 --roof-disparity 1:inf --out "$WORK/r.geojson"
expect_rc roof_reversed 2 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --roi 10,10,40,40 --roof-disparity 30:20 --out "$WORK/r.geojson"
expect_rc pred_scale_huge 2 "$CLI" eval-disparity --pred "$S/disparity_gt.tif" --truth "$S/disparity_gt.tif" --pred-scale 1e300
expect_rc ground_above_roof 3 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --roi 10,10,40,40 --roof-disparity 10:20 --ground-disparity 30:35 --disparity-range 0:60 --out "$WORK/r.geojson"
expect_in "$WORK/ground_above_roof.err" "ground" "a ground interval above the roof is named"
# A roof interval of 1e300 in a feature's properties: exit 3 naming the building's id, at once.
sed -E '0,/"roof_disparity_max": [0-9.]+/s//"roof_disparity_max": 1e300/' "$WORK/init.geojson" >"$WORK/huge.geojson"
sed -i -E '0,/"id": [0-9]+/s//"id": 77/' "$WORK/huge.geojson"
expect_rc roof_1e300 3 "$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --init "$WORK/huge.geojson" --out "$WORK/h.geojson"
expect_in "$WORK/roof_1e300.err" "id 77" "the bad property's building is named by its id"
[[ -e $WORK/h.geojson ]] && fail "roof_1e300: an output was written"

# Ctrl-C during a batch: exit 130, the previous output untouched.
cp "$WORK/init.geojson" "$WORK/previous.geojson"
keep previous "$WORK/previous.geojson"
# A batch long enough to interrupt: the scene's buildings 20 times over (one feature per line).
{
  echo '{ "type": "FeatureCollection", "features": ['
  for k in $(seq 20); do grep '"type": "Feature"' "$WORK/init.geojson" | sed -E 's/,?[[:space:]]*$/,/'; done | sed '$ s/,$//'
  echo ']}'
} >"$WORK/batch.geojson"
"$CLI" delineate --left "$S/left.tif" --right "$S/right.tif" --init "$WORK/batch.geojson" --disparity-range 0:60 \
  --out "$WORK/previous.geojson" >"$WORK/cancel.out" 2>"$WORK/cancel.err" &
pid=$!
for _ in $(seq 600); do grep -q "%" "$WORK/cancel.err" 2>/dev/null && break; sleep 0.05; done
kill -INT "$pid"
wait "$pid"
rc=$?
[[ $rc == 130 ]] || fail "delineate after Ctrl-C: exit $rc, expected 130"
unchanged previous "$WORK/previous.geojson"
ls -a "$WORK" | grep -q "partial" && fail "a temporary file was left after the cancel"

# Progress in a log: about one line per 10 % of the run, not one per stage.
expect_rc progress_log 0 "$CLI" match --left "$S/left.tif" --right "$S/right.tif" --out "$WORK/d.tif"
lines=$(grep -c "%" "$WORK/progress_log.err")
[[ $lines -le 12 ]] || fail "match wrote $lines progress lines to a log, expected at most 12"

# match --help gives no defaults for the range it estimates.
expect_rc match_help 0 "$CLI" match --help
grep -E -- "--dm(in|ax)" "$WORK/match_help.out" | grep -q "default" && fail "match --help shows a default range"

echo "e2e_safety: $failures check(s) failed"
[[ $failures == 0 ]]
