"""End-to-end tests of VectorDrivingEnv's camera observations and core pinning (the rest of
VectorDrivingEnv: test_gym.Vector). `VectorCamera`: VectorDrivingEnv(2, camera=(H, W)) (the
batched Dict space and observations, each sub-environment's states and frames equal to a
DrivingEnv(camera=...)'s with seed s + i bit for bit, the next_step, same_step (final_obs per
environment) and disabled autoresets, 2 llvmpipe threads on a pinned core). `Pinning`:
cpu_affinity ("auto": environment i's server and every engine process on core i,
round-robin; an explicit list; None; this process left as it was) read from /proc/PID/status,
and bad camera / cpu_affinity values.

Run: cd tests/e2e && CONVOY_BIN_DIR=../../build/bin /usr/bin/python3 -m unittest -v \
    test_gym_vector"""
import os
import sys
import unittest

import numpy as np

from e2e_util import BIN_DIR, REPO

os.environ.setdefault("CONVOY_BIN_DIR", BIN_DIR)
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_gym import DrivingEnv, VectorDrivingEnv  # noqa: E402
from convoy_gym.affinity import core_sets  # noqa: E402
from test_gym import assert_gone, policy, server_processes  # noqa: E402

ALLOWED = sorted(os.sched_getaffinity(0))
LP_NUM_THREADS = os.environ.get("LP_NUM_THREADS")


def batch_policy(states):
    return np.stack([policy(s) for s in states])


def cpus_allowed(pid):
    """The set of cores in /proc/PID/status's Cpus_allowed_list (e.g. "0-1,3")."""
    with open("/proc/%d/status" % pid) as f:
        text = f.read().split("Cpus_allowed_list:")[1].split()[0]
    cores = set()
    for part in text.split(","):
        low, _, high = part.partition("-")
        cores.update(range(int(low), int(high or low) + 1))
    return cores


class VectorCamera(unittest.TestCase):
    """VectorDrivingEnv(2, camera=(60, 80)), 10-step episodes (not square: rows stay rows)."""
    SIZE = (60, 80)
    STEPS = 10

    @classmethod
    def setUpClass(cls):
        cls.envs = VectorDrivingEnv(2, camera=cls.SIZE, max_steps=cls.STEPS)

    @classmethod
    def tearDownClass(cls):
        cls.envs.close()

    def episode(self, envs, seed):
        """STEPS steps from reset(seed) (the last truncated) and one more; returns the
        observations (states, frames), actions and the last step's result."""
        obs, _ = envs.reset(seed=seed)
        states, frames, actions = [obs["state"]], [obs["camera"]], []
        for i in range(self.STEPS):
            actions.append(batch_policy(obs["state"]))
            obs, _, terminated, truncated, infos = envs.step(actions[-1])
            self.assertEqual(list(terminated) + list(truncated),
                             [False, False] + [i == self.STEPS - 1] * 2)
            states.append(obs["state"])
            frames.append(obs["camera"])
        last = envs.step(batch_policy(obs["state"]))
        return np.array(states), np.array(frames), np.array(actions), last

    def test_spaces_and_shapes(self):
        envs = self.envs
        space, single = envs.observation_space, envs.single_observation_space
        self.assertEqual(sorted(space.spaces), ["camera", "state"])
        self.assertEqual((space["state"].shape, space["state"].dtype), ((2, 16), np.float32))
        self.assertEqual((space["camera"].shape, space["camera"].dtype),
                         ((2,) + self.SIZE + (3,), np.uint8))
        self.assertEqual(single["camera"].shape, self.SIZE + (3,))
        self.assertEqual(single["state"].shape, (16,))
        obs, _ = envs.reset(seed=0)
        self.assertEqual(obs["camera"].shape, (2,) + self.SIZE + (3,))
        self.assertEqual(obs["camera"].dtype, np.uint8)
        self.assertTrue(space.contains(obs))
        self.assertTrue(single.contains({k: v[1] for k, v in obs.items()}))
        before = obs["camera"].copy()
        obs, *_ = envs.step(batch_policy(obs["state"]))
        self.assertTrue(space.contains(obs))
        for i in range(2):  # a new frame each step, and a picture, not a blank
            self.assertFalse(np.array_equal(before[i], obs["camera"][i]))
            self.assertGreater(obs["camera"][i].std(), 20)
        # the servers and engines are pinned ("auto" with 2 envs), rendering with 2 llvmpipe
        # threads (LP_NUM_THREADS; this process' environment is left as it was)
        for i, env in enumerate(envs.envs):
            for pid in server_processes(env):
                self.assertEqual(cpus_allowed(pid), {ALLOWED[i % len(ALLOWED)]})
                with open("/proc/%d/environ" % pid, "rb") as f:
                    self.assertIn(b"LP_NUM_THREADS=" + os.environ.get(
                        "LP_NUM_THREADS", "2").encode(), f.read().split(b"\0"))
        self.assertEqual(os.environ.get("LP_NUM_THREADS"), LP_NUM_THREADS)

    def test_seeds_and_autoresets_equal_single_envs(self):
        states, frames, actions, last = self.episode(self.envs, seed=31)
        self.assertFalse(np.array_equal(frames[:, 0], frames[:, 1]), "seeds 31 and 32 differ")
        obs, reward, terminated, truncated, infos = last  # next_step: the autoreset
        self.assertEqual(list(reward) + list(terminated) + list(truncated), [0] * 6)
        self.assertEqual(list(infos["steps"]), [0, 0])
        # each sub-environment is a DrivingEnv(camera=...) with seed 31 + i, frames bit for bit
        with DrivingEnv(camera=self.SIZE, max_steps=self.STEPS) as env:
            for i in range(2):
                o, _ = env.reset(seed=31 + i)
                single_states, single_frames = [o["state"]], [o["camera"]]
                for a in actions[:, i]:
                    o, *_ = env.step(a)
                    single_states.append(o["state"])
                    single_frames.append(o["camera"])
                np.testing.assert_array_equal(np.array(single_states), states[:, i])
                np.testing.assert_array_equal(np.array(single_frames), frames[:, i])
                o, _ = env.reset()  # the autoreset's: the generator goes on
                np.testing.assert_array_equal(o["state"], obs["state"][i])
                np.testing.assert_array_equal(o["camera"], obs["camera"][i])
        # same_step: the same episode; the step that ends it returns the reset's observation,
        # the last one per environment in final_obs
        with VectorDrivingEnv(2, camera=self.SIZE, max_steps=self.STEPS,
                              autoreset_mode="same_step") as same:
            o, _ = same.reset(seed=31)
            for a in actions[:-1]:
                o, *_ = same.step(a)
            o, reward, terminated, truncated, infos = same.step(actions[-1])
            self.assertEqual(list(truncated), [True, True])
            self.assertEqual(list(infos["_final_obs"]), [True, True])
            for i in range(2):
                final = infos["final_obs"][i]
                np.testing.assert_array_equal(final["state"], states[-1, i])
                np.testing.assert_array_equal(final["camera"], frames[-1, i])
                np.testing.assert_array_equal(o["camera"][i], obs["camera"][i])
            self.assertEqual(list(infos["final_info"]["steps"]), [self.STEPS] * 2)
            self.assertEqual(list(infos["steps"]), [0, 0])

    def test_disabled_autoreset_and_reset_mask(self):
        with VectorDrivingEnv(2, camera=self.SIZE, max_steps=3,
                              autoreset_mode="disabled") as envs:
            obs, _ = envs.reset(seed=4)
            for _ in range(3):
                obs, _, _, truncated, _ = envs.step(batch_policy(obs["state"]))
            self.assertEqual(list(truncated), [True, True])
            again, infos = envs.reset(options={"reset_mask": [False, True]})
            self.assertEqual(list(infos["_steps"]), [False, True])
            np.testing.assert_array_equal(again["camera"][0], obs["camera"][0])
            np.testing.assert_array_equal(again["state"][0], obs["state"][0])
            self.assertFalse(np.array_equal(again["camera"][1], obs["camera"][1]))


