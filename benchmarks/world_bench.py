#!/usr/bin/python3
"""World-engine benchmark: prints the three figures of the world-engine issue.

  /usr/bin/python3 benchmarks/world_bench.py [--runs 5]

  - physics real-time factor of a four-wheeled car with two steering joints at a 1 ms step
    (build/benchmarks/world_bench)
  - camera 736x480 frames/s in a scene of about 100k triangles (build/benchmarks/render_bench)
  - world step plus a 736x480 camera frame delivered to a Python TF through the coordinator
    (benchmarks/world_camera: one frame per 10 ms engine step), frames/s
  - Parkring start-up (the coordinator's "engines initialized in ... s": from the command's
    start to the first loop step) without and with the parsed-world cache, and its parts
    (build/benchmarks/startup_bench)

  /usr/bin/python3 benchmarks/world_bench.py --startup-only   # just the start-up figures
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def parkring_startup(build, runs):
    """Median start-up of the Parkring detection experiment, cache off and cache warm."""
    exp = os.path.join(REPO, "experiments", "autonomous_driving")
    work = tempfile.mkdtemp(prefix="convoy-startup-")
    try:
        cache = os.path.join(work, "cache")
        result = {}
        for label, cache_dir in (("no cache", "off"), ("cache", cache)):
            env = dict(os.environ, CONVOY_CACHE_DIR=cache_dir)
            values = []
            for i in range(runs + (1 if cache_dir != "off" else 0)):  # the first fills the cache
                run_dir = os.path.join(work, "run-%s-%d" % (label.replace(" ", ""), i))
                r = subprocess.run([os.path.join(build, "bin", "convoy"), "run", "-q", "-c",
                                    os.path.join(exp, "simulation_config_detection.json"),
                                    "-o", "SimulationTimeout=0.1", "--run-dir", run_dir],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
                if r.returncode != 0:
                    sys.exit("Parkring run failed:\n" + r.stderr)
                with open(os.path.join(run_dir, "logs", "coordinator.log")) as f:
                    m = re.search(r"engines initialized in ([0-9.]+) s", f.read())
                if cache_dir != "off" and i == 0:
                    continue
                values.append(float(m.group(1)))
            result[label] = values
        for label, values in result.items():
            print("Parkring start-up (%s): median %.2f s (runs: %s)%s" % (
                label, statistics.median(values), ", ".join("%.2f" % v for v in values),
                "  target <= 2 s (city_traffic)" if label == "cache" else ""))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    path = os.path.join(build, "benchmarks", "startup_bench")
    if os.path.exists(path):
        sys.stdout.flush()
        subprocess.run([path, os.path.join(exp, "parkring_world.sdf"), str(runs)], check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--startup-only", action="store_true")
    args = ap.parse_args()
    if args.startup_only:
        parkring_startup(args.build, max(3, args.runs if args.runs != 5 else 3))
        return
    for prog in ("world_bench", "render_bench"):
        path = os.path.join(args.build, "benchmarks", prog)
        if os.path.exists(path):
            sys.stdout.flush()
            subprocess.run([path], check=True)
        else:
            print("(%s not built)" % prog)
    work = tempfile.mkdtemp(prefix="convoy-worldbench-")
    try:
        shutil.copytree(os.path.join(HERE, "world_camera"), os.path.join(work, "world_camera"))
        shutil.copytree(os.path.join(HERE, "dataplane"), os.path.join(work, "dataplane"))
        values = []
        for i in range(args.runs):
            r = subprocess.run([os.path.join(args.build, "bin", "convoy"), "run", "-q", "-c",
                                os.path.join(work, "world_camera", "simulation_config.json"),
                                "-o", "SimulationTimeout=10", "--run-dir", os.path.join(work, "run%d" % i)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            if r.returncode != 0:
                sys.exit("world camera run failed:\n" + r.stderr)
            with open(os.path.join(work, "world_camera", "timing_view.json")) as f:
                t = json.load(f)
            if t["changed"] < t["frames"] - 1:
                sys.exit("frames did not change every step: %r" % t)
            values.append(t["steps_per_s"])
        print("world step + 736x480 camera frame to a Python TF via the coordinator: median %.1f frames/s "
              "(runs: %s)  target >= 100" % (statistics.median(values), ", ".join("%.1f" % v for v in values)))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    parkring_startup(args.build, 3)


if __name__ == "__main__":
    main()
