#!/usr/bin/python3
"""Realism of the pooled traffic against SUMO (issue 26 item 5), on one network and one demand.

The map (default experiments/city_traffic/large_city.xodr) is converted by netconvert with the
pool's light cycle (25 s green, 3 s yellow, 2 s all red); the demand is --flows-per-entry flows
of --rate vehicles/h from each entry edge (an edge out of the map's border) to exit edges drawn
by --seed among those the pool can drive (a path without lane changes: traffic_pool_bench
--routable, which gives the roads of that path). The same flows feed the pool
(traffic_pool_bench --flows, dt 0.05 s) and SUMO (<flow vehsPerHour> on the pool's route, road
by road; step 0.1 s) with Krauss (SUMO's default) and IDM (the pool's IDM parameters), both
with LC2013. All record 5 Hz samples for --seconds after --warmup; metrics.py computes the
distributions; the run folder gets realism.json, realism.md and one PNG per metric.

  /usr/bin/python3 benchmarks/realism/realism_bench.py [--out DIR] [--seconds 600]
      [--warmup 300] [--rate 100] [--flows-per-entry 2] [--seed 1] [--short]
"""
import argparse
import datetime
import os
import random
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import metrics  # noqa: E402
import report  # noqa: E402
import traces  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(HERE))
SAMPLE_S = 0.2
POOL_DT = 0.05
SUMO_DT = 0.1
# The pool's defaults (src/road_users/idm.h: v0 13.9, T 1.5, s0 2, a 1.5, b 2, delta 4; 4.5 m).
IDM = {"accel": "1.5", "decel": "2.0", "tau": "1.5", "minGap": "2.0", "delta": "4"}
LENGTH = 4.5


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit("realism_bench: %s failed (exit %d): %s" % (os.path.basename(cmd[0]), r.returncode,
                                                           (r.stderr or r.stdout).strip()[-800:]))
    return r.stdout


def convert(xodr, net):
    env = dict(os.environ, SUMO_HOME=os.environ.get("SUMO_HOME", "/usr/share/sumo"))
    run(["netconvert", "--opendrive-files", xodr, "--tls.green.time", "25", "--tls.yellow.time",
         "3", "--tls.allred.time", "2", "--no-warnings", "-o", net], env=env)


def border_edges(net):
    """Entry edges (nothing but their reverse leads into their start) and exit edges."""
    edges = {e.get("id"): (e.get("from"), e.get("to")) for e in ET.parse(net).getroot().iter("edge")
             if e.get("function") != "internal"}
    into, out_of = {}, {}
    for k, (a, b) in edges.items():
        out_of.setdefault(a, []).append(k)
        into.setdefault(b, []).append(k)
    rev = lambda k: k[1:] if k.startswith("-") else "-" + k
    entries = sorted(k for k, (a, _) in edges.items() if all(i == rev(k) for i in into.get(a, [])))
    exits = sorted(k for k, (_, b) in edges.items() if all(o == rev(k) for o in out_of.get(b, [])))
    return entries, exits


def make_demand(args, bench, net, folder):
    entries, exits = border_edges(net)
    cand = os.path.join(folder, "candidates.csv")
    with open(cand, "w") as f:
        f.writelines("%s,%s,%g\n" % (a, b, args.rate) for a in entries for b in exits
                     if b.lstrip("-") != a.lstrip("-"))
    by_entry = {}  # entry -> [(exit, the route's edges)]
    for ln in run([bench, args.map, "--routable", cand]).splitlines():
        f = ln.split(",")
        if len(f) == 5 and f[3] == "yes":
            by_entry.setdefault(f[0], []).append((f[1], f[4]))
    rng = random.Random(args.seed)
    flows = [(a, b, edges) for a in sorted(by_entry)
             for b, edges in rng.sample(by_entry[a], min(args.flows_per_entry, len(by_entry[a])))]
    if not flows:
        sys.exit("realism_bench: %s: no entry-to-exit flow the pool can drive" % args.map)
    path = os.path.join(folder, "flows.csv")
    with open(path, "w") as f:
        f.write("# from_edge,to_edge,vehicles_per_hour (seed %d)\n" % args.seed)
        f.writelines("%s,%s,%g\n" % (a, b, args.rate) for a, b, _ in flows)
    return path, flows


