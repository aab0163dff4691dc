#!/usr/bin/env bash
# Installs every Debian 12 (bookworm) package Delineo needs to build, test and run (clang and
# its sanitizer/libFuzzer runtimes for the fuzz preset, docs/testing.md).
# Idempotent: packages already present are skipped; apt runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git jq
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev libqt6concurrent6 qt6-tools-dev
  qt6-tools-dev-tools qt6-l10n-tools linguist-qt6 libqt6svg6 qt6-translations-l10n
  libopencv-dev libopencv-contrib-dev
  libeigen3-dev nlohmann-json3-dev
  libvtk9-dev libopenmpi-dev
  libgdal-dev gdal-bin
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth libgl1-mesa-dri mesa-utils
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
