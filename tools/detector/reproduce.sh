#!/bin/bash
# Makes Convoy's detector from nothing: renders its training and held-out data with
# tools/dataset/make_dataset.py, then trains and exports it with tools/detector/train.py.
# The shipped models/detector was made by
#
#   tools/detector/reproduce.sh WORK_DIR            # all weathers (the shipped model)
#   tools/detector/reproduce.sh WORK_DIR clear      # the same frames, clear weather only
#
# Writes WORK_DIR/train_<all|clear>/<path>/ (COCO folders), WORK_DIR/eval_<weather>/ (the
# held-out city westbound path, seeds 950-951, in clear, rain, fog and night) and
# WORK_DIR/model_<all|clear>/ (convoy_detector.onnx, classes.txt, model.json,
# training.json). Folders already complete (with runs.json) are kept. About 1 h of rendering
# and 1 h of training on 2 cores. BUILD=... picks the build (default build/); THREADS=...
# torch's threads (default 1, as the shipped model was trained: other counts sum in another
# order).
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,15p' "$0"; exit 2; fi
HERE="$(cd "$(dirname "$0")" && pwd)"
REPO="$(dirname "$(dirname "$HERE")")"
WORK="$(mkdir -p "$1" && cd "$1" && pwd)"
SET="${2:-all}"
case "$SET" in all|clear) ;; *) echo "reproduce.sh: the set is 'all' or 'clear', not '$SET'" >&2; exit 2;; esac
cd "$REPO"
PY=/usr/bin/python3
MD="$PY tools/dataset/make_dataset.py"
B="--build ${BUILD:-$REPO/build}"
C=experiments/city_traffic/simulation_config.json
P=experiments/autonomous_driving/simulation_config_control.json
V="--vary-models car=0.5,bus=0.25,truck=0.25"
path() { echo "--set gazebo.GazeboWorldFile=city_world_$1.sdf --env car_ctl_engine:CONVOY_EGO_ROUTE=ego_route_$1.csv --env car_ctl_engine:CONVOY_EGO_ROUTE_SKIP=$2"; }
done_() { [ -f "$1/runs.json" ]; }
# Held out: the city westbound path (never in training), one set per weather.
for k in clear rain fog night; do
  done_ "$WORK/eval_$k" || $MD $C --out "$WORK/eval_$k" --runs 2 --seed 950 --seconds 80 --every 15 --weather $k $B $(path west 25)
done
# Training: the city eastbound, northbound, southbound and loop paths (each run its own
# vehicle models) and the Parkring lap; each run's weather in turn (or clear only).
if [ "$SET" = all ]; then
  W=(clear,rain,night,fog,snow,dusk fog,snow,clear,dusk,night,rain dusk,rain,fog,clear,night,snow night,clear,snow,rain,dusk,fog rain,fog,night)
else
  W=(clear clear clear clear clear)
fi
T="$WORK/train_$SET"
done_ "$T/east"  || $MD $C --out "$T/east"  --runs 6 --seed 900 --seconds 60 --every 15 --weather ${W[0]} $V $B
done_ "$T/north" || $MD $C --out "$T/north" --runs 6 --seed 910 --seconds 60 --every 15 --weather ${W[1]} $V $B $(path north 10)
done_ "$T/south" || $MD $C --out "$T/south" --runs 6 --seed 920 --seconds 60 --every 15 --weather ${W[2]} $V $B $(path south 10)
done_ "$T/loop"  || $MD $C --out "$T/loop"  --runs 6 --seed 930 --seconds 60 --every 15 --weather ${W[3]} $V $B $(path loop 10)
done_ "$T/parkring" || $MD $P --out "$T/parkring" --runs 3 --seed 100 --seconds 180 --every 20 --weather ${W[4]} $B
$PY tools/detector/train.py --data "$T/east" --data "$T/north" --data "$T/south" --data "$T/loop" --data "$T/parkring" \
  --val "$WORK/eval_clear" --val "$WORK/eval_rain" --val "$WORK/eval_fog" --val "$WORK/eval_night" \
  --out "$WORK/model_$SET" --epochs 12 --batch 16 --input 448x288 --seed 0 --threads "${THREADS:-1}"
