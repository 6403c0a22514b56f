#!/usr/bin/env bash
# Installs Convoy's dependencies from Debian bookworm (idempotent) and builds it into build/.
#   scripts/setup.sh            install + build
#   CONVOY_SKIP_APT=1 ...       build only
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ccache pkg-config
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev libprotoc-dev protobuf-compiler python3-protobuf
  pybind11-dev nlohmann-json3-dev libvalijson-dev python3-dev python3-numpy python3-zstandard
  libgtest-dev
  libdart-dev libdart-external-ikfast-dev libdart-collision-bullet-dev libsdformat-dev
  libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri libassimp-dev libglm-dev libpng-dev libjpeg-dev
  libtinyxml2-dev libjemalloc-dev libopencv-dev python3-onnx python3-opencv
  clang libfuzzer-14-dev
  python3-grpcio mosquitto libmosquitto-dev
  sumo sumo-tools
  python3-torch
  slurm-wlm slurmctld slurmd slurm-client munge
  zlib1g-dev libzstd-dev libembree-dev libboost-dev libboost-python-dev
  ffmpeg
  chromium
  ros-core-dev python3-rospy python3-rosmaster python3-genpy python3-gencpp
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libtf2-msgs-dev libvisualization-msgs-dev
  python3-sensor-msgs python3-nav-msgs python3-geometry-msgs python3-tf2-msgs python3-visualization-msgs
  python3-message-filters
)

if [[ "${CONVOY_SKIP_APT:-0}" != 1 ]]; then
  missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]})); then
    SUDO=""
    [[ $(id -u) -ne 0 ]] && SUDO=sudo
    echo "== installing: ${missing[*]}"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
fi

# ccache keys paths relative to the clone, so that a fresh clone elsewhere finds the objects
# an earlier clone compiled (a warm cache is a quick build).
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}

echo "== building (Release) into build/"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build -j"$(nproc)"
echo "== built: build/bin/convoy, build/bin/NRPCoreSim"

# npm ci DIR: installs DIR's packages from its package-lock.json, unless the installed ones are
# already those (a stamp in node_modules records the lock file's hash).
npm_ci() {
  local sum stamp="$1/node_modules/.convoy-lock.sha1"
  sum=$(sha1sum <"$1/package-lock.json")
  [[ -f $stamp && $(cat "$stamp") == "$sum" ]] && return 0
  (cd "$1" && npm ci --no-audit --no-fund --loglevel=error) && echo "$sum" >"$stamp"
}
# The dashboard's build, unless dist/ was built from the same sources (a stamp in dist/).
dashboard_build() {
  local sum stamp=web/dashboard/dist/.convoy-sources.sha1
  sum=$(cd web/dashboard && find . -path ./node_modules -prune -o -path ./dist -prune -o \
    -type f -print | LC_ALL=C sort | xargs sha1sum | sha1sum)
  [[ -f $stamp && $(cat "$stamp") == "$sum" ]] && return 0
  (cd web/dashboard && npm run build) && echo "$sum" >"$stamp"
}

# Test instruments: the official MCAP library reads Convoy's recordings
# (tests/e2e/test_recording.py; skipped when it is not installed). With the machine's own
# Node.js and npm (Debian's npm package conflicts with a Node.js that bundles npm).
if command -v npm >/dev/null; then
  npm_ci tools/mcap_check ||
    echo "warning: npm ci in tools/mcap_check failed; the @mcap/core test will be skipped"
  # Foxglove's own protocol client watches a live run (tests/e2e/test_live.py).
  npm_ci tools/live_check ||
    echo "warning: npm ci in tools/live_check failed; the @foxglove/ws-protocol test will be skipped"
  # puppeteer-core drives Debian's chromium (above), headless, through the web dashboard
  # (tests/e2e/test_dashboard.py); it downloads no browser.
  npm_ci tools/dashboard_check ||
    echo "warning: npm ci in tools/dashboard_check failed; the dashboard test will be skipped"
  # The web dashboard that `convoy run --live` and `convoy view` serve at / (web/dashboard/dist,
  # linked as build/share/convoy/dashboard).
  { npm_ci web/dashboard && dashboard_build; } ||
    echo "warning: the web dashboard did not build; convoy run --live and convoy view show a text page at / instead"
fi
