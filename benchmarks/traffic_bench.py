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

Section "agents": N `vehicle_agent` engines (one process each) on the city map
(experiments/city_traffic/city.xodr), routes drawn from their seeds, stepping at 100 Hz
(EngineTimestep 0.01) for --agent-end simulated seconds, with one TF building every agent's
neighbour view (python/convoy_traffic/neighbours.py, radius 100 m) each step. For N in
--agents it prints the real-time factor of the loop (summary.json's real_time_factor: simulated
time / loop wall time, start-up excluded; median of --runs), and last the largest N at >= 1x:
`participants at real time: N`.

Section "city": experiments/city_traffic (the ego with its 30 Hz camera, the detector on every
third frame, the planner, 20 vehicle agents, 10 pedestrian agents, SUMO, the lights) for
--city-end simulated seconds, --runs times. Prints, median of the runs:
  - start-up: the coordinator's "engines initialized in ... s" (target <= 2 s); the first run
    starts with an empty parsed-world cache (CONVOY_CACHE_DIR in a temporary folder), the
    others hit it; both are printed;
  - camera frames/s (wall): frames written to camera.mp4 per wall second of the loop
    (target >= 20), detector frames and detections per wall second, the real-time factor.

With --city-road-users N the section runs experiments/city_traffic/simulation_config_pooled.json
instead (above 395, what city.xodr holds: simulation_config_pooled_large.json, the 4x4 grid
city large_city.xodr): the ego among N vehicles of ONE road_user_pool engine (-o
EngineConfigs/5/Density=0 -o EngineConfigs/5/Count=N), drawn by the world engine as actors; it
prints the same lines, the world's collisions (pooled vehicles with each other and with the
ego, which the pool sees) and, from traffic_pool_bench on that map, the collisions among the N
pooled vehicles over 600 simulated s (target 0). --city-pedestrians P adds P pooled walkers (-o
EngineConfigs/5/Pedestrians=P; default 0): it prints the mix (N vehicles + P pedestrians) and
the vehicle-walker collisions of the 600 s run too. A count the map cannot hold ends the section
with the pool's message.

Section "density": experiments/city_traffic/simulation_config_density.json, 10 simulated
minutes of the same road users respawning at their starts and SUMO's flows doubled (no ego).
Prints the collisions among participants (target 0), red-light violations, the road users
seen and the real-time factor.

Section "pooled": the road_user_pool engine (issue 26): N vehicles in ONE engine process with
IDM, MOBIL, junction yielding and traffic lights at 20 Hz on a 10x10 grid network made at run
time (netgenerate --grid --grid.number=10 --grid.length=--pool-grid-length --default.lanenumber 2
--tls.guess true, then netconvert --opendrive-output; deterministic). For N in --pooled:
  - the pool's step alone (benchmarks/traffic_pool/traffic_pool_bench.cpp, --pool-end simulated
    seconds): ms per step, vehicle updates per wall second, the real-time factor, collisions;
  - inside the coordinator loop: `convoy run` of the engine (EngineTimestep 0.05, Count N) with a
    TF reading the whole convoy.data.RoadUsers datapack (binary protobuf) each step: the
    real-time factor of the loop (summary.json, start-up excluded; median of --runs).
Last line: `pooled road users at real time: N`, the largest N at >= 1x in the loop. With
--pool-collision-count K (default 1000) it also runs K vehicles for 600 simulated s alone and
prints the collisions among them (target 0).

  --sections sumo,agents,city,density,pooled   which sections to run (default all but pooled)
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
sys.path.insert(0, HERE)
from traffic_pooled import run, section_pooled  # noqa: E402
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


AGENT_TF = textwrap.dedent("""\
    from nrp_core import *
    from convoy_traffic.neighbours import neighbour_datapacks

    AGENTS = {agents!r}

    {decorators}
    @TransceiverFunction({first!r})
    def neighbours(**states):
        return neighbour_datapacks(list(states.values()), agents=AGENTS, radius=100.0)
    """)


def agents_run(work, n, end, i, build):
    exp = os.path.join(work, "agents%d_%d" % (n, i))
    os.makedirs(exp)
    names = ["car_%d" % k for k in range(n)]
    decorators = "\n".join('@EngineDataPack(keyword=%r, id=DataPackIdentifier("state", %r))'
                           % (a, a) for a in names)
    with open(os.path.join(exp, "tf.py"), "w") as f:
        f.write(AGENT_TF.format(agents=names, decorators=decorators, first=names[0]))
    city = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")
    engines = [{"EngineType": "vehicle_agent", "EngineName": a, "EngineTimestep": 0.01,
                "Map": city, "Seed": k, "StartS": float(k % 7) * 12.0, "InitialSpeed": 8.0,
                "ReactionTime": 0.2} for k, a in enumerate(names)]
    with open(os.path.join(exp, "simulation_config.json"), "w") as f:
        json.dump({"SimulationName": "traffic_bench_agents", "SimulationTimeout": end,
                   "EngineConfigs": engines,
                   "DataPackProcessingFunctions": [{"Name": "neighbours", "FileName": "tf.py"}]},
                  f)
    run_dir = os.path.join(exp, "run")
    t0 = time.monotonic()
    run([os.path.join(build, "bin", "convoy"), "run", "-q", "-c",
         os.path.join(exp, "simulation_config.json"), "--run-dir", run_dir])
    wall = time.monotonic() - t0
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    shutil.rmtree(exp, ignore_errors=True)
    return summary["real_time_factor"], wall


