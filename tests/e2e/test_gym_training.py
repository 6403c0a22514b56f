"""End-to-end test of the training example experiments/rl_parkring/train_cem.py (the
cross-entropy method on convoy_gym's DrivingEnv, docs/gym.md "Training example"): a very short
run (2 iterations) exits 0, writes curve.csv with one row per episode and the PNG, prints the
first-10 / last-10 means, and the same command gives the same curve.

Label `long` (ctest -L long). Run: cd tests/e2e && CONVOY_BIN_DIR=../../build/bin
/usr/bin/python3 -m unittest -v test_gym_training"""
import csv
import math
import os
import shutil
import subprocess
import tempfile
import unittest

from e2e_util import BIN_DIR, REPO

SCRIPT = os.path.join(REPO, "experiments", "rl_parkring", "train_cem.py")
ITERATIONS, POPULATION = 2, 4


def run(out):
    env = dict(os.environ, CONVOY_BIN_DIR=os.environ.get("CONVOY_BIN_DIR", BIN_DIR))
    return subprocess.run(
        ["/usr/bin/python3", SCRIPT, "--iterations", str(ITERATIONS), "--population",
         str(POPULATION), "--elite", "2", "--steps", "100", "--out", out,
         "--png", os.path.join(out, "curve.png")],
        capture_output=True, text=True, timeout=240, env=env)


class TrainingExample(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convoy_gym_training_")
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)

    def test_short_run(self):
        out = os.path.join(self.tmp, "a")
        p = run(out)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("first 10 episodes mean return: ", p.stdout)
        self.assertIn("last 10 episodes mean return: ", p.stdout)
        with open(os.path.join(out, "curve.csv")) as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows[0], ["episode", "iteration", "return"])
        body = rows[1:]
        self.assertEqual(len(body), ITERATIONS * POPULATION)
        self.assertEqual([int(r[0]) for r in body], list(range(1, ITERATIONS * POPULATION + 1)))
        self.assertEqual([int(r[1]) for r in body],
                         [i for i in range(ITERATIONS) for _ in range(POPULATION)])
        self.assertTrue(all(math.isfinite(float(r[2])) for r in body))
        with open(os.path.join(out, "curve.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

        # fixed seeds: the same command, the same curve
        out2 = os.path.join(self.tmp, "b")
        p2 = run(out2)
        self.assertEqual(p2.returncode, 0, p2.stdout + p2.stderr)
        with open(os.path.join(out2, "curve.csv")) as f:
            self.assertEqual(list(csv.reader(f)), rows)

    def test_bad_option(self):
        p = subprocess.run(["/usr/bin/python3", SCRIPT, "--population", "1",
                            "--out", self.tmp], capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 2)
        self.assertIn("--population", p.stderr)


if __name__ == "__main__":
    unittest.main()
