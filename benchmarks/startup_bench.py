#!/usr/bin/python3
"""Start-up of the driving experiments: from the `convoy run` command's start to the first loop
step (summary.json's `startup_s`, the kernel's start of the process to the loop's first step),
and its parts (summary.json's `startup`: the coordinator's own, then each engine's process
start-up and Initialize; engines initialize concurrently).

  /usr/bin/python3 benchmarks/startup_bench.py [--runs 3] [--timeout 0.1] [--build build]
                                               [--json out.json] [--ego E] [CONFIG ...]

A CONFIG ending in .xosc runs as `convoy run --scenario FILE` (its config made in the run, which
the start-up includes), with `--ego E` when given.

Each config runs once with empty caches (a fresh CONVOY_CACHE_DIR and XDG_CACHE_HOME: the
parsed-world cache, SUMO's converted network...), reported as "cold", then `--runs` times with
those caches filled, reported as the median ("warm"). Run it on a quiet machine (on a shared
one: `flock /work/.buildlock ...`); the figures are wall times.
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
CONFIGS = [
    "experiments/autonomous_driving/simulation_config_both.json",
    "experiments/city_traffic/simulation_config.json",
    "experiments/ego_planner/simulation_config.json",
    "experiments/ego_planner/simulation_config_acc.json",
    "experiments/ego_planner/simulation_config_detector.json",
]
PARTS = ("process_s", "functions_s", "launch_s", "initialize_s", "prime_s")


def run_once(convoy, config, timeout, run_dir, env, ego=None):
    """One run; an .xosc runs as `convoy run --scenario` (the config made in the run, which
    start-up counts), with `--ego EGO` when given."""
    what = ["--scenario", config] + (["--ego", ego] if ego else []) if config.endswith(".xosc") \
        else ["-c", config]
    r = subprocess.run([convoy, "run", "-q"] + what + ["-o", "SimulationTimeout=%g" % timeout,
                        "--run-dir", run_dir], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       text=True, env=env)
    if r.returncode != 0:
        sys.exit("%s failed (exit %d):\n%s" % (config, r.returncode, r.stderr))
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)
    if s.get("startup_s") is None:
        sys.exit("%s: summary.json has no startup_s (an older build?)" % run_dir)
    return s


def median_startup(summaries):
    """The median of each figure over the runs."""
    med = lambda xs: statistics.median(xs) if xs else None  # noqa: E731
    out = {"startup_s": med([s["startup_s"] for s in summaries])}
    for p in PARTS:
        out[p] = med([s["startup"][p] for s in summaries if s["startup"].get(p) is not None])
    engines = {}
    for name in summaries[0]["startup"]["engines"]:
        e = [s["startup"]["engines"].get(name, {}) for s in summaries]
        engines[name] = {k: med([x[k] for x in e if x.get(k) is not None])
                         for k in ("process_s", "initialize_s")}
    out["engines"] = engines
    return out


def fmt(v):
    return "   -  " if v is None else "%6.3f" % v


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("configs", nargs="*", help="simulation configs (default: the driving experiments)")
    ap.add_argument("--runs", type=int, default=3, help="warm runs per config (default 3)")
    ap.add_argument("--timeout", type=float, default=0.1, help="SimulationTimeout of each run, s")
    ap.add_argument("--build", default=os.path.join(REPO, "build"), help="the build folder")
    ap.add_argument("--json", help="also write the figures here")
    ap.add_argument("--ego", help="for .xosc configs: convoy run --scenario's --ego (e.g. scenario)")
    args = ap.parse_args()
    convoy = os.path.join(args.build, "bin", "convoy")
    if not os.access(convoy, os.X_OK):
        sys.exit("no %s: build first (or --build DIR)" % convoy)
    if args.runs < 1:
        sys.exit("--runs must be >= 1")
    configs = [os.path.abspath(os.path.join(REPO, c) if not os.path.isabs(c) else c)
               for c in (args.configs or CONFIGS)]
    for c in configs:
        if not os.path.isfile(c):
            sys.exit("no config %s" % c)
    work = tempfile.mkdtemp(prefix="convoy-startup-")
    results = {}
    try:
        for config in configs:
            name = os.path.relpath(config, REPO)
            cache = os.path.join(work, "cache-%d" % len(results))
            env = dict(os.environ, CONVOY_CACHE_DIR=os.path.join(cache, "convoy"), XDG_CACHE_HOME=cache)
            cold = run_once(convoy, config, args.timeout, os.path.join(work, "run-cold"), env, args.ego)
            warm = [run_once(convoy, config, args.timeout, os.path.join(work, "run-%d" % i), env, args.ego)
                    for i in range(args.runs)]
            results[name] = {"cold": median_startup([cold]), "warm": median_startup(warm),
                             "warm_runs_s": [s["startup_s"] for s in warm]}
            shutil.rmtree(cache, ignore_errors=True)
            w = results[name]["warm"]
            print("%s: start-up cold %.3f s, warm median %.3f s (runs: %s)" % (
                name, cold["startup_s"], w["startup_s"],
                ", ".join("%.3f" % v for v in results[name]["warm_runs_s"])), flush=True)
            print("   warm parts (s): " + "  ".join("%s %s" % (p[:-2], fmt(w[p]).strip()) for p in PARTS))
            for e, v in sorted(w["engines"].items(), key=lambda kv: -(kv[1]["initialize_s"] or 0)):
                c = results[name]["cold"]["engines"].get(e, {})
                print("   %-22s process %s  initialize %s   (cold: initialize %s)" % (
                    e, fmt(v["process_s"]), fmt(v["initialize_s"]), fmt(c.get("initialize_s"))))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
