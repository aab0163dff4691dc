#!/usr/bin/env bash
# Every test, from a fresh Debian 12 machine: installs what is missing, builds the CI preset
# (GUI on, warnings are errors) and the headless preset (GUI off), and runs all tests of both.
# GUI tests that need GL run under Xvfb; the whole ctest run is wrapped in xvfb-run for them.
# Then the sanitizer builds (docs/testing.md): the headless tree under ASan + UBSan, the
# threaded parts under TSan, and a short run of each fuzzer when clang is there.
# DELINEO_SANITIZERS=0 leaves the sanitizer and fuzzing part out.
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

if [ "${DELINEO_SANITIZERS:-1}" = "0" ]; then exit 0; fi

# ASan + UBSan: every unit and e2e test but the slowest simulated-scene cases (each 5-15 s in
# Release, several times that under ASan), which the builds above run; their smaller siblings
# (same code paths on smaller scenes) stay in.
asan_skip='^(MatchSimulated\.|SimScene\.(FlatRoofOutlinesAreExactAtPixelCentres|EveryShapeAndRoofTypeOccurs|CourtyardsAreHolesWithGroundInside)$|DisparityRange\.SimulatedSceneRange)'
echo "== AddressSanitizer + UndefinedBehaviorSanitizer (headless)"
bash scripts/build.sh asan
# LeakSanitizer's own tracer now and then crashes at a program's exit after its tests passed
# ("LeakSanitizer has encountered a fatal error", google/sanitizers#1353): when the log shows it,
# the failed tests run once more; any failure without it, or failing again, stands.
asan_log="$(mktemp)"
trap 'rm -f "$asan_log"' EXIT
if ! ctest --preset asan -j "$jobs" -L 'unit|e2e' -E "$asan_skip" 2>&1 | tee "$asan_log"; then
  grep -q "LeakSanitizer has encountered a fatal error" "$asan_log" || exit 1
  echo "== LeakSanitizer's tracer crashed: the failed tests once more"
  ctest --preset asan --rerun-failed
fi

# TSan: the programs whose tests start threads (stereo workers, their cancel and the matcher,
# concurrent reads, progress and cancel); only those are built. RowOrderedTasks.RunWithHelpers…
# asserts that two threads overlap, which TSan's slower thread starts make a matter of chance.
echo "== ThreadSanitizer (threaded parts)"
tsan_targets=(test_stereo test_core test_io)
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j "${DELINEO_JOBS:-$(nproc)}" --target "${tsan_targets[@]}"
tsan_tests='^(RowOrderedTasks|WorkerPool|WorkerCancel|Progress|RasterIo\.ConcurrentReads|MatchSimulated\.(ACityBlockGivesTheSameBits|EveryStagePollsTheCancel))'
ctest --preset tsan -j "$jobs" -R "$tsan_tests" -E 'RowOrderedTasks\.RunWithHelpersStartsTheHelpersItself'

# Fuzzing: replay the seed corpus, then each target for a few seconds (docs/testing.md).
if command -v clang++ >/dev/null && [ -n "$(ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a 2>/dev/null)" ]; then
  echo "== fuzzing"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "${DELINEO_JOBS:-$(nproc)}" \
    --target fuzz_geojson fuzz_raster fuzz_project fuzz_cli_options
  ctest --preset fuzz -L fuzz
  bash scripts/fuzz.sh "${DELINEO_FUZZ_SECONDS:-10}"
else
  echo "== fuzzing skipped: clang and libFuzzer (libclang-rt-14-dev) not installed"
fi
