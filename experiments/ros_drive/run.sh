#!/bin/bash
# The ros_drive experiment: a ROS master (unless one answers at $ROS_MASTER_URI), the rospy
# driver (driver_node.py) and the simulation, in RUN_DIR. Leaves RUN_DIR/summary.json
# (lap_completed), trajectory.csv, driver_node.log, driver.csv; exits with the simulation's
# code. The master and the node are stopped whatever happens (their own process groups).
#
#   experiments/ros_drive/run.sh RUN_DIR [convoy run options, e.g. -o SimulationTimeout=20]
#
# ROS_MASTER_URI (default http://127.0.0.1:11311) is respected; a master is started only
# at a local URI. Binaries from $CONVOY_BIN_DIR (default <repo>/build/bin).
set -u
if [ $# -lt 1 ]; then
  echo "usage: $0 RUN_DIR [convoy run options]" >&2
  exit 2
fi
RUN_DIR=$(realpath -m "$1")
shift
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
BIN_DIR=${CONVOY_BIN_DIR:-$REPO/build/bin}
PY=/usr/bin/python3
export ROS_MASTER_URI=${ROS_MASTER_URI:-http://127.0.0.1:11311}
export CONVOY_BIN_DIR=$BIN_DIR
mkdir -p "$RUN_DIR"

groups=()
stop_all() {
  local g
  for g in "${groups[@]}"; do kill -TERM -- "-$g" 2>/dev/null; done
  for _ in $(seq 20); do
    local alive=0
    for g in "${groups[@]}"; do kill -0 -- "-$g" 2>/dev/null && alive=1; done
    [ $alive = 0 ] && return
    sleep 0.1
  done
  for g in "${groups[@]}"; do kill -KILL -- "-$g" 2>/dev/null; done
}
trap stop_all EXIT
trap 'exit 130' INT TERM  # until the simulation runs; then forwarded to it

# "up", "local PORT" (none answers, this machine's URI) or "remote" (none answers)
master_state() {
  "$PY" - "$ROS_MASTER_URI" <<'PYEOF'
import socket, sys, urllib.parse, xmlrpc.client
uri = sys.argv[1]
socket.setdefaulttimeout(2.0)
try:
    xmlrpc.client.ServerProxy(uri).getPid("/run_sh")
    print("up")
except (OSError, xmlrpc.client.Error):
    u = urllib.parse.urlparse(uri)
    local = u.hostname in ("localhost", socket.gethostname()) or (u.hostname or "").startswith("127.")
    print("local %d" % (u.port or 11311) if local else "remote")
PYEOF
}

state=$(master_state)
case "$state" in
  up) echo "ROS master at $ROS_MASTER_URI" ;;
  local*)
    port=${state#local }
    setsid rosmaster --core -p "$port" >"$RUN_DIR/rosmaster.log" 2>&1 </dev/null &
    groups+=($!)
    for _ in $(seq 100); do
      [ "$(master_state)" = up ] && break
      sleep 0.1
    done
    if [ "$(master_state)" != up ]; then
      echo "error: the ROS master started at $ROS_MASTER_URI does not answer (see $RUN_DIR/rosmaster.log)" >&2
      exit 3
    fi
    echo "started a ROS master at $ROS_MASTER_URI" ;;
  *)
    echo "error: no ROS master at $ROS_MASTER_URI (ROS_MASTER_URI), and it is not this machine's to start" >&2
    exit 3 ;;
esac

setsid "$PY" "$HERE/driver_node.py" "_log:=$RUN_DIR/driver.csv" \
  >"$RUN_DIR/driver_node.log" 2>&1 </dev/null &
groups+=($!)

"$BIN_DIR/convoy" run -c "$HERE/simulation_config.json" --run-dir "$RUN_DIR" "$@" &
sim=$!
trap 'kill -TERM $sim 2>/dev/null' INT TERM  # it ends cleanly, keeping its logs
code=0
while true; do
  wait $sim
  code=$?
  kill -0 $sim 2>/dev/null || break  # wait was interrupted by a signal: wait again
done
if [ -f "$RUN_DIR/summary.json" ]; then
  "$PY" -c 'import json, sys; s = json.load(open(sys.argv[1])); print("lap_completed: %s, lap_time_s: %s" % (s.get("lap_completed"), s.get("lap_time_s")))' "$RUN_DIR/summary.json"
fi
exit $code
