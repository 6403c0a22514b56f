#!/usr/bin/python3
"""ros_bridge benchmark: synchronous ROS round trips per second, the bridge alone.

  /usr/bin/python3 benchmarks/ros_bench.py [--seconds 5] [--runs 3] [--timestep 0.001]

One experiment of the ros_bridge engine alone (EngineTimestep 0.001, no world): each step
publishes /clock and waits for its answer. An echo node (rospy, Debian's python3; this file
with --echo) answers each /clock with a convoy_msgs/Control stamped the same; both sides use
tcp_nodelay. A master on a free port is started for the benchmark (own process group, stopped
at the end like the node). Each run simulates --seconds s; the rate is the loop's cycles over
its wall time (summary.json: cycles, loop_wall_s). Then the same bridge asynchronous (no
waiting: /clock only) for what the round trip adds. Prints each run, the medians and the CPU
model.
"""
import argparse
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import xmlrpc.client

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
BIN_DIR = os.environ.get("CONVOY_BIN_DIR") or os.path.join(REPO, "build", "bin")
sys.path.insert(0, HERE)
from machine import cpu_model  # noqa: E402


def echo_node():
    """The ROS side: each /clock answered by a Control stamped with it."""
    sys.path.insert(0, os.path.join(os.path.dirname(BIN_DIR), "python"))
    import rospy
    from convoy_msgs.msg import Control
    from rosgraph_msgs.msg import Clock
    rospy.init_node("convoy_echo")
    pub = rospy.Publisher("/convoy/control", Control, queue_size=10, tcp_nodelay=True)

    def on_clock(msg):
        while pub.get_num_connections() == 0 and not rospy.is_shutdown():
            time.sleep(0.001)  # the bridge's subscription is not connected yet
        answer = Control(throttle=0.0, brake=0.0, steer=0.0, reverse=False)
        answer.header.stamp = msg.clock
        pub.publish(answer)

    rospy.Subscriber("/clock", Clock, on_clock, queue_size=10, tcp_nodelay=True)
    rospy.spin()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_group(cmd, log, env):
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                            env=env, start_new_session=True)


def stop_group(p):
    for sig, wait in ((signal.SIGTERM, 3.0), (signal.SIGKILL, 3.0)):
        try:
            os.killpg(p.pid, sig)
        except ProcessLookupError:
            break
        try:
            p.wait(wait)
            break
        except subprocess.TimeoutExpired:
            continue


def wait_master(uri, within=10.0):
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            xmlrpc.client.ServerProxy(uri).getPid("/ros_bench")
            return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError("the ROS master at %s does not answer" % uri)


def config(timestep, seconds, synchronous):
    return {"SimulationName": "ros_bench", "SimulationTimeout": seconds,
            "EngineConfigs": [{"EngineType": "ros_bridge", "EngineName": "ros",
                               "StartMaster": False, "Synchronous": synchronous,
                               "SyncTimeout": 10, "EngineTimestep": timestep}]}


def run(folder, env, timestep, seconds, synchronous, tag):
    path = os.path.join(folder, "config_%s.json" % tag)
    with open(path, "w") as f:
        json.dump(config(timestep, seconds, synchronous), f)
    run_dir = os.path.join(folder, "run_%s" % tag)
    r = subprocess.run([os.path.join(BIN_DIR, "convoy"), "run", "-q", "-c", path,
                        "--run-dir", run_dir], env=env, stdin=subprocess.DEVNULL,
                       capture_output=True, text=True, timeout=seconds * 100 + 60)
    if r.returncode != 0:
        raise RuntimeError("convoy run failed (%d):\n%s" % (r.returncode, r.stderr))
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)
    return s["cycles"] / s["loop_wall_s"]


def measure(args, folder):
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port,
               PYTHONDONTWRITEBYTECODE="1")
    procs = []
    with open(os.path.join(folder, "ros.log"), "w") as log:
        try:
            procs.append(start_group(["rosmaster", "--core", "-p", str(port)], log, env))
            wait_master(env["ROS_MASTER_URI"])
            procs.append(start_group([sys.executable, os.path.abspath(__file__), "--echo"],
                                     log, env))
            rates = {True: [], False: []}
            for synchronous in (True, False):
                mode = "synchronous" if synchronous else "asynchronous"
                for i in range(args.runs):
                    rate = run(folder, env, args.timestep, args.seconds, synchronous,
                               "%s_%d" % (mode, i))
                    rates[synchronous].append(rate)
                    print("%s, run %d: %.0f steps/s" % (mode, i + 1, rate), flush=True)
            return rates
        finally:
            for p in reversed(procs):
                stop_group(p)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="simulated s per run")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--timestep", type=float, default=0.001)
    parser.add_argument("--echo", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.echo:
        return echo_node()
    with tempfile.TemporaryDirectory(prefix="convoy-ros-bench-") as folder:
        rates = measure(args, folder)
    print("CPU: %s (%d cores)" % (cpu_model(), os.cpu_count()))
    print("asynchronous bridge steps/s (no answer awaited): %.0f"
          % statistics.median(rates[False]))
    print("synchronous ROS round trips/s: %.0f" % statistics.median(rates[True]))


if __name__ == "__main__":
    main()