class Pinning(unittest.TestCase):
    """cpu_affinity: each environment's processes on their cores, read from /proc."""

    def assert_tree_on(self, env, cores):
        pids = server_processes(env)
        self.assertGreaterEqual(len(pids), 2, "the server and its world engine")
        for pid in pids:
            self.assertEqual(cpus_allowed(pid), set(cores), "process %d" % pid)

    def test_auto_pins_each_env_to_its_core(self):
        before = os.sched_getaffinity(0)
        with VectorDrivingEnv(2) as envs:
            self.assertEqual(envs.cpu_sets, [{ALLOWED[0]}, {ALLOWED[1 % len(ALLOWED)]}])
            for i, env in enumerate(envs.envs):
                self.assert_tree_on(env, {ALLOWED[i % len(ALLOWED)]})
            # this process and the threads that started the servers are not pinned
            self.assertEqual(os.sched_getaffinity(0), before)
            threads = envs._pool.submit(os.sched_getaffinity, 0).result()
            self.assertEqual(threads, before)
            envs.reset(seed=1)
            envs.step([[0.0, 5.0], [0.0, 5.0]])
            pids = [p for env in envs.envs for p in server_processes(env)]
        assert_gone(self, pids)

    def test_explicit_sets_and_none(self):
        last = ALLOWED[-1]
        with VectorDrivingEnv(2, cpu_affinity=[[last], None]) as envs:
            self.assert_tree_on(envs.envs[0], {last})
            self.assert_tree_on(envs.envs[1], set(ALLOWED))
        with VectorDrivingEnv(1) as envs:  # "auto" with one environment: not pinned
            self.assertEqual(envs.cpu_sets, [None])
            self.assert_tree_on(envs.envs[0], set(ALLOWED))

    def test_core_sets(self):
        self.assertEqual(core_sets("auto", 3, allowed={0, 1}), [{0}, {1}, {0}])
        self.assertEqual(core_sets("auto", 2, allowed={2, 5}), [{2}, {5}])
        self.assertEqual(core_sets("auto", 1, allowed={0, 1}), [None])
        self.assertEqual(core_sets(True, 1, allowed={0, 1}), [{0}])
        self.assertEqual(core_sets(None, 2), [None, None])
        self.assertEqual(core_sets(False, 2), [None, None])
        self.assertEqual(core_sets([0, {0, 1}], 2, allowed={0, 1}), [{0}, {0, 1}])

    def test_bad_values(self):
        bad = [("fast", r"'fast'"), (2, r"got 2"), ([0], r"1 core sets for 2 envs"),
               ([[0], [99]], r"\[1\]: core\(s\) 99 not among"),
               ([[], None], r"\[0\]: \[\] is not"),
               ([["a"], None], r"\[0\]: \['a'\] is not"),
               ([True, None], r"\[0\]: True is not")]
        for value, message in bad:
            with self.assertRaisesRegex(ValueError, "^VectorDrivingEnv: cpu_affinity.*" + message):
                VectorDrivingEnv(2, cpu_affinity=value)
        for camera in [(84,), (0, 84), "84x84", (84, 84, 3)]:
            with self.assertRaisesRegex(ValueError, r"^VectorDrivingEnv: camera .*%s"
                                        % repr(camera).replace("(", r"\(").replace(")", r"\)")):
                VectorDrivingEnv(2, camera=camera)


if __name__ == "__main__":
    unittest.main()
