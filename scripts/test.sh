#!/usr/bin/env bash
# Builds (if needed) and runs every test: unit tests (GoogleTest) and end-to-end tests.
# Tests labelled `long` (soak runs: the scenario suite, 20 repeats) are left out unless a label
# selection is given (-L / -LE): `scripts/test.sh -L long` runs them. Tests run in parallel,
# one per core (CONVOY_TEST_JOBS sets how many at once): each works in its own temp folder on
# ports the system picks, and the Slurm ones take turns (ctest RESOURCE_LOCK).
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}  # (setup.sh)
if [[ ! -x build/bin/convoy ]] || [[ "${CONVOY_REBUILD:-1}" == 1 ]]; then
  CONVOY_SKIP_APT=${CONVOY_SKIP_APT:-1} scripts/setup.sh >/dev/null
fi
cd build
labels=(-LE long)
for a in "$@"; do
  [[ "$a" == -L || "$a" == -LE || "$a" == --label-regex* || "$a" == --label-exclude* ]] && labels=()
done
ctest --output-on-failure -j"${CONVOY_TEST_JOBS:-$(nproc)}" "${labels[@]}" "$@"
