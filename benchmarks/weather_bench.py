#!/usr/bin/python3
"""Weather benchmark: prints the figures of the weather issue (median of --runs runs).

  /usr/bin/python3 benchmarks/weather_bench.py [--runs 3] [--seconds 40]

  - Parkring camera frames/s (the autonomous_driving detection experiment: the 30 Hz
    736x480 camera and the detector's ground-truth backend, for --seconds simulated) in
    clear weather, in rain (0.7) with fog (100 m visibility), in snow and at night, and each
    against clear (target: rain + fog >= 85 % of clear)
  - braking distance from 50 km/h per surface (experiments/weather_braking's braking.json),
    next to v^2 / (2 mu g) (target: within 10 %)
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

WEATHERS = [
    ("clear", []),
    ("rain + fog", ["Precipitation=0.7", "Surface=\"wet\"", "Visibility=100"]),
    ("snow", ["Precipitation=0.5", "PrecipitationType=\"snow\"", "Surface=\"snow\""]),
    ("night", ["SunAltitude=-20"]),
]


def run(convoy, config, run_dir, overrides):
    cmd = [convoy, "run", "-q", "-c", config, "--run-dir", run_dir]
    for o in overrides:
        cmd += ["-o", o]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("run failed (%s):\n%s" % (" ".join(cmd), r.stderr[-2000:]))
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=40.0)
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--skip-braking", action="store_true")
    args = ap.parse_args()
    convoy = os.path.join(args.build, "bin", "convoy")
    work = tempfile.mkdtemp(prefix="convoy-weather-bench-")
    try:
        config = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_detection.json")
        with open(config) as f:
            index = [e["EngineName"] for e in json.load(f)["EngineConfigs"]].index("weather")
        fps = {}
        for label, keys in WEATHERS:
            values = []
            for i in range(args.runs):
                overrides = ["SimulationTimeout=%g" % args.seconds]
                overrides += ["EngineConfigs/%d/%s" % (index, k) for k in keys]
                s = run(convoy, config, os.path.join(work, "%s-%d" % (label.replace(" ", ""), i)), overrides)
                values.append(s["camera_frames_per_s"])
            fps[label] = values
        clear = statistics.median(fps["clear"])
        for label, values in fps.items():
            m = statistics.median(values)
            print("Parkring camera frames/s, %-10s median %6.1f (runs: %s)  %5.1f %% of clear%s" % (
                label + ":", m, ", ".join("%.1f" % v for v in values), 100 * m / clear,
                "  target >= 85 %" if label == "rain + fog" else ""))
        if args.skip_braking:
            return
        config = os.path.join(REPO, "experiments", "weather_braking", "simulation_config.json")
        runs = [run(convoy, config, os.path.join(work, "braking-%d" % i), []) for i in range(args.runs)]
        results = []
        for i in range(args.runs):
            with open(os.path.join(work, "braking-%d" % i, "braking.json")) as f:
                results.append(json.load(f))
        for surface in ("dry", "wet", "snow", "ice"):
            d = [r["surfaces"][surface]["distance_m"] for r in results]
            s0 = results[0]["surfaces"][surface]
            m = statistics.median(d)
            print("braking from 50 km/h on %-4s (mu %.2f): median %6.2f m (runs: %s), v^2/(2 mu g) "
                  "%6.2f m: %+5.1f %%  target within 10 %%" % (
                      surface, s0["mu"], m, ", ".join("%.2f" % x for x in d), s0["expected_m"],
                      100 * (m / s0["expected_m"] - 1)))
        del runs
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
