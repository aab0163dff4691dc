#!/usr/bin/env bash
# Takes a screenshot of each main state of the GUI (sample project opened, building picked,
# delineated, corrected, accepted + DEM, 3D view) into docs/images/.
# Usage: scripts/screenshots.sh [BUILD_DIR]   (default: build/default)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/default}"
out="$root/docs/images"
mkdir -p "$out"
if [[ ! -x "$build/bin/delineo" ]]; then
  echo "screenshots: $build/bin/delineo not found; build the 'delineo' target first" >&2
  exit 2
fi
# A private settings/data home so the tour starts from the default layout and its own sample.
home="$(mktemp -d)"
trap 'rm -rf "$home"' EXIT
XDG_CONFIG_HOME="$home/config" XDG_DATA_HOME="$home/data" QT_QPA_PLATFORM=xcb \
  xvfb-run -a -s "-screen 0 1600x1000x24" "$build/bin/delineo" --screenshot-dir "$out"
ls -l "$out"/*.png
