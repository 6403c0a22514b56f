#!/usr/bin/python3
"""The live server's cost (issue 29): the "both" experiment without a viewer and with
`--clients` Foxglove clients (tools/live_check, @foxglove/ws-protocol) subscribed to every
channel, reading at full speed. Prints the loop's real-time factor of each run (summary.json's
`real_time_factor`: start-up and shutdown not counted), `live real-time factor ratio: R` (the
mean with clients over the mean without) and `dropped messages: N` (summary.json's
live.dropped_messages, over every client of every run). Then one more run with the web
dashboard open in headless Chromium (tools/dashboard_check, puppeteer-core) prints
`frame latency ms: N` (median, a camera frame reaching the coordinator's tap -> drawn in the
page) and `dashboard first paint ms: N` (opening the URL -> first contentful paint).

  /usr/bin/python3 benchmarks/live_bench.py [--seconds 30] [--repeats 2] [--clients 2]
                                            [--build build] [--config CONFIG]

The two cases alternate (without, with, without, with...) so that a change in the machine's
load hits both alike; still, run it on a quiet machine for figures to quote.
"""
import argparse
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine import cpu_model  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
CONFIG = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_both.json")
LIVE_CHECK = os.path.join(REPO, "tools", "live_check")
DASHBOARD_CHECK = os.path.join(REPO, "tools", "dashboard_check")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run(args, tmp, name, clients):
    run_dir = os.path.join(tmp, name)
    cmd = [args.convoy, "run", "-q", "-c", args.config, "-o", "SimulationTimeout=%g" % args.seconds,
           "--run-dir", run_dir]
    procs = []
    if clients:
        port = free_port()
        cmd += ["--live", str(port)]
        for i in range(clients):
            out = os.path.join(tmp, "%s_client%d.json" % (name, i))
            procs.append((subprocess.Popen(
                ["node", os.path.join(LIVE_CHECK, "check.mjs"), "--url", "ws://127.0.0.1:%d" % port,
                 "--out", out, "--wait", "60", "--timeout", str(args.seconds * 20 + 120)],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True), out))
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("%s failed (%d): %s" % (" ".join(cmd), r.returncode, r.stderr[-2000:]))
    got = []
    for proc, out in procs:
        proc.wait(timeout=60)
        with open(out) as f:
            got.append(json.load(f))
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    return summary, got


def dashboard(args, tmp):
    """A live run with the dashboard open in headless Chromium: dashboard_check's figures."""
    port = free_port()
    run_dir = os.path.join(tmp, "dashboard")
    cmd = [args.convoy, "run", "-q", "-c", args.config, "-o", "SimulationTimeout=%g" % args.seconds,
           "--run-dir", run_dir, "--live", str(port)]
    sim = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        check = subprocess.run(
            ["node", os.path.join(DASHBOARD_CHECK, "check.mjs"), "--url", "http://127.0.0.1:%d/" % port,
             "--expect-live", "--seconds", str(max(5, int(args.seconds / 2))), "--timeout", "120"],
            capture_output=True, text=True, timeout=600)
    finally:
        _, err = sim.communicate(timeout=args.seconds * 20 + 120)
    if sim.returncode != 0:
        sys.exit("%s failed (%d): %s" % (" ".join(cmd), sim.returncode, err[-2000:]))
    if check.returncode != 0:
        sys.exit("dashboard_check failed: %s" % check.stderr[-2000:])
    return json.loads(check.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=30, help="simulated seconds per run")
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--clients", type=int, default=2)
    p.add_argument("--build", default=os.path.join(REPO, "build"))
    p.add_argument("--config", default=CONFIG)
    args = p.parse_args()
    args.convoy = os.path.join(args.build, "bin", "convoy")
    if not os.path.isdir(os.path.join(LIVE_CHECK, "node_modules", "@foxglove", "ws-protocol")):
        sys.exit("tools/live_check is not installed: (cd tools/live_check && npm ci)")
    if not os.path.isdir(os.path.join(DASHBOARD_CHECK, "node_modules", "puppeteer-core")):
        sys.exit("tools/dashboard_check is not installed: (cd tools/dashboard_check && npm ci)")
    tmp = tempfile.mkdtemp(prefix="convoy_live_bench_")
    plain, live, dropped = [], [], 0
    try:
        for i in range(args.repeats):
            summary, _ = run(args, tmp, "plain%d" % i, 0)
            plain.append(summary["real_time_factor"])
            print("run %d without clients: real-time factor %.3f" % (i + 1, plain[-1]), flush=True)
            summary, got = run(args, tmp, "live%d" % i, args.clients)
            live.append(summary["real_time_factor"])
            dropped += summary["live"]["dropped_messages"]
            counts = [sum(m["count"] for m in g["messages"].values()) for g in got]
            images = [max((m["count"] for t, m in g["messages"].items() if t.endswith("/image")),
                          default=0) for g in got]
            print("run %d with %d clients: real-time factor %.3f, messages per client %s "
                  "(camera images %s), dropped %d" %
                  (i + 1, args.clients, live[-1], counts, images,
                   summary["live"]["dropped_messages"]), flush=True)
        page = dashboard(args, tmp)
        print("dashboard run: %d camera frames drawn, %d latency samples (p90 %s ms), %d road users"
              % (page.get("framesDrawn", 0), page.get("latencySamples", 0),
                 page.get("frameLatencyP90Ms"), page.get("roadUsers", 0)), flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("cpu: %s (%d cores)" % (cpu_model(), os.cpu_count()))
    print("config: %s, %g simulated s per run, %d runs each, alternating" %
          (os.path.relpath(args.config, REPO), args.seconds, args.repeats))
    print("real-time factor without clients: mean %.3f" % statistics.mean(plain))
    print("real-time factor with %d clients: mean %.3f" % (args.clients, statistics.mean(live)))
    print("live real-time factor ratio: %.3f" % (statistics.mean(live) / statistics.mean(plain)))
    print("dropped messages: %d" % dropped)
    print("frame latency ms: %.1f" % page["frameLatencyMedianMs"])
    print("dashboard first paint ms: %.1f" % page["firstPaintMs"])


if __name__ == "__main__":
    main()