def section_agents(args):
    if not os.path.exists(os.path.join(args.build, "bin", "convoy-engine-vehicle_agent")):
        print("agents: convoy-engine-vehicle_agent is not built")
        return
    work = tempfile.mkdtemp(prefix="convoy-trafficbench-agents-")
    best = 0
    try:
        print("agents: vehicle_agent processes at 100 Hz on the city map, neighbour views by one "
              "TF, %g s simulated, %d run(s) each" % (args.agent_end, args.runs))
        for n in [int(x) for x in args.agents.split(",")]:
            rtfs, walls = [], []
            for i in range(args.runs):
                rtf, wall = agents_run(work, n, args.agent_end, i, args.build)
                rtfs.append(rtf)
                walls.append(wall)
            rtf = statistics.median(rtfs)
            print("  N = %3d: real-time factor %.2fx (runs: %s; wall with start-up %.1f s)"
                  % (n, rtf, ", ".join("%.2f" % r for r in rtfs), statistics.median(walls)),
                  flush=True)
            if rtf >= 1.0:
                best = max(best, n)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    args.agents_best = best
    print("participants at real time: %d" % best)


CITY = os.path.join(REPO, "experiments", "city_traffic")


def city_run(args, config, end, run_dir, env=None, overrides=()):
    cmd = [os.path.join(args.build, "bin", "convoy"), "run", "-c", config, "--run-dir", run_dir,
           "-o", "SimulationTimeout=%g" % end]
    for o in overrides:
        cmd += ["-o", o]
    out = subprocess.run(cmd, cwd=CITY, capture_output=True, text=True, env=env)
    if out.returncode != 0:
        sys.exit("city: %s failed (exit %d):\n%s" % (config, out.returncode, out.stderr[-3000:]))
    startup = None
    with open(os.path.join(run_dir, "logs", "coordinator.log")) as f:
        for line in f:
            if "engines initialized in" in line:
                startup = float(line.split("engines initialized in")[1].split()[0])
    with open(os.path.join(run_dir, "summary.json")) as f:
        return startup, json.load(f)


POOLED_CITY = "simulation_config_pooled.json"
# Above what city.xodr holds (395 vehicles standing), the large grid city (make_large_city.py).
POOLED_CITY_LARGE, CITY_XODR_HOLDS = "simulation_config_pooled_large.json", 395


def pooled_city_map(n):
    return "large_city.xodr" if n > CITY_XODR_HOLDS else "city.xodr"


def pooled_city_collisions(args, n, walkers=0):
    """The pool alone on the pooled city's map, N vehicles (and `walkers` walkers) for 600
    simulated s: its collision line (and its walkers' line)."""
    bench = os.path.join(args.build, "benchmarks", "traffic_pool_bench")
    if not os.path.exists(bench):
        return "traffic_pool_bench is not built"
    r = subprocess.run([bench, os.path.join(CITY, pooled_city_map(n)), "--counts", str(n),
                        "--seconds", "600", "--walkers", str(walkers)],
                       capture_output=True, text=True)
    lines = [ln.strip() for ln in r.stdout.splitlines()
             if ln.strip().startswith(("N =", "walkers"))]
    return "; ".join(lines) if r.returncode == 0 and lines else \
        (r.stderr or r.stdout).strip()[-500:]


