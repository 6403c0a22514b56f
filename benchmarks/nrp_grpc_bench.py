#!/usr/bin/python3
"""python_grpc benchmark: runs NRP-Core's protobuf benchmark experiments (shared/nrp-bench)
unchanged under Convoy and prints the figures of issue 16.

  /usr/bin/python3 benchmarks/nrp_grpc_bench.py [--runs 5] [--bench-dir shared/nrp-bench]

The experiments write timing_<engine>.json next to their config, so they are copied to a
temporary folder first. Figures (median of --runs; the receiving engine's steps_per_s):
  - a_tiny_grpc: loop steps/s (2 python_grpc engines, a Dump.String relayed by one TF)
  - c_image_grpc: frames/s of a 736x480x3 Gazebo.Camera relayed by a TF (and 320x240), with
    the copies of a frame each process made (summary.json's frame_copies per loop cycle)
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


def run(args, cfg, sim_s, run_dir):
    cmd = [os.path.join(args.bin_dir, "convoy"), "run", "-q", "-c", cfg, "--run-dir", run_dir,
           "-o", "SimulationTimeout=%g" % sim_s]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("benchmark run failed (%s):\n%s" % (" ".join(cmd), r.stderr))
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)


def measure(args, work, exp, cfg, sim_s, check):
    """steps_per_s of python_2 in each run, and the last run's summary and timing."""
    values, summary, timing = [], None, None
    for i in range(args.runs):
        summary = run(args, os.path.join(work, exp, cfg), sim_s,
                      os.path.join(work, "runs", "%s_%d" % (cfg, i)))
        with open(os.path.join(work, exp, "timing_python_2.json")) as f:
            timing = json.load(f)
        check(timing)
        values.append(timing["steps_per_s"])
    return values, summary, timing


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--bench-dir", default=os.path.join(os.path.dirname(REPO), "shared", "nrp-bench"))
    ap.add_argument("--bin-dir", default=os.path.join(REPO, "build", "bin"))
    ap.add_argument("--tiny-s", type=float, default=200, help="simulated seconds of a_tiny_grpc (0.01 s steps)")
    ap.add_argument("--image-s", type=float, default=30, help="simulated seconds of c_image_grpc")
    args = ap.parse_args()
    if not os.path.isdir(args.bench_dir):  # in the repo, or next to a worktree's parent
        for alt in (os.path.join(REPO, "shared", "nrp-bench"),
                    os.path.join(os.path.dirname(os.path.dirname(REPO)), "shared", "nrp-bench")):
            if os.path.isdir(alt):
                args.bench_dir = alt
                break
    work = tempfile.mkdtemp(prefix="convoy-grpc-bench-")
    try:
        for d in ("a_tiny_grpc", "c_image_grpc", "common"):
            shutil.copytree(os.path.join(args.bench_dir, d), os.path.join(work, d))

        def report(name, values, unit, target):
            print("%-44s median %9.1f %-9s (runs: %s)  target %s" % (
                name, statistics.median(values), unit, ", ".join("%.0f" % v for v in values), target),
                flush=True)

        steps = round(args.tiny_s / 0.01)

        def tiny_ok(t):  # every step got the datapack of the step before
            if t["n_fresh"] != steps or t["last_seq"] != steps - 1:
                sys.exit("a_tiny_grpc: %d fresh values, last %d, of %d steps" % (t["n_fresh"], t["last_seq"], steps))

        values, _, _ = measure(args, work, "a_tiny_grpc", "simulation_config.json", args.tiny_s, tiny_ok)
        report("a_tiny_grpc loop steps/s", values, "steps/s", ">= 20000 (NRP-Core 601)")

        for size, target in (("736x480", ">= 1000 (NRP-Core 152)"), ("320x240", "- (NRP-Core 432)")):
            frames = round(args.image_s / 0.01)

            def image_ok(t):  # every frame arrived, fresh and of the right shape
                if t["n_fresh"] != frames or t["bad_shape"] or t["n_images"] != frames:
                    sys.exit("c_image_grpc %s: %s" % (size, t))

            values, summary, _ = measure(args, work, "c_image_grpc", "simulation_config_%s.json" % size,
                                         args.image_s, image_ok)
            report("c_image_grpc %s frames/s" % size, values, "frames/s", target)
            cycles = summary["cycles"]
            copies = summary["frame_copies"]
            print("%-44s %s  (per loop cycle; %d cycles)" % (
                "c_image_grpc %s copies of a frame" % size,
                ", ".join("%s %.2f" % (p, n / cycles) for p, n in sorted(copies.items())), cycles),
                flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
