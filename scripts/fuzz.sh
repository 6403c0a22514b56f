#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang++ with ASan + UBSan) into build-fuzz/ when needed
# and runs them.
#   scripts/fuzz.sh TARGET SECONDS        fuzz one target for SECONDS
#   scripts/fuzz.sh all SECONDS           each target in turn
#   scripts/fuzz.sh regressions [TARGET]  run each target once over fuzz/regressions/TARGET/*
#   scripts/fuzz.sh build                 only configure and build
# The corpus grows in build-fuzz/corpus/TARGET (seeded from build-fuzz/seeds/TARGET and
# fuzz/regressions/TARGET); crashing inputs go to fuzz/crashes/TARGET/. Exits non-zero when a
# target crashed, timed out or ran out of memory. Logs: build-fuzz/logs/TARGET.log.
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}  # (setup.sh)

TARGETS=(config opendrive datapack proto python_codec sdf)
BUILD=build-fuzz

usage() {
  echo "usage: scripts/fuzz.sh {TARGET|all} SECONDS | regressions [TARGET] | build" >&2
  echo "targets: ${TARGETS[*]}" >&2
  exit 2
}

build() {
  mkdir -p "$BUILD"
  # One build at a time (ctest may start several fuzz entries).
  exec 9>"$BUILD/.lock"
  flock 9
  if [[ ! -f $BUILD/CMakeCache.txt ]]; then
    cmake -S . -B "$BUILD" -DCONVOY_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ \
      -DCMAKE_BUILD_TYPE=Fuzz -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
  fi
  cmake --build "$BUILD" -j"${CONVOY_FUZZ_JOBS:-2}" >"$BUILD/build.log" 2>&1 || {
    tail -50 "$BUILD/build.log"
    echo "fuzz build failed (log: $BUILD/build.log)" >&2
    exit 1
  }
  flock -u 9
}

check_target() {
  local t
  for t in "${TARGETS[@]}"; do [[ $t == "$1" ]] && return 0; done
  echo "unknown target '$1'" >&2
  usage
}

# Leaks are reported by libFuzzer per input and by LSan at exit; the Python target's embedded
# interpreter (numpy, OpenSSL) never frees its state, so it runs without leak checks.
sanitizer_env() {
  local leaks=1
  [[ $1 == python_codec ]] && leaks=0
  export ASAN_OPTIONS=abort_on_error=1:symbolize=1:detect_leaks=$leaks
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
}

fuzz_one() {
  local t=$1 seconds=$2
  local corpus=$BUILD/corpus/$t crashes=fuzz/crashes/$t log=$BUILD/logs/$t.log
  mkdir -p "$corpus" "$crashes" "$BUILD/logs"
  cp -n "$BUILD/seeds/$t"/* "$corpus"/ 2>/dev/null || true
  [[ -d fuzz/regressions/$t ]] && cp -n fuzz/regressions/"$t"/* "$corpus"/ 2>/dev/null || true
  local extra=()
  [[ $t == python_codec ]] && extra+=(-detect_leaks=0)
  # A fixed seed (the tests set CONVOY_FUZZ_SEED) makes a short run repeat the same inputs.
  [[ -n ${CONVOY_FUZZ_SEED:-} ]] && extra+=(-seed="$CONVOY_FUZZ_SEED")
  echo "== fuzzing $t for ${seconds}s (corpus $corpus)"
  local rc=0
  sanitizer_env "$t"
  "$BUILD/fuzz/$t" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$crashes/" -print_final_stats=1 "${extra[@]}" >"$log" 2>&1 || rc=$?
  grep -E '^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss_mb)' "$log" || true
  if ((rc != 0)); then
    tail -60 "$log"
    echo "== $t: CRASH (exit $rc); inputs in $crashes/, log $log" >&2
    return 1
  fi
  echo "== $t: no crash"
}

regressions_one() {
  local t=$1
  local files=()
  [[ -d fuzz/regressions/$t ]] && mapfile -t files < <(find fuzz/regressions/"$t" -type f | sort)
  ((${#files[@]})) || { echo "== $t: no regression inputs"; return 0; }
  sanitizer_env "$t"
  local extra=()
  [[ $t == python_codec ]] && extra+=(-detect_leaks=0)
  echo "== $t: ${#files[@]} regression inputs"
  "$BUILD/fuzz/$t" -timeout=10 -rss_limit_mb=2048 "${extra[@]}" "${files[@]}" \
    >"$BUILD/logs/regressions_$t.log" 2>&1 || {
    tail -60 "$BUILD/logs/regressions_$t.log"
    echo "== $t: a regression input crashed" >&2
    return 1
  }
}

(($# >= 1)) || usage
case $1 in
  build)
    build
    ;;
  regressions)
    build
    mkdir -p "$BUILD/logs"
    status=0
    if (($# >= 2)); then
      check_target "$2"
      regressions_one "$2" || status=1
    else
      for t in "${TARGETS[@]}"; do regressions_one "$t" || status=1; done
    fi
    exit $status
    ;;
  all)
    (($# == 2)) || usage
    build
    status=0
    for t in "${TARGETS[@]}"; do fuzz_one "$t" "$2" || status=1; done
    exit $status
    ;;
  *)
    (($# == 2)) || usage
    check_target "$1"
    build
    fuzz_one "$1" "$2"
    ;;
esac
