#!/usr/bin/env bash
# End-to-end checks of delineo-cli on a generated scene: outputs exist and are consistent, and
# every bad input gives a clear message and the documented exit code.
# Usage: cli_e2e.sh PATH/TO/delineo-cli WORKDIR
set -uo pipefail
cli="$1"
work="$2"
rm -rf "$work"
mkdir -p "$work"
failures=0
passed=0

check() {  # check NAME EXPECTED_CODE EXPECTED_STDERR_SUBSTRING -- command...
  local name="$1" want="$2" needle="$3"
  shift 4
  "$@" >"$work/$name.out" 2>"$work/$name.err"
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, expected $want"; sed 's/^/  | /' "$work/$name.err" | tail -5
    failures=$((failures + 1)); return
  fi
  if [ -n "$needle" ] && ! grep -qiF -- "$needle" "$work/$name.err"; then
    echo "FAIL $name: stderr lacks '$needle'"; sed 's/^/  | /' "$work/$name.err" | tail -5
    failures=$((failures + 1)); return
  fi
  echo "ok   $name"
  passed=$((passed + 1))
}

has() { "$cli" --help | grep -q "^  $1 "; }

scene="$work/scene"
if has simulate; then
  check simulate 0 "" -- "$cli" simulate --out "$scene" --seed 3 --width 320 --height 240 --buildings 4 --trees 3
  for f in left.tif right.tif disparity_gt.tif occlusion_gt.tif dem_gt.tif labels_gt.tif footprints_gt.geojson scene.json; do
    if [ -s "$scene/$f" ]; then passed=$((passed + 1)); else echo "FAIL simulate wrote no $f"; failures=$((failures + 1)); fi
  done
  check simulate_usage 2 "out" -- "$cli" simulate --seed 3
  check simulate_bad_value 2 "width" -- "$cli" simulate --out "$work/x" --width abc
fi

if has eval-disparity && [ -s "$scene/disparity_gt.tif" ]; then
  check eval_disp_self 0 "" -- "$cli" eval-disparity --pred "$scene/disparity_gt.tif" --truth "$scene/disparity_gt.tif" --json "$work/self.json"
  if grep -q '"bad_1": *0' "$work/self.json" || grep -q '"bad_1":0' "$work/self.json"; then
    passed=$((passed + 1)); else echo "FAIL eval of GT against itself is not perfect"; cat "$work/self.json"; failures=$((failures + 1)); fi
  check eval_disp_missing 3 "nope.tif" -- "$cli" eval-disparity --pred "$work/nope.tif" --truth "$scene/disparity_gt.tif"
  head -c 3000 "$scene/disparity_gt.tif" >"$work/truncated.tif"
  check eval_disp_truncated 3 "truncated.tif" -- "$cli" eval-disparity --pred "$work/truncated.tif" --truth "$scene/disparity_gt.tif"
  gdal_create -q -of GTiff -outsize 100 80 -bands 1 -ot Float32 "$work/small.tif" >/dev/null 2>&1 \
    && check eval_disp_size_mismatch 3 "small.tif" -- "$cli" eval-disparity --pred "$work/small.tif" --truth "$scene/disparity_gt.tif"
  gdal_create -q -of GTiff -outsize 320 240 -bands 3 -ot Float32 "$work/threeband.tif" >/dev/null 2>&1 \
    && check eval_disp_band_count 3 "band" -- "$cli" eval-disparity --pred "$work/threeband.tif" --truth "$scene/disparity_gt.tif"
fi

if has eval-footprints && [ -s "$scene/footprints_gt.geojson" ]; then
  check eval_fp_self 0 "" -- "$cli" eval-footprints --pred "$scene/footprints_gt.geojson" --truth "$scene/footprints_gt.geojson" --json "$work/fp.json"
  echo '{"type": "FeatureCollection", "features": [ {"type": "Feature", ' >"$work/invalid.geojson"
  check eval_fp_invalid_json 3 "invalid.geojson" -- "$cli" eval-footprints --pred "$work/invalid.geojson" --truth "$scene/footprints_gt.geojson"
  cat >"$work/empty_polygon.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {"id": 1}, "geometry": {"type": "Polygon", "coordinates": [[[5,5],[5,5],[5,5],[5,5]]]}}]}
JSON
  check eval_fp_empty_polygon 3 "empty_polygon.geojson" -- "$cli" eval-footprints --pred "$work/empty_polygon.geojson" --truth "$scene/footprints_gt.geojson"
fi

