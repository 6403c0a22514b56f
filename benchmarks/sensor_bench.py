#!/usr/bin/python3
"""Sensor benchmark (issue 27): prints the LiDAR figures and the CPU they were measured on.

  /usr/bin/python3 benchmarks/sensor_bench.py [--runs 3] [--scans 100] [--build build]

Runs build/benchmarks/lidar_bench (benchmarks/lidar/lidar_bench.cpp) `--runs` times: the
city_traffic world with 100 moving car-sized boxes, a roof LiDAR at 10 Hz on a vehicle driving
the ego's loop. Prints the median of the runs:

  lidar 32x1024 real-time factor: R   (target >= 10)
  lidar 64x2048 real-time factor: R   (target >= 2)
  lidar range error p99 m: E          (noise off, against a brute-force double-precision
                                       intersection; target <= 0.01)

and, when build/benchmarks/radar_bench is there (benchmarks/radar/radar_bench.cpp: the same
city and traffic, a front radar at 20 Hz on the vehicle driving the loop), the median of as
many runs of `--scans` x 2 scans:

  radar real-time factor: R           (the radar's own work per scan: object tracking, the
                                       Embree scene's update, occlusion rays, detection)
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import machine  # noqa: E402

FIGURES = ("lidar 32x1024 real-time factor", "lidar 64x2048 real-time factor",
           "lidar range error p99 m")
TARGETS = {FIGURES[0]: "target >= 10", FIGURES[1]: "target >= 2", FIGURES[2]: "target <= 0.01"}


RADAR = "radar real-time factor"


def run_radar(program, scans):
    r = subprocess.run([program, "--scans", str(scans)], capture_output=True, text=True)
    m = re.search(re.escape(RADAR) + r": ([0-9.eE+-]+)", r.stdout)
    if r.returncode != 0 or not m:
        sys.exit("radar_bench failed (exit %d):\n%s%s" % (r.returncode, r.stdout, r.stderr))
    return float(m.group(1))


def run_once(program, scans):
    r = subprocess.run([program, "--scans", str(scans)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("lidar_bench failed (exit %d):\n%s" % (r.returncode, r.stderr))
    values = {}
    for name in FIGURES:
        m = re.search(re.escape(name) + r": ([0-9.eE+-]+)", r.stdout)
        if not m:
            sys.exit("lidar_bench printed no '%s':\n%s" % (name, r.stdout))
        values[name] = float(m.group(1))
    return values


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--scans", type=int, default=100)
    ap.add_argument("--build", default=os.path.join(os.path.dirname(HERE), "build"))
    args = ap.parse_args()
    program = os.path.join(args.build, "benchmarks", "lidar_bench")
    if not os.path.exists(program):
        sys.exit("%s not found: cmake --build %s --target lidar_bench" % (program, args.build))
    runs = [run_once(program, args.scans) for _ in range(max(1, args.runs))]
    for name in FIGURES:
        values = [r[name] for r in runs]
        median = statistics.median(values)
        fmt = "%.5f" if name == FIGURES[2] else "%.1f"
        print(("%s: " + fmt + "   (%s; runs: %s)") % (
            name, median, TARGETS[name], ", ".join(fmt % v for v in values)))
    radar = os.path.join(args.build, "benchmarks", "radar_bench")
    if os.path.exists(radar):
        values = [run_radar(radar, 2 * args.scans) for _ in range(max(1, args.runs))]
        print("%s: %.1f   (runs: %s)" % (RADAR, statistics.median(values),
                                         ", ".join("%.1f" % v for v in values)))
    else:
        print("%s: not measured (cmake --build %s --target radar_bench)" % (RADAR, args.build))
    print("CPU: %s, %d cores" % (machine.cpu_model(), os.cpu_count() or 0))


if __name__ == "__main__":
    main()
