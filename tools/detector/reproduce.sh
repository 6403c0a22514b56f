#!/bin/bash
# Makes Convoy's detector from nothing: renders its training and held-out data with
# tools/dataset/make_dataset.py, then trains and exports it with tools/detector/train.py.
# The shipped models/detector was made by
#
#   tools/detector/reproduce.sh WORK_DIR            # all weathers (the shipped model)
#   tools/detector/reproduce.sh WORK_DIR clear      # the same frames, clear weather only
#
# Writes WORK_DIR/train_<all|clear>/<set>/ (COCO folders: the city's paths, the Parkring,
# scene_<name> for the generated worlds), WORK_DIR/eval_<weather>/ (the held-out city
# westbound path, seeds 950-951, in clear, rain, fog and night), WORK_DIR/eval_multi/ (held
# out: busy_multi_intersections on its generated world, a map never trained on),
# WORK_DIR/peds_<weather>_<scene>/ (held out: people among traffic on new scenes, six weathers),
# WORK_DIR/configs/ (the scenes' configs) and WORK_DIR/model_<all|clear>/
# (convoy_detector.onnx, classes.txt, model.json, training.json). Folders already complete
# (with runs.json) are kept. About 1 h 15 min of rendering and 50 min of training on 2 cores.
# BUILD=... picks the build (default build/); THREADS=... torch's threads (default 1, as the
# shipped model was trained: other counts sum in another order).
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,18p' "$0"; exit 2; fi
HERE="$(cd "$(dirname "$0")" && pwd)"
REPO="$(dirname "$(dirname "$HERE")")"
WORK="$(mkdir -p "$1" && cd "$1" && pwd)"
SET="${2:-all}"
case "$SET" in all|clear) ;; *) echo "reproduce.sh: the set is 'all' or 'clear', not '$SET'" >&2; exit 2;; esac
cd "$REPO"
PY=/usr/bin/python3
MD="$PY tools/dataset/make_dataset.py"
BUILD="${BUILD:-$REPO/build}"
B="--build $BUILD"
C=experiments/city_traffic/simulation_config.json
P=experiments/autonomous_driving/simulation_config_control.json
V="--vary-models car=0.5,bus=0.25,truck=0.25"
path() { echo "--set gazebo.GazeboWorldFile=city_world_$1.sdf --env car_ctl_engine:CONVOY_EGO_ROUTE=ego_route_$1.csv --env car_ctl_engine:CONVOY_EGO_ROUTE_SKIP=$2"; }
done_() { [ -f "$1/runs.json" ]; }
# Held out: the city westbound path (never in training), one set per weather.
for k in clear rain fog night; do
  done_ "$WORK/eval_$k" || $MD $C --out "$WORK/eval_$k" --runs 2 --seed 950 --seconds 80 --every 15 --weather $k $B $(path west 25)
done
# Generated worlds of esmini maps (urban scenery: buildings with facades, trees, street
# furniture) with road users: a scenario's default config (python/convoy_scenario/make_config.py,
# the world generated and cached as `convoy run --scenario` does), rendered like any
# experiment, each run with its own vehicle models; the detector engine passes the ground
# truth through (the renders do not need its boxes, and it saves a core's time).
G="--set yolo_detector.Backend=ground_truth"
scene() {  # scene XOSC NAME: the config of a scenario, into WORK_DIR/configs/NAME/
  $PY python/convoy_scenario/make_config.py "$1" --out "$WORK/configs/$2/config.json" --scenery urban \
    --bin-dir "$BUILD/bin" > /dev/null
  echo "$WORK/configs/$2/config.json"
}
# Held out: busy_multi_intersections (never in training: no training scene is on that map).
done_ "$WORK/eval_multi" || $MD "$(scene benchmarks/worlds/busy_multi_intersections.xosc multi)" --out "$WORK/eval_multi" \
  --runs 2 --seed 960 --seconds 25 --every 15 --weather clear,rain $V $G $B