if has match && [ -s "$scene/left.tif" ]; then
  check match_sgbm 0 "" -- "$cli" match --left "$scene/left.tif" --right "$scene/right.tif" --dmin 0 --dmax 48 --method sgbm --out "$work/d_sgbm.tif"
  check match_empty_range 3 "" -- "$cli" match --left "$scene/left.tif" --right "$scene/right.tif" --dmin 10 --dmax 5 --out "$work/d.tif"
  gdal_create -q -of GTiff -outsize 320 200 -bands 1 -ot Byte "$work/short.tif" >/dev/null 2>&1 \
    && check match_size_mismatch 3 "short.tif" -- "$cli" match --left "$scene/left.tif" --right "$work/short.tif" --dmin 0 --dmax 16 --out "$work/d.tif"
  gdal_create -q -of GTiff -outsize 320 240 -bands 2 -ot Byte "$work/twoband.tif" >/dev/null 2>&1 \
    && check match_two_bands 3 "twoband.tif" -- "$cli" match --left "$work/twoband.tif" --right "$scene/right.tif" --dmin 0 --dmax 16 --out "$work/d.tif"

  # Without --dmin/--dmax the range is estimated; it must hold the scene's true range.
  check match_estimated 0 "disparity range estimated from" -- "$cli" match --left "$scene/left.tif" --right "$scene/right.tif" --method sgbm --out "$work/d_est.tif"
  est=$(grep -o 'estimated from [0-9]* matches: \[-\?[0-9]*, -\?[0-9]*\]' "$work/match_estimated.err" | grep -o '\[.*\]' | tr -d '[],')
  true_min=$(grep -o '"disparity_min": *-\?[0-9]*' "$scene/scene.json" | grep -o -- '-\?[0-9]*$')
  true_max=$(grep -o '"disparity_max": *-\?[0-9]*' "$scene/scene.json" | grep -o -- '-\?[0-9]*$')
  read -r est_min est_max <<<"$est"
  if [ -n "$est_min" ] && [ -n "$true_min" ] && [ "$est_min" -le "$true_min" ] && [ "$est_max" -ge "$true_max" ]; then
    passed=$((passed + 1))
  else
    echo "FAIL estimated range [$est_min, $est_max] does not hold the scene's $true_min:$true_max"; failures=$((failures + 1))
  fi
  if [ -s "$work/d_est.tif" ]; then passed=$((passed + 1)); else echo "FAIL match_estimated wrote no map"; failures=$((failures + 1)); fi
  # A flag given alone overrides its end of the estimate.
  check match_dmin_only 0 "disparities 0..$est_max," -- "$cli" match --left "$scene/left.tif" --right "$scene/right.tif" --dmin 0 --method sgbm --out "$work/d_min.tif"
  check match_quiet_estimate 0 "" -- "$cli" match --left "$scene/left.tif" --right "$scene/right.tif" --method sgbm --quiet --out "$work/d_q.tif"
  if [ -s "$work/match_quiet_estimate.err" ]; then echo "FAIL match --quiet printed on stderr"; failures=$((failures + 1)); else passed=$((passed + 1)); fi
  # --help lists no made-up default range.
  if "$cli" match --help | grep -E -- '--dmi[n]|--dma[x]' | grep -q "default"; then
    echo "FAIL match --help shows a default for --dmin/--dmax"; failures=$((failures + 1)); else passed=$((passed + 1)); fi
  # A blank pair: no range can be estimated, the error says so and which flags to give.
  gdal_create -q -of GTiff -outsize 320 240 -bands 1 -ot Byte -burn 128 "$work/blank.tif" >/dev/null 2>&1 \
    && check match_blank_pair 4 "blank" -- "$cli" match --left "$work/blank.tif" --right "$work/blank.tif" --out "$work/d.tif" \
    && if grep -q -- "--dmin" "$work/match_blank_pair.err"; then passed=$((passed + 1)); else echo "FAIL blank-pair error does not name --dmin"; failures=$((failures + 1)); fi
fi

if has range && [ -s "$scene/left.tif" ]; then
  check range 0 "" -- "$cli" range --left "$scene/left.tif" --right "$scene/right.tif" --json "$work/range.json"
  if grep -q -- "^--dmin ${est_min:-x} --dmax ${est_max:-x}\$" "$work/range.out" && grep -q '"dmin"' "$work/range.json"; then
    passed=$((passed + 1)); else echo "FAIL range printed '$(cat "$work/range.out")', match estimated [$est_min, $est_max]"; failures=$((failures + 1)); fi
  [ -s "$work/blank.tif" ] && check range_blank 4 "blank" -- "$cli" range --left "$work/blank.tif" --right "$work/blank.tif"
  check range_bad_param 3 "percentile" -- "$cli" range --left "$scene/left.tif" --right "$scene/right.tif" --low-percentile 50 --high-percentile 50
fi

if has delineate && [ -s "$scene/footprints_gt.geojson" ] && has rough-init; then
  check rough_init 0 "" -- "$cli" rough-init --truth "$scene/footprints_gt.geojson" --grow 8 --out "$work/init.geojson"
  check delineate 0 "" -- "$cli" delineate --left "$scene/left.tif" --right "$scene/right.tif" --init "$work/init.geojson" --out "$work/fp.geojson"
  check delineate_roi_outside 3 "" -- "$cli" delineate --left "$scene/left.tif" --right "$scene/right.tif" --roi 5000,5000,50,50 --roof-disparity 10:20 --out "$work/x.geojson"
fi

if has simulate; then
  # Ctrl-C: the command stops at its next progress poll and exits with 130.
  "$cli" simulate --out "$work/big" --width 3000 --height 3000 --buildings 40 >"$work/sigint.out" 2>"$work/sigint.err" &
  pid=$!
  # Interrupt once it is working (its handler installed): a slow start (sanitizer builds, a
  # loaded machine) would otherwise get the signal before the handler is in place.
  for _ in $(seq 1 300); do
    grep -q "%" "$work/sigint.err" 2>/dev/null && break
    sleep 0.1
  done
  kill -INT "$pid"
  wait "$pid"
  rc=$?
  if [ "$rc" -eq 130 ] && grep -qi "canceled" "$work/sigint.err"; then
    echo "ok   sigint_cancels"; passed=$((passed + 1))
  else
    echo "FAIL sigint_cancels: exit $rc"; tail -3 "$work/sigint.err"; failures=$((failures + 1))
  fi
fi

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
