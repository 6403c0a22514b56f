#!/usr/bin/python3
"""Phantom braking of the reference agent (issue 27: "phantom braking on the full Parkring lap with
sensor perception (stops without an object in the lane): target 0").

  /usr/bin/python3 benchmarks/phantom/phantom_bench.py [--perception sensors] [--scenario X.xosc]
      [--scenery | --world WORLD.sdf] [--build build] [--out DIR] [--run-dir EXISTING_RUN]

Runs `convoy run --scenario X --perception P` (default: parkring_lap.xosc here, the ego alone
on the Parkring lap, 950 m of its lane's 1001: a route ending on the straight behind
the start would end the run at once; 140 s at most; the scenario's default world is the road
only, --scenery runs it in the Parkring's scenery: experiments/autonomous_driving/
parkring_world.sdf without its smart_car, written into the run folder) and reads the run's planner result and tracks.csv. A
braking episode is a stretch of the planner's trace (10 Hz) in which it brakes for an object:
mode "aeb", or a lead object (not a traffic light's stop line) while the ego is below 0.5 m/s
after having driven; rows less than 2 s apart are one episode. An episode is a phantom when no
other scenario entity (tracks.csv) was in the ego's lane ahead then: within 2 m of its axis,
0 to the lead's gap + 10 m ahead. Prints the count, then one line per episode. With --run-dir
it only reads an existing run."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
MERGE_S = 2.0
STOPPED_MPS = 0.5
LANE_HALF_M = 2.0
SCENERY = os.path.join(REPO, "experiments", "autonomous_driving", "parkring_world.sdf")


def scenery_world(out_dir, src=SCENERY):
    """Writes src without its `model://smart_car` include (the scenario inserts the ego) as
    out_dir/parkring_world_no_ego.sdf; returns its path."""
    text = open(src).read()
    start = text.find("<uri>model://smart_car</uri>")
    if start < 0:
        raise ValueError("%s: no model://smart_car include to remove" % src)
    a = text.rfind("<include>", 0, start)
    b = text.find("</include>", start)
    if a < 0 or b < 0:
        raise ValueError("%s: the smart_car include is not an <include> element" % src)
    path = os.path.join(out_dir, "parkring_world_no_ego.sdf")
    with open(path, "w") as f:
        f.write(text[:a] + text[b + len("</include>"):])
    return path


def episodes(trace):
    """[(t0, t1, rows)] of the trace's braking episodes (module docstring)."""
    out, moved = [], False
    for r in trace:
        moved = moved or r["speed_mps"] > 1.0
        lead = r.get("lead")
        braking = r["mode"] == "aeb" or (lead is not None and not str(lead).startswith("stop_line")
                                         and moved and r["speed_mps"] < STOPPED_MPS)
        if not braking:
            continue
        if out and r["t"] - out[-1][1] <= MERGE_S:
            out[-1] = (out[-1][0], r["t"], out[-1][2] + [r])
        else:
            out.append((r["t"], r["t"], [r]))
    return out


def states(tracks_csv):
    """{t (rounded to 0.05 s): {entity: (x, y, heading)}} from tracks.csv."""
    out = {}
    with open(tracks_csv) as f:
        for row in csv.DictReader(f):
            t = round(float(row["t"]) * 20) / 20
            out.setdefault(t, {})[row["entity"]] = (float(row["x"]), float(row["y"]), float(row["heading"]))
    return out


def in_lane_ahead(st, t, reach):
    """Other entities in the ego's lane ahead at time t (nearest stored step)."""
    if not st:
        return []
    key = min(st, key=lambda k: abs(k - t))
    snap = st[key]
    if "Ego" not in snap:
        return []
    ex, ey, eh = snap["Ego"]
    c, s = math.cos(eh), math.sin(eh)
    out = []
    for name, (x, y, _) in sorted(snap.items()):
        if name == "Ego":
            continue
        lon, lat = c * (x - ex) + s * (y - ey), -s * (x - ex) + c * (y - ey)
        if 0.0 < lon < reach and abs(lat) < LANE_HALF_M:
            out.append(name)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenario", default=os.path.join(HERE, "parkring_lap.xosc"))
    ap.add_argument("--perception", default="sensors", choices=["ground_truth", "sensors"])
    ap.add_argument("--world", default=None, help="the world SDF without the ego (convoy run --world)")
    ap.add_argument("--scenery", action="store_true",
                    help="the Parkring's scenery world (parkring_world.sdf without its ego)")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--out", default=None, help="the run folder (default: a new temporary one)")
    ap.add_argument("--run-dir", default=None, help="read this existing run instead of running")
    a = ap.parse_args()
    run = a.run_dir
    if run is None:
        run = a.out or tempfile.mkdtemp(prefix="convoy-phantom-")
        cmd = [os.path.join(a.build, "bin", "convoy"), "run", "--scenario", a.scenario,
               "--perception", a.perception, "--run-dir", run, "--quiet"]
        os.makedirs(run, exist_ok=True)
        world = scenery_world(run) if a.scenery and not a.world else a.world
        if world:
            cmd += ["--world", world]
        rc = subprocess.call(cmd)
        if rc != 0:
            print("phantom_bench: %s exited %d (run folder %s)" % (" ".join(cmd), rc, run), file=sys.stderr)
            return rc
    try:
        with open(os.path.join(run, "ego_planner.json")) as f:
            planner = json.load(f)
        with open(os.path.join(run, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        print("phantom_bench: %s: no planner result or summary: %s" % (run, e), file=sys.stderr)
        return 2
    st = states(os.path.join(run, "tracks.csv"))
    eps = episodes(planner["speed_trace"])
    phantoms = []
    for t0, t1, rows in eps:
        gap = min((r["gap_m"] for r in rows if r.get("gap_m") is not None), default=0.0)
        real = in_lane_ahead(st, t0, gap + 10.0)
        if not real:
            phantoms.append((t0, t1, rows))
    trace = planner["speed_trace"]
    print("phantom braking (%s perception, %s): %d of %d braking episodes without an object in the "
          "lane; route completion %.1f %%, DS %.2f, %.1f s simulated, run %s  target 0" % (
              summary.get("perception", a.perception), os.path.basename(a.scenario), len(phantoms), len(eps),
              summary.get("route_completion") or 0.0, summary.get("driving_score") or 0.0,
              trace[-1]["t"] if trace else 0.0, run))
    for t0, t1, rows in phantoms:
        leads = sorted({"%s (%s)" % (r.get("lead"), r.get("lead_class")) for r in rows if r.get("lead")})
        print("  %.2f-%.2f s: min speed %.2f m/s, min gap %s m, leads %s" % (
            t0, t1, min(r["speed_mps"] for r in rows),
            min((round(r["gap_m"], 2) for r in rows if r.get("gap_m") is not None), default=None),
            ", ".join(leads)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
