#!/usr/bin/python3
"""Autonomous-driving benchmark: runs the experiment's three configs and prints the issue's
figures (median of --runs), from each run's summary_driving.json.

  /usr/bin/python3 benchmarks/driving_bench.py [--runs 3] [--backend ground_truth|hog|yolo] [--model M.onnx]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
EXP = os.path.join(REPO, "experiments", "autonomous_driving")


def run(args, config, extra, run_dir):
    cmd = [os.path.join(args.build, "bin", "convoy"), "run", "-q", "-c", os.path.join(EXP, config),
           "--run-dir", run_dir] + extra
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("run failed (%s):\n%s" % (" ".join(cmd), r.stderr))
    with open(os.path.join(run_dir, "summary_driving.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--backend", default="ground_truth")
    ap.add_argument("--model", default="")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--detection-seconds", type=float, default=30)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="convoy-driving-")
    det = ["-o", "EngineConfigs/1/Backend=%s" % args.backend]
    det_both = ["-o", "EngineConfigs/2/Backend=%s" % args.backend]
    if args.model:
        det += ["-o", "EngineConfigs/1/ModelPath=%s" % args.model]
        det_both += ["-o", "EngineConfigs/2/ModelPath=%s" % args.model]
    rows = {"control": [], "detection": [], "both": []}
    for i in range(args.runs):
        rows["control"].append(run(args, "simulation_config_control.json", [], os.path.join(work, "c%d" % i)))
        rows["detection"].append(run(args, "simulation_config_detection.json",
                                     det + ["-o", "SimulationTimeout=%g" % args.detection_seconds],
                                     os.path.join(work, "d%d" % i)))
        rows["both"].append(run(args, "simulation_config_both.json", det_both, os.path.join(work, "b%d" % i)))
    med = lambda k, key: statistics.median(r[key] for r in rows[k])
    print("control only: real-time factor (whole run) median %.1fx (runs: %s); lap %s in %.1f s sim; "
          "cross-track mean %.3f m, max %.3f m" % (
              med("control", "real_time_factor"), ", ".join("%.1f" % r["real_time_factor"] for r in rows["control"]),
              rows["control"][0]["lap_completed"], rows["control"][0]["lap_time_s"] or 0,
              rows["control"][0]["cross_track_error_m"]["mean"], rows["control"][0]["cross_track_error_m"]["max"]))
    for k in ("detection", "both"):
        print("%s (backend %s): camera frames/s median %.1f (runs: %s); precision %s, recall %s" % (
            k, args.backend, med(k, "camera_frames_per_s"),
            ", ".join("%.1f" % r["camera_frames_per_s"] for r in rows[k]),
            rows[k][0]["detector_precision"], rows[k][0]["detector_recall"]))
    print("(runs kept in %s)" % work)


if __name__ == "__main__":
    main()