# Held out: the pedestrian scenes (benchmarks/worlds/heldout/, make_busy_scenarios.py --heldout:
# eight to ten people among traffic on the city map's roads 3 and 4 and on multi_intersections),
# each in six weathers, WORK_DIR/peds_<weather>_<scene>/: the pedestrian AP by weather
# (benchmarks/perception_bench.py --heldout fog=DIR,DIR,DIR scores a weather's three as one set).
k=0
for wx in clear rain fog snow dusk night; do
  for n in city_r3 city_r4 multi_r281; do
    k=$((k + 1))
    done_ "$WORK/peds_${wx}_$n" || $MD "$(scene benchmarks/worlds/heldout/heldout_$n.xosc heldout_$n)" \
      --out "$WORK/peds_${wx}_$n" --runs 1 --seed $((980 + k)) --seconds 25 --every 10 --weather $wx $V $G $B
  done
done
# Training: the city eastbound, northbound, southbound and loop paths (each run its own
# vehicle models), the Parkring lap (the scenery world, parkring_world.sdf) and the training
# scenes on esmini's maps (benchmarks/worlds/train/, make_busy_scenarios.py --train); each
# run's weather in turn (or clear only).
if [ "$SET" = all ]; then
  W=(clear,rain,night,fog,snow,dusk fog,snow,clear,dusk,night,rain dusk,rain,fog,clear,night,snow night,clear,snow,rain,dusk,fog rain,fog,night)
else
  W=(clear clear clear clear clear)
fi
# the scenes' weathers: two runs each, clear in one of them (or both)
if [ "$SET" = all ]; then
  WS=(clear,rain fog,clear clear,night dusk,clear clear,snow rain,clear clear,fog night,clear clear,dusk)
else
  WS=(clear clear clear clear clear clear clear clear clear)
fi
SCENES=(fabriksgatan_lights_r2_mid fabriksgatan_lights_r3_north fabriksgatan_r0_west fabriksgatan_r2_north
  fabriksgatan_r3 parking_demo_r1 soderleden_r0 soderleden_r0_far soderleden_r2)
T="$WORK/train_$SET"
done_ "$T/east"  || $MD $C --out "$T/east"  --runs 6 --seed 900 --seconds 60 --every 15 --weather ${W[0]} $V $B
done_ "$T/north" || $MD $C --out "$T/north" --runs 6 --seed 910 --seconds 60 --every 15 --weather ${W[1]} $V $B $(path north 10)
done_ "$T/south" || $MD $C --out "$T/south" --runs 6 --seed 920 --seconds 60 --every 15 --weather ${W[2]} $V $B $(path south 10)
done_ "$T/loop"  || $MD $C --out "$T/loop"  --runs 6 --seed 930 --seconds 60 --every 15 --weather ${W[3]} $V $B $(path loop 10)
done_ "$T/parkring_scenery" || $MD $P --out "$T/parkring_scenery" --runs 3 --seed 100 --seconds 180 --every 20 --weather ${W[4]} $B
D=()
for i in "${!SCENES[@]}"; do
  n=${SCENES[$i]}
  done_ "$T/scene_$n" || $MD "$(scene benchmarks/worlds/train/train_$n.xosc $n)" --out "$T/scene_$n" \
    --runs 2 --seed $((1000 + 10 * i)) --seconds 30 --every 20 --weather ${WS[$i]} $V $G $B
  D+=(--data "$T/scene_$n")
done
# 10 epochs of 4380 frames: 2730 steps, about as many as the 12 epochs of 3717 before.
$PY tools/detector/train.py --data "$T/east" --data "$T/north" --data "$T/south" --data "$T/loop" --data "$T/parkring_scenery" \
  "${D[@]}" \
  --val "$WORK/eval_clear" --val "$WORK/eval_rain" --val "$WORK/eval_fog" --val "$WORK/eval_night" --val "$WORK/eval_multi" \
  --out "$WORK/model_$SET" --epochs 10 --batch 16 --input 448x288 --seed 0 --threads "${THREADS:-1}"
