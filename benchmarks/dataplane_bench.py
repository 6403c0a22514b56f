#!/usr/bin/python3
"""Data-plane benchmark: a camera frame relayed engine -> TF -> engine every loop step.

  /usr/bin/python3 benchmarks/dataplane_bench.py [--runs 5] [--memory-frames 100000]

Prints (median of --runs, frames/s as timed by the receiving engine's runLoop calls):
  - 736x480 RGB relay as a protobuf camera datapack (GazeboCameraDataPack)
  - 736x480 RGB relay with the report's numpy-in-JSON pattern (camera_tf.py)
  - the same two at 1920x1080
  - the same 736x480 relays with shared memory off (CONVOY_SHM_MB=0: bytes inline)
  - NRP-Core's b_image_json experiment unchanged (a flat list of ints), if shared/ is there
  - coordinator RSS growth over --memory-frames relayed 736x480 frames
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


def run(args, cfg, overrides, run_dir, env=None, sample_rss=False):
    cmd = [os.path.join(args.bin_dir, "convoy"), "run", "-q", "-c", cfg, "--run-dir", run_dir]
    for o in overrides:
        cmd += ["-o", o]
    e = dict(os.environ)
    e.update(env or {})
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=e)
    samples = []
    while p.poll() is None:
        if sample_rss:
            try:
                with open("/proc/%d/status" % p.pid) as f:
                    for line in f:
                        if line.startswith("VmRSS:"):
                            samples.append((time.perf_counter(), int(line.split()[1])))
            except OSError:
                pass
        time.sleep(0.05)
    if p.returncode != 0:
        sys.exit("benchmark run failed (%s):\n%s" % (" ".join(cmd), p.stderr.read()))
    return samples


def relay(args, work, kind, w, h, frames, env=None):
    exp = os.path.join(work, "dataplane")
    values = []
    for i in range(args.runs):
        run(args, os.path.join(exp, "simulation_config_%s.json" % kind),
            ["SimulationTimeout=%g" % (frames * 0.01),
             "EngineConfigs/0/EngineEnvParams=[\"IMG_W=%d\",\"IMG_H=%d\"]" % (w, h),
             "EngineConfigs/1/EngineEnvParams=[\"IMG_W=%d\",\"IMG_H=%d\"]" % (w, h)],
            os.path.join(work, "runs", "%s_%d" % (kind, i)), env)
        with open(os.path.join(exp, "timing_view.json")) as f:
            t = json.load(f)
        if t["bad"] or t["fresh"] < t["n_calls"] - 1:
            sys.exit("relay check failed: %r" % t)
        values.append(t["steps_per_s"])
    return values


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--frames", type=int, default=3000, help="frames per timed run")
    ap.add_argument("--memory-frames", type=int, default=100000)
    ap.add_argument("--bin-dir", default=os.path.join(REPO, "build", "bin"))
    ap.add_argument("--bench-dir", default=os.path.join(os.path.dirname(REPO), "shared", "nrp-bench"))
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="convoy-dataplane-")
    try:
        shutil.copytree(os.path.join(HERE, "dataplane"), os.path.join(work, "dataplane"))

        def report(name, values, target):
            print("%-58s median %8.1f frames/s  (runs: %s)  target %s" % (
                name, statistics.median(values), ", ".join("%.0f" % v for v in values), target),
                flush=True)

        report("736x480 relay, protobuf camera datapack", relay(args, work, "proto", 736, 480, args.frames),
               ">= 2000 (NRP-Core grpc 152)")
        report("736x480 relay, numpy-in-JSON (report's camera_tf.py)",
               relay(args, work, "json", 736, 480, args.frames), ">= 2000 (NRP-Core json 3.5)")
        report("1920x1080 relay, protobuf camera datapack",
               relay(args, work, "proto", 1920, 1080, args.frames // 3), "reported")
        report("1920x1080 relay, numpy-in-JSON", relay(args, work, "json", 1920, 1080, args.frames // 3),
               "reported")
        report("736x480 relay, protobuf, shared memory off (inline)",
               relay(args, work, "proto", 736, 480, 300, {"CONVOY_SHM_MB": "0"}), "reported")
        bench = args.bench_dir
        if os.path.isdir(os.path.join(bench, "b_image_json")):
            shutil.copytree(os.path.join(bench, "b_image_json"), os.path.join(work, "b_image_json"))
            shutil.copytree(os.path.join(bench, "common"), os.path.join(work, "common"))
            vals = []
            for i in range(args.runs):
                run(args, os.path.join(work, "b_image_json", "simulation_config_736x480.json"),
                    ["SimulationTimeout=1"], os.path.join(work, "runs", "b_%d" % i))
                with open(os.path.join(work, "b_image_json", "timing_python_2.json")) as f:
                    vals.append(json.load(f)["steps_per_s"])
            report("NRP-Core b_image_json 736x480 unchanged (list of ints)", vals, "- (NRP-Core 3.5)")
        samples = run(args, os.path.join(work, "dataplane", "simulation_config_proto.json"),
                      ["SimulationTimeout=%g" % (args.memory_frames * 0.01)],
                      os.path.join(work, "runs", "mem"), sample_rss=True)
        t0, t1 = samples[0][0], samples[-1][0]
        steady = [v for t, v in samples if t >= t0 + 0.1 * (t1 - t0)]
        print("%-58s first %d KiB, last %d KiB, max %d KiB: growth %+d KiB  target < 10 MiB" % (
            "coordinator RSS over %d relayed 736x480 frames" % args.memory_frames,
            steady[0], steady[-1], max(steady), steady[-1] - steady[0]), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
