#!/usr/bin/python3
"""Traffic benchmark: prints the figures of the road-users issue (issue 11).

  /usr/bin/python3 benchmarks/traffic_bench.py [--runs 3] [--end 600] [--grid 10]

Section "sumo": the `sumo` engine against SUMO alone, side by side on the same network and
demand, written to a temporary folder:
  netgenerate --grid --grid.number=10 --grid.length=200 --default.lanenumber 2
  randomTrips.py -e 600 -p 0.25 --seed 42        (routes made by duarouter)
at a 0.1 s step (10 Hz), both with SUMO's seed 42:
  - SUMO alone: `sumo -n net -r routes --step-length 0.1 --end 600 --no-step-log --seed 42`
    (with --summary-output, one line a step, for the vehicle counts), wall time of the process;
  - SUMO alone in-process: the same through libsumo (Debian's Python module, a loop of
    simulationStep() with nothing read), wall time of the process, start-up included;
  - Convoy: `convoy run` of a config with the sumo engine publishing every vehicle as a
    convoy.data.RoadUsers datapack each step and a TF that reads it each step (the message is
    built, moved to the coordinator and parsed in Python), SimulationTimeout 600, wall time of
    the process (start-up included, as for SUMO alone).
Prints each side's wall time (median of --runs), the ratio of speeds (target >= 0.8x SUMO
alone), the peak number of vehicles and vehicle-steps per wall second.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
SUMO_HOME = os.environ.get("SUMO_HOME", "/usr/share/sumo")

COUNT_TF = textwrap.dedent("""\
    import json
    from nrp_core import *

    _stats = {"peak": 0, "vehicle_steps": 0, "steps": 0}


    @EngineDataPack(keyword="v", id=DataPackIdentifier("vehicles", "sumo"))
    @TransceiverFunction("sumo")
    def count_vehicles(v):
        if v.isEmpty():
            return []
        users = v.data.users
        # The engine lists the vehicles that left (absent, once) first.
        gone = 0
        while gone < len(users) and users[gone].absent:
            gone += 1
        n = len(users) - gone
        _stats["peak"] = max(_stats["peak"], n)
        _stats["vehicle_steps"] += n
        _stats["steps"] += 1
        if v.data.time_ns >= END_NS:
            with open(STATS, "w") as f:
                json.dump(_stats, f)
        return []
    """)


def run(cmd, **kw):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s\n%s" % (" ".join(cmd), r.stdout[-2000:], r.stderr[-2000:]))
    return r


def make_scenario(work, grid, end):
    env = dict(os.environ, SUMO_HOME=SUMO_HOME)
    net = os.path.join(work, "grid.net.xml")
    routes = os.path.join(work, "routes.rou.xml")
    run(["netgenerate", "--grid", "--grid.number=%d" % grid, "--grid.length=200",
         "--default.lanenumber", "2", "-o", net], env=env)
    run(["/usr/bin/python3", os.path.join(SUMO_HOME, "tools", "randomTrips.py"), "-n", net,
         "-e", str(end), "-p", "0.25", "--seed", "42", "-o", os.path.join(work, "trips.xml"),
         "-r", routes], env=env, cwd=work)
    return net, routes


def sumo_alone(work, net, routes, end, i):
    summary = os.path.join(work, "summary%d.xml" % i)
    t0 = time.monotonic()
    run(["sumo", "-n", net, "-r", routes, "--step-length", "0.1", "--end", str(end),
         "--no-step-log", "--seed", "42", "--summary-output", summary],
        env=dict(os.environ, SUMO_HOME=SUMO_HOME))
    wall = time.monotonic() - t0
    running = [int(s.get("running")) for s in ET.parse(summary).getroot().iter("step")]
    return wall, max(running), sum(running)


LIBSUMO_LOOP = textwrap.dedent("""\
    import sys
    import libsumo
    net, routes, end = sys.argv[1], sys.argv[2], float(sys.argv[3])
    libsumo.start(["sumo", "-n", net, "-r", routes, "--step-length", "0.1", "--no-step-log",
                   "true", "--seed", "42"])
    for i in range(int(round(end / 0.1))):
        libsumo.simulationStep((i + 1) * 0.1)
    libsumo.close()
    """)


def libsumo_alone(work, net, routes, end):
    script = os.path.join(work, "libsumo_loop.py")
    with open(script, "w") as f:
        f.write(LIBSUMO_LOOP)
    t0 = time.monotonic()
    run(["/usr/bin/python3", script, net, routes, str(end)],
        env=dict(os.environ, SUMO_HOME=SUMO_HOME))
    return time.monotonic() - t0


def convoy_run(work, net, routes, end, i, build):
    stats = os.path.join(work, "stats%d.json" % i)
    exp = os.path.join(work, "convoy%d" % i)
    os.makedirs(exp)
    with open(os.path.join(exp, "count_tf.py"), "w") as f:
        f.write(COUNT_TF.replace("END_NS", str(int(end * 1e9))).replace("STATS", repr(stats)))
    with open(os.path.join(exp, "simulation_config.json"), "w") as f:
        json.dump({"SimulationName": "traffic_bench_sumo", "SimulationTimeout": end,
                   "EngineConfigs": [{"EngineType": "sumo", "EngineName": "sumo",
                                      "EngineTimestep": 0.1, "NetFile": net,
                                      "RouteFiles": [routes], "Seed": 42}],
                   "DataPackProcessingFunctions": [{"Name": "count_vehicles",
                                                    "FileName": "count_tf.py"}]}, f)
    t0 = time.monotonic()
    run([os.path.join(build, "bin", "convoy"), "run", "-q", "-c",
         os.path.join(exp, "simulation_config.json"), "--run-dir", os.path.join(exp, "run")])
    wall = time.monotonic() - t0
    with open(stats) as f:
        s = json.load(f)
    return wall, s["peak"], s["vehicle_steps"]


def section_sumo(args):
    if not os.path.exists(os.path.join(args.build, "bin", "convoy-engine-sumo")):
        print("sumo: the sumo engine is not built (apt-get install sumo sumo-tools; reconfigure)")
        return
    work = tempfile.mkdtemp(prefix="convoy-trafficbench-")
    try:
        net, routes = make_scenario(work, args.grid, args.end)
        alone, inproc, convoy = [], [], []
        for i in range(args.runs):  # interleaved, so that all see the same machine
            alone.append(sumo_alone(work, net, routes, args.end, i))
            inproc.append(libsumo_alone(work, net, routes, args.end))
            convoy.append(convoy_run(work, net, routes, args.end, i, args.build))
            print("  run %d: SUMO alone %.2f s (peak %d), libsumo alone %.2f s, Convoy sumo "
                  "engine %.2f s (peak %d)" % (i, alone[-1][0], alone[-1][1], inproc[-1],
                                               convoy[-1][0], convoy[-1][1]), flush=True)
        wa = statistics.median(w for w, _, _ in alone)
        wl = statistics.median(inproc)
        wc = statistics.median(w for w, _, _ in convoy)
        print("sumo: grid %dx%d x 200 m, 2 lanes, randomTrips -e %d -p 0.25, 0.1 s step, %d runs"
              % (args.grid, args.grid, args.end, args.runs))
        print("  SUMO alone (sumo binary):  %.2f s wall for %d s simulated (%.1fx real time), "
              "peak %d vehicles, %.0f vehicle-steps per wall second"
              % (wa, args.end, args.end / wa, alone[0][1], alone[0][2] / wa))
        print("  SUMO alone (libsumo):      %.2f s wall (%.1fx real time), %.0f vehicle-steps per "
              "wall second" % (wl, args.end / wl, alone[0][2] / wl))
        print("  Convoy, sumo engine + TF:  %.2f s wall for %d s simulated (%.1fx real time), "
              "peak %d vehicles, %.0f vehicle-steps per wall second"
              % (wc, args.end, args.end / wc, convoy[0][1], convoy[0][2] / wc))
        print("  sumo engine speed / SUMO alone (libsumo): %.2fx" % (wl / wc))
        print("  sumo engine speed / SUMO alone (sumo binary): %.2fx  target >= 0.8x" % (wa / wc))
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--end", type=int, default=600, help="simulated seconds")
    ap.add_argument("--grid", type=int, default=10, help="junctions per side of the grid")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    args = ap.parse_args()
    section_sumo(args)


if __name__ == "__main__":
    main()
