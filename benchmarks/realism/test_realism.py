"""The realism benchmark (benchmarks/realism) in short: metrics on a hand-made trace, then
realism_bench.py --short (60 s after 60 s of warm-up on the large city) checked for every
metric of every source with finite figures, the flows at the measuring points and the PNGs.

  CONVOY_BUILD=build /usr/bin/python3 -m unittest -v benchmarks/realism/test_realism.py
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import metrics  # noqa: E402
import report  # noqa: E402

BUILD = os.environ.get("CONVOY_BUILD", os.path.join(os.path.dirname(os.path.dirname(HERE)),
                                                    "build"))


def trace(rows):
    """rows: (t, vid, lane, s, speed, junction, road, x, y)."""
    a = np.array(rows, dtype=float)
    tr = {"t": a[:, 0], "vid": a[:, 1].astype(int), "lane": a[:, 2].astype(int), "s": a[:, 3],
          "speed": a[:, 4], "junction": a[:, 5].astype(int), "road": a[:, 6].astype(int),
          "x": a[:, 7], "y": a[:, 8], "limit": np.full(len(a), 13.9),
          "length": np.full(len(a), 4.5)}
    order = np.lexsort((tr["t"], tr["vid"]))
    tr = {k: v[order] for k, v in tr.items()}
    tr["names"] = {"roads": ["r0", "r1"], "junctions": ["j0"]}
    return tr


class Metrics(unittest.TestCase):
    def test_headway_is_gap_over_follower_speed(self):
        # vehicle 1 follows vehicle 0 on lane 3: 20 m front to front, a 4.5 m car, 10 m/s.
        tr = trace([(0, 0, 3, 30, 12, -1, 0, 0, 0), (0, 1, 3, 10, 10, -1, 0, 0, 0),
                    (0, 2, 4, 5, 1, -1, 0, 0, 0), (0, 3, 4, 15, 1, -1, 0, 0, 0)])
        h = metrics.time_headways(tr)
        self.assertEqual(len(h), 1)  # the follower on lane 4 moves at 1 m/s: not counted
        self.assertAlmostEqual(h[0], 15.5 / 10)

    def test_constant_acceleration_and_crossing_gap(self):
        rows = [(0.2 * k, 0, 0, 0, 1 + 0.4 * k, -1, 0, 0, 0) for k in range(30)]
        acc, jerk = metrics.accel_jerk(trace(rows))
        self.assertTrue(np.allclose(acc, 2.0))
        self.assertTrue(np.allclose(jerk, 0.0, atol=1e-9))
        # vehicle 0 enters junction 0 heading east at t 1, vehicle 1 heading north at t 4.
        rows = [(0, 0, 0, 0, 5, -1, 0, 0, 0), (0.8, 0, 0, 0, 5, -1, 0, 4, 0),
                (1, 0, 1, 0, 5, 0, -1, 5, 0), (3, 1, 2, 0, 5, -1, 1, 9, -9),
                (3.8, 1, 2, 0, 5, -1, 1, 9, -5), (4, 1, 3, 0, 5, 0, -1, 9, -4)]
        self.assertTrue(np.allclose(metrics.accepted_gaps(trace(rows)), [3.0, 3.0]))

    def test_ks(self):
        self.assertEqual(metrics.ks([1, 2, 3], [1, 2, 3]), 0.0)
        self.assertEqual(metrics.ks([1, 2, 3], [7, 8]), 1.0)


class ShortRun(unittest.TestCase):
    def test_every_metric_for_every_source(self):
        out = tempfile.mkdtemp(prefix="realism-test-")
        r = subprocess.run([sys.executable, os.path.join(HERE, "realism_bench.py"), "--short",
                            "--build", BUILD, "--out", out], capture_output=True, text=True,
                           timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        with open(os.path.join(out, "realism.json")) as f:
            doc = json.load(f)
        self.assertEqual(set(doc["metrics"]), set(report.RULES))
        for name, e in doc["metrics"].items():
            for src in report.SOURCES:
                s = e["sources"][src]
                self.assertGreater(s["n"], 0, "%s %s" % (name, src))
                for q in ("p5", "p25", "p50", "p75", "p95", "mean"):
                    self.assertTrue(math.isfinite(s[q]), "%s %s %s" % (name, src, q))
                self.assertLessEqual(s["p5"], s["p95"])
            for v in e["ks"].values():
                self.assertTrue(0 <= v <= 1, name)
            with open(os.path.join(out, name + ".png"), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        self.assertGreaterEqual(len(doc["flows_vph"]), 3)
        for road, f in doc["flows_vph"].items():
            self.assertTrue(any(v > 0 for v in f.values()), road)
        self.assertIn("collisions 0", doc["setup"]["runs"]["pool"]["summary"])


if __name__ == "__main__":
    unittest.main()
