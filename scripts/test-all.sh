#!/usr/bin/env bash
# Every test, from a fresh Debian 12 machine: installs what is missing, builds the CI preset
# (GUI on, warnings are errors) and the headless preset (GUI off), and runs all tests of both.
# GUI tests that need GL run under Xvfb; the whole ctest run is wrapped in xvfb-run for them.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
bash scripts/install-deps.sh
bash scripts/build.sh ci
bash scripts/build.sh nogui
jobs="${DELINEO_TEST_JOBS:-2}"
echo "== headless build (GUI off)"
ctest --preset nogui -j "$jobs"
echo "== full build (GUI on)"
xvfb-run -a -s "-noreset -screen 0 1600x1000x24" ctest --preset ci -j "$jobs"
