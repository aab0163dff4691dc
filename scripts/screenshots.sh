#!/usr/bin/env bash
# Retakes the user guide's screenshots (docs/images/) from the real-pair scenario: the operator's
# whole job on the Toulouse 0051 pair of ../shared/data (tests/gui/app/test_real_pair.cpp).
# Usage: scripts/screenshots.sh [BUILD_DIR]   (default: build/default)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/default}"
test="$build/tests/gui/app/test_gui_real_pair"
if [[ ! -x "$test" ]]; then
  echo "screenshots: $test not found; build the 'test_gui_real_pair' target first" >&2
  exit 2
fi
data="${DELINEO_DATA_DIR:-$root/../shared/data}"
if [[ ! -d "$data/aerial-toulouse" ]]; then
  echo "screenshots: the real pairs are not in $data (set DELINEO_DATA_DIR)" >&2
  exit 2
fi
out="$root/docs/images"
mkdir -p "$out"
DELINEO_DATA_DIR="$data" DELINEO_SCREENSHOT_DIR="$out" QT_QPA_PLATFORM=xcb \
  xvfb-run -a -s "-noreset -screen 0 1600x1000x24" "$test"
ls -l "$out"/*.png
