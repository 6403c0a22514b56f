#!/usr/bin/env bash
# Builds (if needed) and runs every test: unit tests (GoogleTest) and end-to-end tests.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ ! -x build/bin/convoy ]] || [[ "${CONVOY_REBUILD:-1}" == 1 ]]; then
  CONVOY_SKIP_APT=${CONVOY_SKIP_APT:-1} scripts/setup.sh >/dev/null
fi
cd build
ctest --output-on-failure -j1 "$@"
