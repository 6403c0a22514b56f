"""End-to-end tests of convoy_gym's DrivingEnv on experiments/rl_parkring: the gymnasium
contract (reset / step shapes and dtypes, observations in the observation space), seeding
(same seed -> the same episode bit for bit, another seed -> another), actions outside the
space, termination and truncation, a custom reward, another physics step, and that close(),
a `with` block and garbage collection leave no process behind.

Run: cd tests/e2e && CONVOY_BIN_DIR=../../build/bin /usr/bin/python3 -m unittest -v test_gym"""
import gc
import os
import subprocess
import sys
import time
import unittest

import numpy as np

from e2e_util import BIN_DIR, REPO, pid_alive

os.environ.setdefault("CONVOY_BIN_DIR", BIN_DIR)
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_gym import DrivingEnv  # noqa: E402


def policy(obs):
    """Steer along the heading error at 6 m/s."""
    return np.array([np.clip(0.8 * obs[4], -0.55, 0.55), 6.0], dtype=np.float32)


def descendants(pid):
    """`pid` and every process below it."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open("/proc/%s/stat" % entry) as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo += children.get(p, [])
    return out


def server_processes(env):
    return descendants(env._nrp._server.process.pid)


def assert_gone(test, pids, within=5.0):
    deadline = time.monotonic() + within
    while any(pid_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    test.assertEqual([p for p in pids if pid_alive(p)], [], "processes left behind")


class DrivingEnvTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = DrivingEnv(max_steps=200)

    @classmethod
    def tearDownClass(cls):
        cls.env.close()

    def episode(self, seed, steps=50):
        obs, info = self.env.reset(seed=seed)
        trajectory, rewards = [obs], []
        for _ in range(steps):
            obs, reward, terminated, truncated, info = self.env.step(policy(obs))
            trajectory.append(obs)
            rewards.append(reward)
        return np.array(trajectory), rewards

    def test_reset_and_step_contract(self):
        env = self.env
        self.assertEqual(env.observation_space.shape, (16,))
        self.assertEqual(env.action_space.shape, (2,))
        obs, info = env.reset(seed=0)
        self.assertIsInstance(obs, np.ndarray)
        self.assertEqual(obs.shape, (16,))
        self.assertEqual(obs.dtype, np.float32)
        self.assertTrue(env.observation_space.contains(obs), obs)
        self.assertIsInstance(info, dict)
        for _ in range(20):
            action = env.action_space.sample()
            self.assertTrue(env.action_space.contains(action))
            result = env.step(action)
            self.assertEqual(len(result), 5)
            obs, reward, terminated, truncated, info = result
            self.assertEqual(obs.shape, (16,))
            self.assertEqual(obs.dtype, np.float32)
            self.assertTrue(env.observation_space.contains(obs), obs)
            self.assertIsInstance(reward, float)
            self.assertIsInstance(terminated, bool)
            self.assertIsInstance(truncated, bool)
            self.assertIsInstance(info, dict)
        self.assertEqual(info["steps"], 20)

    def test_same_seed_same_episode(self):
        a, ra = self.episode(seed=11)
        self.episode(seed=12)  # something else in between
        b, rb = self.episode(seed=11)
        np.testing.assert_array_equal(a, b)
        self.assertEqual(ra, rb)
        self.assertGreater(a[-1][0] - a[0][0], 5.0, "the car should drive forward")

    def test_different_seeds_differ(self):
        a, _ = self.episode(seed=1, steps=10)
        b, _ = self.episode(seed=2, steps=10)
        self.assertFalse(np.array_equal(a, b))

    def test_action_outside_the_space(self):
        self.env.reset(seed=0)
        with self.assertRaisesRegex(ValueError, r"steer.*0\.9.*above.*0\.55"):
            self.env.step([0.9, 5.0])
        with self.assertRaisesRegex(ValueError, r"speed.*-1.*below.*0"):
            self.env.step([0.0, -1.0])
        with self.assertRaisesRegex(ValueError, r"shape"):
            self.env.step([0.0, 1.0, 2.0])
        with self.assertRaisesRegex(ValueError, r"not a finite number"):
            self.env.step([float("nan"), 1.0])
        self.env.step([0.0, 1.0])  # still usable

    def test_leaving_the_track_terminates(self):
        obs, _ = self.env.reset(seed=0)
        for i in range(200):
            obs, reward, terminated, truncated, info = self.env.step([0.55, 8.0])
            if terminated or truncated:
                break
        self.assertTrue(terminated, "a full-lock circle should leave the track")
        self.assertFalse(truncated)
        self.assertLessEqual(reward, -10.0)
        self.assertGreater(info["off_path"], 3.0)


class LifecycleTest(unittest.TestCase):
    def test_truncated_and_context_manager(self):
        calls = []

        def reward_fn(before, after, action):
            calls.append(action)
            return 1.5

        with DrivingEnv(max_steps=5, reward_fn=reward_fn) as env:
            pids = server_processes(env)
            self.assertGreater(len(pids), 1)
            obs, _ = env.reset(seed=3)
            for i in range(5):
                obs, reward, terminated, truncated, info = env.step(policy(obs))
                self.assertEqual(reward, 1.5)
                self.assertEqual(truncated, i == 4)
                self.assertFalse(terminated)
            self.assertEqual(len(calls), 5)
        assert_gone(self, pids)
        with self.assertRaisesRegex(RuntimeError, "closed"):
            env.reset()

    def test_physics_step(self):
        with self.assertRaisesRegex(ValueError, "physics_step.*0.5"):
            DrivingEnv(physics_step=0.5)
        with DrivingEnv(physics_step=0.005, max_steps=30) as env:
            folder = env._tmp
            self.assertTrue(os.path.isdir(folder))
            ends = []
            for _ in range(2):  # the first episode (from initialize()) is like the next
                obs, _ = env.reset(seed=4)
                for _ in range(30):
                    obs, reward, terminated, truncated, info = env.step(policy(obs))
                self.assertTrue(truncated)
                self.assertTrue(env.observation_space.contains(obs))
                self.assertGreater(info["waypoint"], 2)
                ends.append(obs)
            np.testing.assert_array_equal(ends[0], ends[1])
        self.assertFalse(os.path.exists(folder))

    def test_close_and_garbage_collection(self):
        env = DrivingEnv()
        pids = server_processes(env)
        env.reset(seed=1)
        env.close()
        env.close()  # twice is fine
        assert_gone(self, pids)
        env = DrivingEnv()
        pids = server_processes(env)
        del env
        gc.collect()
        assert_gone(self, pids)
        mine = [str(p) for p in pids]
        left = subprocess.run(["pgrep", "-f", "NRPCoreSim"], capture_output=True,
                              text=True).stdout.split()
        self.assertEqual([p for p in left if p in mine], [])


if __name__ == "__main__":
    unittest.main()