def run_pool(args, bench, flows_csv, folder):
    trace = os.path.join(folder, "pool_trace.csv")
    t0 = time.time()
    out = run([bench, args.map, "--flows", flows_csv, "--warmup", str(args.warmup), "--seconds",
               str(args.seconds), "--dt", str(POOL_DT), "--trace-every",
               str(int(round(SAMPLE_S / POOL_DT))), "--seed", str(args.seed), "--trace", trace])
    summary = [ln for ln in out.splitlines() if ln.startswith("flows")]
    return trace, {"summary": summary[-1] if summary else out.strip(), "wall_s": time.time() - t0}


def run_sumo(args, model, net, flows, folder):
    rou = os.path.join(folder, "sumo_%s.rou.xml" % model)
    extra = " ".join('%s="%s"' % kv for kv in IDM.items()) if model == "idm" else ""
    end = args.warmup + args.seconds
    with open(rou, "w") as f:
        f.write('<routes>\n  <vType id="car" length="%g" carFollowModel="%s" '
                'laneChangeModel="LC2013" %s/>\n' % (LENGTH, model.upper() if model == "idm"
                                                     else "Krauss", extra))
        for k, (_, _, edges) in enumerate(flows):  # the pool's route, road by road
            f.write('  <flow id="f%d" type="car" begin="0" end="%g" vehsPerHour="%g" '
                    'departLane="best" departSpeed="0">\n    <route edges="%s"/>\n  </flow>\n'
                    % (k, end, args.rate, edges))
        f.write("</routes>\n")
    fcd = os.path.join(folder, "sumo_%s_fcd.xml" % model)
    t0 = time.time()
    out = run(["sumo", "-n", net, "-r", rou, "--begin", "0", "--end", str(end), "--step-length",
               str(SUMO_DT), "--seed", str(args.seed), "--fcd-output", fcd,
               "--fcd-output.attributes", "x,y,speed,pos,lane",
               "--device.fcd.begin", str(args.warmup),
               "--device.fcd.period", str(SAMPLE_S), "--no-step-log", "--duration-log.statistics",
               "--collision.action", "warn", "--no-warnings"])
    stats = [ln.strip() for ln in out.splitlines()
             if any(w in ln for w in ("Inserted", "Running", "Waiting", "Teleports", "Collisions"))]
    return fcd, {"summary": "; ".join(stats), "wall_s": time.time() - t0}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--map", default=os.path.join(ROOT, "experiments/city_traffic/large_city.xodr"))
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", help="run folder (default: a new folder under /tmp)")
    ap.add_argument("--seconds", type=float, default=600)
    ap.add_argument("--warmup", type=float, default=300)
    ap.add_argument("--rate", type=float, default=100, help="vehicles/h of each flow")
    ap.add_argument("--flows-per-entry", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--short", action="store_true", help="60 s after 60 s of warm-up (the test)")
    args = ap.parse_args()
    if args.short:
        args.seconds, args.warmup = 60, 60
    bench = os.path.join(args.build, "benchmarks", "traffic_pool_bench")
    if not os.path.exists(bench):
        sys.exit("realism_bench: %s is not built" % bench)
    if not os.path.exists(args.map):
        sys.exit("realism_bench: %s: no such map" % args.map)
    folder = args.out or tempfile.mkdtemp(prefix="realism-")
    os.makedirs(folder, exist_ok=True)
    net = os.path.join(folder, "map.net.xml")
    convert(args.map, net)
    flows_csv, flows = make_demand(args, bench, net, folder)
    runs, data = {}, {}
    trace, runs["pool"] = run_pool(args, bench, flows_csv, folder)
    data["pool"] = traces.load_pool(trace)
    for model in ("idm", "krauss"):
        fcd, runs["sumo_" + model] = run_sumo(args, model, net, flows, folder)
        data["sumo_" + model] = traces.load_sumo(fcd, net, LENGTH)
    results = {name: metrics.all_metrics(tr, args.seconds) for name, tr in data.items()}
    setup = {"map": os.path.relpath(args.map, ROOT), "flows": len(flows),
             "rate_per_flow": args.rate,
             "warmup_s": args.warmup, "seconds": args.seconds, "sample_s": SAMPLE_S,
             "pool_dt": POOL_DT, "sumo_dt": SUMO_DT, "seed": args.seed,
             "date": datetime.datetime.now().isoformat(timespec="seconds"),
             "load_average": os.getloadavg(), "runs": runs}
    doc = report.write(folder, setup, results)
    print(report.text_table(doc))
    print("report: %s" % os.path.join(folder, "realism.md"))


if __name__ == "__main__":
    main()
