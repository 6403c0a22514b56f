#!/usr/bin/python3
"""Renders one camera frame per map of benchmarks/worlds (esmini's maps, their worlds generated
by convoy-odr world) and puts them in one picture, to look at what the generator makes.

  /usr/bin/python3 tools/opendrive/look_worlds.py OUT.jpg [--maps a,b,...] [--time 6]
        [--columns 4] [--width 368] [--build build]

Each map's scenario runs for --time simulated seconds (`make_config.py --snapshots`, then
`convoy run -c`) with a fresh world cache, and its frame at that time is scaled to --width
pixels, labelled with the map's name and placed in a grid. Frames are also kept as
OUT_DIR/worlds_frames/<map>.png."""
import argparse
import glob
import os
import subprocess
import sys
import tempfile

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SCENARIOS = os.path.join(REPO, "benchmarks", "worlds")


def frame(build, scenario, t, tmp):
    name = os.path.splitext(os.path.basename(scenario))[0]
    run = os.path.join(tmp, name)
    env = dict(os.environ, CONVOY_CACHE_DIR=os.path.join(tmp, "cache"))
    subprocess.run(["/usr/bin/python3", os.path.join(REPO, "python", "convoy_scenario", "make_config.py"),
                    scenario, "--out", os.path.join(run, "config.json"), "--bin-dir",
                    os.path.join(build, "bin"), "--snapshots", "%g" % t], check=True, env=env,
                   stderr=subprocess.DEVNULL)
    subprocess.run([os.path.join(build, "bin", "convoy"), "run", "-q", "-c", os.path.join(run, "config.json"),
                    "--run-dir", os.path.join(run, "run"), "-o", "SimulationTimeout=%g" % (t + 0.5)],
                   check=True, env=env, stderr=subprocess.DEVNULL)
    return cv2.imread(os.path.join(run, "run", "camera_%gs.png" % t))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--maps")
    ap.add_argument("--time", type=float, default=6.0)
    ap.add_argument("--columns", type=int, default=4)
    ap.add_argument("--width", type=int, default=368)
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    a = ap.parse_args()
    scenarios = sorted(glob.glob(os.path.join(SCENARIOS, "*.xosc")))
    if a.maps:
        scenarios = [os.path.join(SCENARIOS, m + ".xosc") for m in a.maps.split(",")]
    frames_dir = os.path.join(os.path.dirname(os.path.abspath(a.out)), "worlds_frames")
    os.makedirs(frames_dir, exist_ok=True)
    tiles = []
    with tempfile.TemporaryDirectory(prefix="look_worlds_") as tmp:
        for sc in scenarios:
            name = os.path.splitext(os.path.basename(sc))[0]
            img = frame(a.build, sc, a.time, tmp)
            cv2.imwrite(os.path.join(frames_dir, name + ".png"), img)
            h = int(round(img.shape[0] * a.width / img.shape[1]))
            small = cv2.resize(img, (a.width, h), interpolation=cv2.INTER_AREA)
            cv2.rectangle(small, (0, 0), (a.width, 18), (0, 0, 0), -1)
            cv2.putText(small, name, (4, 13), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
            tiles.append(small)
            print("%s: %s" % (name, os.path.join(frames_dir, name + ".png")), flush=True)
    rows = []
    for i in range(0, len(tiles), a.columns):
        row = tiles[i:i + a.columns]
        row += [np.zeros_like(tiles[0])] * (a.columns - len(row))
        rows.append(np.hstack(row))
    cv2.imwrite(a.out, np.vstack(rows), [cv2.IMWRITE_JPEG_QUALITY, 85])
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
