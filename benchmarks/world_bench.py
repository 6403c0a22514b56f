#!/usr/bin/python3
"""World-engine benchmark: prints the three figures of the world-engine issue.

  /usr/bin/python3 benchmarks/world_bench.py [--runs 5]

  - physics real-time factor of a four-wheeled car with two steering joints at a 1 ms step
    (build/benchmarks/world_bench)
  - camera 736x480 frames/s in a scene of about 100k triangles (build/benchmarks/render_bench)
  - world step plus a 736x480 camera frame delivered to a Python TF through the coordinator
    (benchmarks/world_camera: one frame per 10 ms engine step), frames/s
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    args = ap.parse_args()
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


if __name__ == "__main__":
    main()
