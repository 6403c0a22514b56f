"""experiments/cut_in: a python_json road user cuts in just ahead of a vehicle agent; the agent
brakes (IDM) without touching it, and the run is deterministic."""

import json
import os
import subprocess
import tempfile
import unittest

from e2e_util import CONVOY, REPO

EXAMPLE = os.path.join(REPO, "experiments", "cut_in")


def run_example(run_dir):
    p = subprocess.run([CONVOY, "run", "-c", "simulation_config.json", "--run-dir", run_dir,
                        "-q"], cwd=EXAMPLE, capture_output=True, text=True, timeout=120)
    return p


class CutIn(unittest.TestCase):
    def test_cut_in(self):
        with tempfile.TemporaryDirectory() as tmp:
            results = []
            for i in range(2):
                run_dir = os.path.join(tmp, "run%d" % i)
                p = run_example(run_dir)
                self.assertEqual(p.returncode, 0, p.stderr[-2000:])
                with open(os.path.join(run_dir, "cut_in.json")) as f:
                    results.append(f.read())
            r = json.loads(results[0])
            self.assertIsNotNone(r["cut_in_time_s"], r)        # the cut-in happened
            self.assertTrue(r["cutter_ahead_in_agent_lane"], r)  # and it ended ahead
            self.assertEqual(r["cutter"]["lane"], r["agent"]["lane"])
            self.assertGreater(r["cutter"]["x"], r["agent"]["x"])
            self.assertLess(r["min_agent_acceleration"], -1.0, r)  # the agent braked
            self.assertFalse(r["overlap"], r)                      # never touched
            self.assertGreater(r["min_gap_m"], 0.0, r)
            self.assertLess(r["min_gap_m"], 5.0, r)                # it was a tight cut-in
            self.assertEqual(results[0], results[1])               # deterministic


if __name__ == "__main__":
    unittest.main()
