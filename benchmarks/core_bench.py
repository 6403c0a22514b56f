#!/usr/bin/python3
"""Co-simulation core benchmark: runs NRP-Core's benchmark experiments (shared/nrp-bench)
unchanged under Convoy and prints the figures of the core issue.

  /usr/bin/python3 benchmarks/core_bench.py [--runs 5] [--bench-dir shared/nrp-bench]

The experiments write timing_<engine>.json next to their config, so they are copied to a
temporary folder first. Figures (median of --runs):
  - loop steps/s, a_tiny_json (2 python_json engines, tiny datapack, one TF)
  - loop steps/s, ring of 2 / 4 / 8 engines (d_scaling_json)
  - start-up + shutdown wall time of 8 engines (one-step run of the 8-ring)
  - coordinator RSS over 100k steps of a_tiny_json (first sample after start-up, last, max)
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def convoy_bin(args):
    return os.path.join(args.bin_dir, "convoy")


def run(args, cfg, overrides, run_dir):
    cmd = [convoy_bin(args), "run", "-q", "-c", cfg, "--run-dir", run_dir]
    for o in overrides:
        cmd += ["-o", o]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit("benchmark run failed (%s):\n%s" % (" ".join(cmd), r.stderr))
    return wall


def steps_per_s(args, work, exp, cfg, engine, sim_s):
    cfg_path = os.path.join(work, exp, cfg)
    values = []
    for i in range(args.runs):
        run(args, cfg_path, ["SimulationTimeout=%g" % sim_s], os.path.join(work, "runs", "%s_%d" % (cfg, i)))
        with open(os.path.join(work, exp, "timing_%s.json" % engine)) as f:
            values.append(json.load(f)["steps_per_s"])
    return values


def rss_kib(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def memory_run(args, work, steps):
    cfg = os.path.join(work, "a_tiny_json", "simulation_config.json")
    cmd = [convoy_bin(args), "run", "-q", "-c", cfg, "--run-dir", os.path.join(work, "runs", "mem"),
           "-o", "SimulationTimeout=%g" % (steps * 0.01)]
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    samples = []
    while p.poll() is None:
        v = rss_kib(p.pid)
        if v:
            samples.append((time.perf_counter(), v))
        time.sleep(0.05)
    if p.returncode != 0:
        sys.exit("memory run failed:\n" + p.stderr.read())
    # Skip start-up: take samples from 10 % of the run on.
    t_first, t_last = samples[0][0], samples[-1][0]
    steady = [v for t, v in samples if t >= t_first + 0.1 * (t_last - t_first)]
    return steady[0], steady[-1], max(steady)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--bench-dir", default=os.path.join(os.path.dirname(REPO), "shared", "nrp-bench"))
    ap.add_argument("--bin-dir", default=os.path.join(REPO, "build", "bin"))
    ap.add_argument("--memory-steps", type=int, default=100000)
    args = ap.parse_args()
    if not os.path.isdir(args.bench_dir):
        alt = os.path.join(REPO, "shared", "nrp-bench")
        args.bench_dir = alt if os.path.isdir(alt) else args.bench_dir
    work = tempfile.mkdtemp(prefix="convoy-bench-")
    try:
        for d in os.listdir(args.bench_dir):
            src = os.path.join(args.bench_dir, d)
            if os.path.isdir(src):
                shutil.copytree(src, os.path.join(work, d))
        rows = []

        def report(name, values, unit, target):
            med = statistics.median(values)
            rows.append((name, med, unit, target))
            print("%-48s median %10.1f %-8s (runs: %s)  target %s" % (
                name, med, unit, ", ".join("%.0f" % v if v > 10 else "%.3f" % v for v in values), target),
                flush=True)

        report("a_tiny_json loop steps/s", steps_per_s(args, work, "a_tiny_json", "simulation_config.json",
                                                        "python_2", 200), "steps/s", ">= 20000 (NRP-Core 370)")
        for n, target in ((2, "- (NRP-Core 368)"), (4, "- (NRP-Core 183)"), (8, ">= 3000 (NRP-Core 69)")):
            report("ring of %d engines loop steps/s" % n,
                   steps_per_s(args, work, "d_scaling_json", "simulation_config_%d.json" % n, "e0", 100),
                   "steps/s", target)
        walls = [run(args, os.path.join(work, "d_scaling_json", "simulation_config_8.json"),
                     ["SimulationTimeout=0.01"], os.path.join(work, "runs", "startup_%d" % i))
                 for i in range(args.runs)]
        report("start-up + shutdown of 8 engines (whole run)", walls, "s", "<= 1 s (NRP-Core 12.4 s)")
        first, last, peak = memory_run(args, work, args.memory_steps)
        print("%-48s first %d KiB, last %d KiB, max %d KiB, growth %+d KiB  target flat" % (
            "coordinator RSS over %d steps" % args.memory_steps, first, last, peak, last - first), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
