#!/usr/bin/python3
"""The world generator on OpenDRIVE maps (convoy-odr world; docs/worlds.md).

  /usr/bin/python3 benchmarks/odr_world_bench.py [MAP.xodr ...] [--scenery urban] [--seed 1]
        [--render] [--frames MAP] [--build build] [--json out.json]

Generates each map's world from an empty folder (default: esmini's 20 maps in
tests/data/esmini/xodr) and prints one line per map, `MAP: generated in S s, N
triangles`, then `worlds generated: N/M, median S s, max S s`. With --render, each world is
also loaded, rendered and driven: benchmarks/worlds/<map>.xosc runs to its end (20 s) on the
generated world (`convoy run --scenario`: the report's smart car with its camera and detector
follows the lane's waypoints behind a slower car); a map counts as rendered when the run ends
with exit 0 and the detector got camera frames, and its lane as kept when the car's reference
point stayed within 0.85 m of the lane's centre (summary.json's score.route_max_offset_m) while
it drove at least 60 m. A
second run of 1 s gives the start-up with the world cache warm (summary.json's startup_s). With --frames MAP (a name
like multi_intersections), the smart car is put where that map's scenario starts the ego and
build/benchmarks/frame_bench measures its camera (physics, rendering with shadows, ground
truth) over 200 frames, 3 runs: `camera frames/s on MAP: F`.
"""
import argparse
import glob
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
MAPS = os.path.join(REPO, "tests", "data", "esmini", "xodr")