def section_city(args):
    pooled = args.city_road_users > 0
    engine = "convoy-engine-road_user_pool" if pooled else "convoy-engine-sumo"
    if not os.path.exists(os.path.join(args.build, "bin", engine)):
        print("city: %s is not built" % engine)
        return
    config = "simulation_config.json"
    if pooled:
        config = POOLED_CITY_LARGE if args.city_road_users > CITY_XODR_HOLDS else POOLED_CITY
    overrides = ["EngineConfigs/5/Density=0", "EngineConfigs/5/Count=%d" % args.city_road_users,
                 "EngineConfigs/5/Pedestrians=%d" % args.city_pedestrians] if pooled else []
    work = tempfile.mkdtemp(prefix="convoy-trafficbench-city-")
    try:
        env = dict(os.environ, CONVOY_CACHE_DIR=os.path.join(work, "cache"))
        rows = []
        for i in range(args.runs + 1):  # the first with an empty cache, then --runs warm
            startup, s = city_run(args, config, args.city_end, os.path.join(work, "run%d" % i),
                                  env, overrides)
            wall = s["loop_wall_s"]
            rows.append((startup, s["camera_frames"] / wall, s["detector_frames"] / wall,
                         s["detections"] / wall, s["real_time_factor"], s))
            shutil.rmtree(os.path.join(work, "run%d" % i), ignore_errors=True)
        warm = rows[1:]
        med = lambda k: statistics.median(r[k] for r in warm)  # noqa: E731
        s = rows[-1][5]
        print("city: experiments/city_traffic/%s, %g s simulated, %d run(s) (the first with an "
              "empty parsed-world cache); participants %s%s"
              % (config, args.city_end, len(rows), json.dumps(s["participants"]),
                 ", pooled road users %d vehicles + %d pedestrians = %d"
                 % (args.city_road_users, args.city_pedestrians,
                    args.city_road_users + args.city_pedestrians) if pooled else ""))
        print("  start-up (engines initialized in): %.2f s with the cache (runs: %s), %.2f s "
              "without it  target <= 2 s" % (med(0), ", ".join("%.2f" % r[0] for r in warm),
                                            rows[0][0]))
        print("  camera frames/s (30 Hz camera, wall): %.1f (runs: %s)  target >= 20"
              % (med(1), ", ".join("%.1f" % r[1] for r in warm)))
        print("  detector frames/s (every third camera frame): %.1f; detections/s: %.1f"
              % (med(2), med(3)))
        print("  real-time factor: %.2fx; collisions %d, red-light violations %d, ego stops "
              "for pedestrians %s" % (med(4), len(s["collisions"]), s["red_light_violations"],
                                      s["ego_stops_for_pedestrians"]))
        if pooled:
            for c in s["collisions"]:
                print("    %s" % json.dumps(c))
            print("  collisions among the %d pooled vehicles (and with its %d walkers), 600 "
                  "simulated s (the pool alone): %s  target 0"
                  % (args.city_road_users, args.city_pedestrians,
                     pooled_city_collisions(args, args.city_road_users, args.city_pedestrians)))
    finally:
        shutil.rmtree(work, ignore_errors=True)


def section_density(args):
    if not os.path.exists(os.path.join(args.build, "bin", "convoy-engine-sumo")):
        print("density: the sumo engine is not built")
        return
    work = tempfile.mkdtemp(prefix="convoy-trafficbench-density-")
    try:
        _, s = city_run(args, "simulation_config_density.json", args.density_end,
                        os.path.join(work, "run"))
        print("density: %g simulated s of city_traffic's road users respawning, SUMO's flows "
              "doubled; %d road users seen (%d SUMO vehicles), real-time factor %.2fx"
              % (args.density_end, s["road_users_seen"], s["participants"]["sumo_vehicles"],
                 s["real_time_factor"]))
        print("  collisions among participants: %d  target 0" % len(s["collisions"]))
        for c in s["collisions"]:
            print("    %s" % json.dumps(c))
        print("  red-light violations: %d" % s["red_light_violations"])
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--end", type=int, default=600, help="simulated seconds")
    ap.add_argument("--grid", type=int, default=10, help="junctions per side of the grid")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--sections", default="sumo,agents,city,density")
    ap.add_argument("--agents", default="8,16,32,64,128,256", help="agent counts, comma-separated")
    ap.add_argument("--city-end", type=float, default=60.0,
                    help="simulated seconds of each city run")
    ap.add_argument("--city-road-users", type=int, default=0,
                    help="city section: run simulation_config_pooled.json (above 395: "
                         "simulation_config_pooled_large.json) with N pooled vehicles instead of the agent engines and SUMO (0: the usual config)")
    ap.add_argument("--city-pedestrians", type=int, default=0,
                    help="with --city-road-users: the pool's walkers on the sidewalks "
                         "(EngineConfigs/5/Pedestrians)")
    ap.add_argument("--density-end", type=float, default=600.0,
                    help="simulated seconds of the density run")
    ap.add_argument("--agent-end", type=float, default=10.0,
                    help="simulated seconds of each agents run")
    ap.add_argument("--pooled", default="1000,5000,10000,20000,40000",
                    help="pooled vehicle counts, comma-separated")
    ap.add_argument("--pool-end", type=float, default=20.0,
                    help="simulated seconds of each pooled run")
    ap.add_argument("--pool-grid-length", type=float, default=400.0,
                    help="m between the grid's junctions")
    ap.add_argument("--pool-collision-count", type=int, default=1000,
                    help="vehicles of the 600 s collision run (0: none)")
    args = ap.parse_args()
    sections = args.sections.split(",")
    if "sumo" in sections:
        section_sumo(args)
    if "agents" in sections:
        section_agents(args)
    if "city" in sections:
        section_city(args)
    if "density" in sections:
        section_density(args)
    if "pooled" in sections:
        section_pooled(args)
    if "agents" in sections and "pooled" in sections:
        print("participants at real time: %d" % getattr(args, "agents_best", 0))


if __name__ == "__main__":
    main()
