#!/usr/bin/python3
"""The video writer's encoder memory over a long run (issue 30, soak): feeds
convoy_video.VideoWriter N synthetic camera frames (city_traffic's size, 736x480, a moving
scene) as fast as ffmpeg takes them and samples the ffmpeg process's resident memory.

    /usr/bin/python3 benchmarks/video_memory_bench.py [--frames 108000] [--every 3000]

108,000 frames are one simulated hour of city_traffic's 30 Hz camera. Prints the RSS of ffmpeg
every --every frames and last `ffmpeg growth MiB: N` (the largest RSS after the first 9,000
frames, the soak's 300 s warm-up, minus the RSS then) and the file's frame count (ffprobe).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from convoy_video import VideoWriter  # noqa: E402

W, H, WARMUP = 736, 480, 9000


def rss_kib(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def frame(k, base):
    """A scene that moves: the background scrolls, a box crosses it."""
    img = np.roll(base, k % W, axis=1)
    x = (7 * k) % (W - 80)
    img[200:260, x:x + 80] = (40, 40, 200)
    return img


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=108000)
    ap.add_argument("--every", type=int, default=3000)
    args = ap.parse_args()
    cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = next((l.split(":", 1)[1].strip() for l in cpu.splitlines() if "Model name" in l), "?")
    print("video memory: %d frames of %dx%d; CPU %s" % (args.frames, W, H, model), flush=True)
    rng = np.random.default_rng(1)
    base = (rng.integers(0, 60, (H, W, 3)) + np.linspace(60, 180, W)[None, :, None]).astype(np.uint8)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "camera.mp4")
        video = VideoWriter(path, fps=30)
        t0 = time.monotonic()
        baseline, peak = None, 0
        for k in range(args.frames):
            video.write(frame(k, base))
            if (k + 1) % args.every == 0:
                r = rss_kib(video._proc.pid)
                if k + 1 >= WARMUP:
                    baseline = r if baseline is None else baseline
                    peak = max(peak, r)
                print("frame %6d  ffmpeg RSS %.2f MiB  (%.0f s)" % (k + 1, r / 1024,
                                                                    time.monotonic() - t0), flush=True)
        video.close()
        n = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                            "-show_entries", "stream=nb_read_frames", "-of", "csv=p=0", path],
                           capture_output=True, text=True).stdout.strip()
        print("frames in the file: %s" % n)
    print("ffmpeg growth MiB: %.2f" % ((peak - (baseline or 0)) / 1024))


if __name__ == "__main__":
    main()