def generate(odr, xodr, out, scenery, seed):
    t0 = time.monotonic()
    p = subprocess.run([odr, "world", xodr, out, "--scenery", scenery, "--seed", str(seed)],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    dt = time.monotonic() - t0
    if p.returncode != 0:
        return None, p.stderr.strip().splitlines()[-1:] or ["failed"]
    m = re.search(r"(\d+) triangles generated", p.stdout)
    return (dt, int(m.group(1)) if m else 0), p.stdout.strip()


def run_scenario(convoy, scenario, cache, run_dir, timeout=None):
    env = dict(os.environ, CONVOY_CACHE_DIR=cache)
    cmd = [convoy, "run", "--scenario", scenario, "-q", "--run-dir", run_dir]
    if timeout:
        cmd += ["-o", "SimulationTimeout=%g" % timeout]
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    summary = {}
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        pass
    summary["ok"] = p.returncode == 0 and summary.get("cycles", 0) > 0
    summary["stderr"] = p.stderr.strip().splitlines()[-1:]
    return summary


# The smart car keeps its lane when its reference point stays this close to the lane's centre:
# half a 3.5 m lane less half the car's 1.8 m width.
LANE_KEEPING_M = 0.85
# ... over at least this much of its route (20 s behind a car at 6 m/s: about 128 m)
MIN_PROGRESS_M = 60.0


def ego_start(odr, scenario):
    """(x, y, z, heading) of the ego's Init LanePosition in one of benchmarks/worlds/*.xosc."""
    text = open(scenario).read()
    m = re.search(r'LanePosition roadId="([^"]+)" laneId="([^"]+)" s="\$EgoS"', text)
    s = float(re.search(r'name="EgoS" parameterType="double" value="([^"]+)"', text).group(1))
    xodr = os.path.join(REPO, "tests", "data", "esmini",
                        re.search(r'esmini/([^"]+\.xodr)', text).group(1))
    q = json.dumps({"op": "pose", "road": m.group(1), "lane": int(m.group(2)), "s": s})
    r = json.loads(subprocess.run([odr, "query", xodr], input=q + "\n", capture_output=True,
                                  text=True).stdout)
    return r["x"], r["y"], r["z"], r["heading"]


def camera_fps(build, world, pose):
    """Camera frames/s of the smart car at `pose` in a generated world (frame_bench)."""
    text = open(world).read()
    car = ("    <include><uri>model://smart_car</uri><name>smart_car</name>"
           "<pose>%.3f %.3f %.3f 0 0 %.5f</pose></include>\n" % pose)
    with_car = os.path.join(os.path.dirname(world), "world_with_car.sdf")
    with open(with_car, "w") as f:
        f.write(text.replace("  </world>", car + "  </world>"))
    env = dict(os.environ, CONVOY_MODEL_PATH=os.path.join(REPO, "experiments", "city_traffic", "models"))
    p = subprocess.run([os.path.join(build, "benchmarks", "frame_bench"), with_car, "--frames", "200",
                        "--runs", "3", "--shadows", "1"], capture_output=True, text=True, env=env)
    m = re.search(r"([0-9.]+) frames/s", p.stdout)
    return (float(m.group(1)) if m else None), (p.stdout + p.stderr).strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("maps", nargs="*")
    ap.add_argument("--scenery", default="urban", choices=["none", "roadside", "urban"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--render", action="store_true")
    ap.add_argument("--frames", metavar="MAP", help="measure the camera's frames/s on this map's world")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--json")
    a = ap.parse_args()
    maps = a.maps or sorted(glob.glob(os.path.join(MAPS, "*.xodr")))
    odr = os.path.join(a.build, "bin", "convoy-odr")
    convoy = os.path.join(a.build, "bin", "convoy")
    tmp = tempfile.mkdtemp(prefix="odr_world_bench_")
    results, times = [], []
    try:
        for xodr in maps:
            name = os.path.splitext(os.path.basename(xodr))[0]
            got, info = generate(odr, xodr, os.path.join(tmp, "worlds", name), a.scenery, a.seed)
            row = {"map": name, "generated": got is not None}
            if got:
                row["seconds"], row["triangles"] = got
                times.append(got[0])
                print("%s: generated in %.3f s, %d triangles" % (name, got[0], got[1]), flush=True)
            else:
                print("%s: FAILED: %s" % (name, " ".join(info)), flush=True)
            scenario = os.path.join(HERE, "worlds", name + ".xosc")
            if a.render and got and os.path.exists(scenario):
                cache = os.path.join(tmp, "cache_" + name)
                drive = run_scenario(convoy, scenario, cache, os.path.join(tmp, "run_" + name))
                warm = run_scenario(convoy, scenario, cache, os.path.join(tmp, "run2_" + name), timeout=1)
                score = drive.get("score") or {}
                offset = score.get("route_max_offset_m")
                progress = score.get("route_progress_m") or 0
                kept = drive["ok"] and offset is not None and offset <= LANE_KEEPING_M and \
                    progress >= MIN_PROGRESS_M
                row.update(rendered=drive["ok"] and warm["ok"] and drive.get("detector_frames", 0) > 0,
                           startup_cold_s=drive.get("startup_s"), startup_warm_s=warm.get("startup_s"),
                           max_offset_m=offset, lane_kept=kept,
                           progress_m=score.get("route_progress_m"),
                           collisions=len((score.get("nuplan_score") or {}).get("collisions") or []))
                print("%s: %s; drove %.1f m, %s (max %.2f m off the lane centre), %d collisions; "
                      "start-up %.3f s (world cache empty), %.3f s (warm)%s"
                      % (name, "loads and renders" if row["rendered"] else "FAILED",
                         row["progress_m"] or 0, "kept its lane" if kept else "LEFT its lane",
                         offset if offset is not None else float("nan"), row["collisions"],
                         row["startup_cold_s"] or 0, row["startup_warm_s"] or 0,
                         "" if drive["ok"] else ": " + " ".join(drive["stderr"])), flush=True)
            if a.frames == name and got:
                fps, out = camera_fps(a.build, os.path.join(tmp, "worlds", name, "world.sdf"),
                                  ego_start(odr, scenario))
                row["frames_per_s"] = fps
                print(out)
                print("camera frames/s on %s: %s" % (name, fps), flush=True)
            results.append(row)
        n = sum(r["generated"] for r in results)
        print("worlds generated: %d/%d, median %.3f s, max %.3f s"
              % (n, len(results), statistics.median(times) if times else 0, max(times) if times else 0))
        if a.render:
            rendered = [r for r in results if r.get("rendered")]
            warm = [r["startup_warm_s"] for r in rendered if r.get("startup_warm_s")]
            print("worlds that load and render: %d/%d" % (len(rendered), len(results)))
            print("lane kept by the smart car: %d/%d maps" % (sum(bool(r.get("lane_kept")) for r in results),
                                                            len(results)))
            print("start-up of a scenario run, world cache warm: median %.3f s, max %.3f s"
                  % (statistics.median(warm) if warm else 0, max(warm) if warm else 0))
        if a.json:
            with open(a.json, "w") as f:
                json.dump(results, f, indent=1)
        return 0 if n == len(results) else 1
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
