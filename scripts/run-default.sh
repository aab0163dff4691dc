#!/usr/bin/env bash
# The main job on the bundled default scene, from a fresh Debian 12 machine:
# installs what is missing, builds, generates the default scene (deterministic, seed 7),
# matches it, delineates every building from a rough rectangle, scores the result against the
# ground truth, and writes everything to out/default-scene/. When a display is present and the
# GUI is built, it then opens the GUI on the bundled sample project.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
bash scripts/install-deps.sh
bash scripts/build.sh default
cli="$root/build/default/bin/delineo-cli"
out="${DELINEO_OUT:-$root/out/default-scene}"
mkdir -p "$out"
echo "== Writing results to $out"

"$cli" simulate --out "$out" --seed 7 --width 800 --height 600 --buildings 10 --trees 12
dmin=$(jq '.disparity_min' "$out/scene.json")
dmax=$(jq '.disparity_max' "$out/scene.json")
"$cli" match --left "$out/left.tif" --right "$out/right.tif" --dmin "$dmin" --dmax "$dmax" \
  --out "$out/disparity.tif" --score "$out/score.tif"
"$cli" eval-disparity --pred "$out/disparity.tif" --truth "$out/disparity_gt.tif" \
  --json "$out/disparity_eval.json"
# The operator's rough input: each building's true outline replaced by its bounding rectangle
# grown by 8 px, with the roof disparity interval the operator would read off the histogram.
"$cli" rough-init --truth "$out/footprints_gt.geojson" --grow 8 --out "$out/init.geojson"
"$cli" delineate --left "$out/left.tif" --right "$out/right.tif" --init "$out/init.geojson" \
  --out "$out/footprints.geojson"
"$cli" eval-footprints --pred "$out/footprints.geojson" --truth "$out/footprints_gt.geojson" \
  --json "$out/footprints_eval.json"
echo "== Done: results in $out"

gui="$root/build/default/bin/delineo"
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] && [ -x "$gui" ] && [ -z "${CI:-}" ]; then
  exec "$gui"
fi
