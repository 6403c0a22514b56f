"""End-to-end tests of convoy_gym's DrivingEnv on experiments/rl_parkring: the gymnasium
contract (reset / step shapes and dtypes, observations in the observation space), seeding
(same seed -> the same episode bit for bit, another seed -> another), actions outside the
space, termination and truncation, a custom reward, another physics step, the lap completed
at the default 5 ms physics step, a config with the python_json agent engine, and that close(),
a `with` block and garbage collection leave no process behind. `Vector`: VectorDrivingEnv(2)
(batch shapes, each sub-environment equal to a DrivingEnv with its seed, autoreset, a bad
action naming the env, an error in one env closing all, no process left after close();
camera and core pinning: test_gym_vector).
`Camera`: DrivingEnv(camera=(H, W)) (the Dict observation's shapes, dtypes and contains(), a
new frame every step, rendered at H x W by a camera of that size, the same frames bit for bit
for the same seed, bad camera arguments).

Run: cd tests/e2e && CONVOY_BIN_DIR=../../build/bin /usr/bin/python3 -m unittest -v test_gym"""
import gc
import json
import os
import shutil
import subprocess
import sys
import time
import unittest

import numpy as np

from e2e_util import BIN_DIR, REPO, pid_alive

os.environ.setdefault("CONVOY_BIN_DIR", BIN_DIR)
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_gym import DrivingEnv, VectorDrivingEnv  # noqa: E402


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

    def test_same_seed_same_episode_another_seed_another(self):
        # (each reset costs about a second: three episodes prove both)
        a, ra = self.episode(seed=11)
        other, _ = self.episode(seed=12)  # something else in between
        b, rb = self.episode(seed=11)
        np.testing.assert_array_equal(a, b)
        self.assertEqual(ra, rb)
        self.assertGreater(a[-1][0] - a[0][0], 5.0, "the car should drive forward")
        self.assertFalse(np.array_equal(a[:11], other[:11]), "seeds 11 and 12 start alike")

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

    def test_step_in_two_halves(self):
        # step_begin() + step_finish() is step(): the same episode, bit for bit
        a, ra = self.episode(seed=13, steps=20)
        obs, _ = self.env.reset(seed=13)
        halves, rewards = [obs], []
        for _ in range(20):
            self.env.step_begin(policy(obs))
            with self.assertRaisesRegex(RuntimeError, "step_begin\\(\\) twice"):
                self.env.step_begin(policy(obs))
            with self.assertRaisesRegex(RuntimeError, "between step_begin"):
                self.env.reset()
            obs, reward, _, _, _ = self.env.step_finish()
            halves.append(obs)
            rewards.append(reward)
        np.testing.assert_array_equal(a, np.array(halves))
        self.assertEqual(ra, rewards)
        with self.assertRaisesRegex(RuntimeError, "without step_begin"):
            self.env.step_finish()
        with self.assertRaisesRegex(ValueError, "steer"):
            self.env.step_begin([0.9, 1.0])  # checked before anything is sent
        self.env.step([0.0, 1.0])  # still usable

    def test_leaving_the_track_terminates(self):
        obs, info = self.env.reset(seed=0)
        for i in range(200):
            before = info
            obs, reward, terminated, truncated, info = self.env.step([0.55, 8.0])
            if terminated or truncated:
                break
        self.assertTrue(terminated, "a full-lock circle should leave the track")
        self.assertFalse(truncated)
        # default_reward: waypoints gained, minus 0.1 per metre off the path, minus 10
        self.assertAlmostEqual(reward, info["waypoint"] - before["waypoint"]
                               - 0.1 * info["off_path"] - 10.0, places=9)
        self.assertFalse(info["lap_done"])
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

    def test_lap_at_the_default_physics_step(self):
        # DrivingEnv's default 10 ms physics step (PHYSICS_STEP, with STEERING_PID) keeps the
        # world's lap: the
        # heading-error policy at 8 m/s completes it (about 2,640 steps, 132 s simulated)
        with DrivingEnv(max_steps=4000) as env:
            obs, info = env.reset(options={"start_steps": 1, "start_speed": 0.0,
                                           "start_steer": 0.0})
            for _ in range(4000):
                action = [float(np.clip(0.8 * obs[4], -0.55, 0.55)), 8.0]
                obs, reward, terminated, truncated, info = env.step(action)
                if terminated or truncated:
                    break
            self.assertTrue(info["lap_done"], info)
            self.assertLess(info["off_path"], 1.0)

    def test_agent_engine_config(self):
        # A config with rl_parkring's python_json "agent" engine gets the action as its
        # datapack (drive_tf turns it into the joint targets), at the world's own step
        config = os.path.join(REPO, "experiments", "rl_parkring", "simulation_config.json")
        with DrivingEnv(config=config, physics_step=None, max_steps=40) as env:
            self.assertIsNone(env._tmp)
            obs, info = env.reset(seed=5)
            start = obs
            for _ in range(40):
                obs, reward, terminated, truncated, info = env.step(policy(obs))
            self.assertTrue(truncated)
            self.assertGreater(float(np.hypot(*(obs[:2] - start[:2]))), 5.0)

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


def batch_policy(obs):
    """policy() for each row of a batch of observations."""
    return np.stack([policy(o) for o in obs])


class Vector(unittest.TestCase):
    """VectorDrivingEnv: 2 DrivingEnvs (2 servers) stepped together, 30-step episodes."""
    STEPS = 30

    @classmethod
    def setUpClass(cls):
        cls.envs = VectorDrivingEnv(2, max_steps=cls.STEPS)

    @classmethod
    def tearDownClass(cls):
        cls.envs.close()

    def episode(self, seed):
        """Resets with `seed`, runs STEPS steps (ending truncated) and one more (the
        autoreset); returns the observations, actions, rewards and the last step."""
        envs = self.envs
        obs, infos = envs.reset(seed=seed)
        trajectory, actions, rewards = [obs], [], []
        for i in range(self.STEPS):
            a = batch_policy(obs)
            obs, reward, terminated, truncated, infos = envs.step(a)
            trajectory.append(obs)
            actions.append(a)
            rewards.append(reward)
            self.assertEqual(list(terminated), [False, False])
            self.assertEqual(list(truncated), [i == self.STEPS - 1] * 2)
        after = envs.step(batch_policy(obs))  # the autoreset
        return np.array(trajectory), np.array(actions), np.array(rewards), after

    def test_spaces_and_shapes(self):
        envs = self.envs
        self.assertEqual(envs.num_envs, 2)
        self.assertEqual(envs.single_observation_space.shape, (16,))
        self.assertEqual(envs.single_action_space.shape, (2,))
        self.assertEqual(envs.observation_space.shape, (2, 16))
        self.assertEqual(envs.action_space.shape, (2, 2))
        self.assertEqual(envs.metadata["autoreset_mode"], "next_step")
        obs, infos = envs.reset(seed=0)
        self.assertEqual(obs.shape, (2, 16))
        self.assertEqual(obs.dtype, np.float32)
        self.assertTrue(envs.observation_space.contains(obs))
        self.assertEqual(list(infos["_waypoint"]), [True, True])
        self.assertEqual(infos["start"]["steps"].shape, (2,))
        obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())
        self.assertEqual(obs.shape, (2, 16))
        self.assertEqual((rewards.shape, rewards.dtype), ((2,), np.float64))
        self.assertEqual((terminated.shape, terminated.dtype), ((2,), bool))
        self.assertEqual((truncated.shape, truncated.dtype), ((2,), bool))
        self.assertEqual(list(infos["steps"]), [1, 1])

    def test_seeds_autoreset_and_single_envs(self):
        # (one episode: each sub-environment equal to a DrivingEnv with its seed, which gives the
        # same episode for the same seed (DrivingEnvTest), makes the vector env's repeatable)
        traj, actions, rewards, after = self.episode(seed=21)
        self.assertFalse(np.array_equal(traj[:, 0], traj[:, 1]), "seeds 21 and 22 differ")
        # the step after the truncation reset both envs, continuing their generators
        obs, reward, terminated, truncated, infos = after
        self.assertEqual(list(reward), [0.0, 0.0])
        self.assertEqual(list(terminated) + list(truncated), [False] * 4)
        self.assertEqual(list(infos["steps"]), [0, 0])
        self.assertEqual(list(infos["_start"]), [True, True])
        # each sub-environment is a DrivingEnv with seed 21 + i (one DrivingEnv for both: a
        # reset with a seed starts as a new one does)
        with DrivingEnv(max_steps=self.STEPS) as env:
            for i in range(2):
                o, _ = env.reset(seed=21 + i)
                single, single_rewards = [o], []
                for a in actions[:, i]:
                    o, r, terminated, truncated, _ = env.step(a)
                    single.append(o)
                    single_rewards.append(r)
                self.assertTrue(truncated)
                np.testing.assert_array_equal(np.array(single), traj[:, i])
                np.testing.assert_array_equal(single_rewards, rewards[:, i])
                o, _ = env.reset()  # the autoreset's: no seed, the generator goes on
                np.testing.assert_array_equal(o, obs[i])

    def test_bad_action_names_the_env(self):
        envs = self.envs
        envs.reset(seed=0)
        with self.assertRaisesRegex(ValueError, r"env 1: action\[0\] \(steer\) = 0\.9 is above"):
            envs.step([[0.0, 5.0], [0.9, 5.0]])
        with self.assertRaisesRegex(ValueError, r"env 0: action\[1\] \(speed\) = -1.* below"):
            envs.step([[0.0, -1.0], [0.0, 5.0]])
        with self.assertRaisesRegex(ValueError, r"shape \(2,\)"):
            envs.step([0.0, 5.0])
        obs, _, _, _, infos = envs.step([[0.0, 5.0], [0.0, 5.0]])  # nothing stepped before
        self.assertEqual(list(infos["steps"]), [1, 1])

    def test_error_in_one_env_closes_all(self):
        envs = VectorDrivingEnv(2, max_steps=10)
        pids = [p for env in envs.envs for p in server_processes(env)]
        envs.reset(seed=0)
        envs.envs[1]._nrp._server.process.kill()  # env 1's server dies
        with self.assertRaisesRegex(RuntimeError, r"^env 1: "):
            for _ in range(5):
                envs.step([[0.0, 5.0], [0.0, 5.0]])
        assert_gone(self, pids)
        with self.assertRaisesRegex(RuntimeError, "closed"):
            envs.reset()

    def test_close_leaves_no_process(self):
        with VectorDrivingEnv(2) as envs:
            pids = [p for env in envs.envs for p in server_processes(env)]
            self.assertEqual(len({env._nrp._server.process.pid for env in envs.envs}), 2)
            envs.reset(seed=5)
            envs.step([[0.0, 5.0], [0.1, 5.0]])
        assert_gone(self, pids)
        envs.close()  # twice is fine
        left = subprocess.run(["pgrep", "-f", "NRPCoreSim"], capture_output=True,
                              text=True).stdout.split()
        self.assertEqual([p for p in left if int(p) in pids], [])


if __name__ == "__main__":
    unittest.main()


class Camera(unittest.TestCase):
    """DrivingEnv(camera=(H, W)): a camera 60 x 80 (not square: rows and columns stay apart)."""
    SIZE = (60, 80)

    @classmethod
    def setUpClass(cls):
        cls.env = DrivingEnv(max_steps=200, camera=cls.SIZE)

    @classmethod
    def tearDownClass(cls):
        cls.env.close()

    def episode(self, seed, steps=25):
        obs, _ = self.env.reset(seed=seed)
        frames, states = [obs["camera"]], [obs["state"]]
        for _ in range(steps):
            obs, _, _, _, _ = self.env.step(policy(obs["state"]))
            frames.append(obs["camera"])
            states.append(obs["state"])
        return np.array(frames), np.array(states)

    def test_spaces_shapes_and_frames(self):
        env = self.env
        space = env.observation_space
        self.assertEqual(sorted(space.spaces), ["camera", "state"])
        self.assertEqual(space["state"].shape, (16,))
        self.assertEqual(space["state"].dtype, np.float32)
        self.assertEqual(space["camera"].shape, self.SIZE + (3,))
        self.assertEqual(space["camera"].dtype, np.uint8)
        self.assertEqual((int(space["camera"].low.min()), int(space["camera"].high.max())),
                         (0, 255))
        self.assertTrue(space.contains(space.sample()))
        frames, states = self.episode(seed=2, steps=10)
        self.assertEqual(frames.shape, (11,) + self.SIZE + (3,))
        self.assertEqual(frames.dtype, np.uint8)
        self.assertEqual(states.dtype, np.float32)
        obs, *_ = env.step(policy(states[-1]))
        self.assertTrue(space.contains(obs))
        self.assertFalse(space.contains({"state": obs["state"], "camera": obs["camera"].T}))
        # one frame per step: the car moves, every step's frame is a new one
        for a, b in zip(frames, frames[1:]):
            self.assertFalse(np.array_equal(a, b))
        # a picture (road, sky), not a blank: the top rows (sky) are brighter than the middle
        self.assertGreater(frames[-1].std(), 20)
        self.assertGreater(frames[-1][:10].mean(), frames[-1][30:40].mean())
        # rendered at that size: the world copy's camera is 80 x 60, one frame per 0.05 s step
        with open(os.path.join(env._tmp, "world0", "models", "smart_car", "model.sdf")) as f:
            sdf = f.read()
        self.assertIn("<width>80</width>", sdf)
        self.assertIn("<height>60</height>", sdf)
        self.assertIn("<update_rate>20.0</update_rate>", sdf)

    def test_shadow_map_sized_to_the_camera(self):
        from convoy_gym.world_variant import shadow_distance, shadow_map_size, variant_config
        sizes = [(60, 80), (84, 84), (8, 8), (480, 736), (120, 160)]
        self.assertEqual([shadow_map_size(c) for c in sizes], [128, 128, 64, 1024, 512])
        self.assertEqual([round(shadow_distance(c), 2) for c in sizes],
                         [28.57, 30.0, 20.0, 60.0, 57.14])
        # the running variant's world engine has it; shadows=False turns them off
        with open(self.env._nrp_config) as f:
            world = json.load(f)["EngineConfigs"][0]
        self.assertEqual((world["ShadowMapSize"], world["ShadowDistance"], world.get("Shadows")),
                         (128, shadow_distance(self.env.camera), None))
        path, tmp = variant_config(self.env.config, camera=(84, 84), shadows=False)
        try:
            with open(path) as f:
                world = json.load(f)["EngineConfigs"][0]
            self.assertEqual((world["ShadowMapSize"], world["Shadows"]), (128, False))
        finally:
            shutil.rmtree(tmp)

    def test_same_seed_same_frames(self):
        frames_a, states_a = self.episode(seed=5)
        frames_b, _ = self.episode(seed=6)
        frames_c, states_c = self.episode(seed=5)
        np.testing.assert_array_equal(frames_a, frames_c)
        np.testing.assert_array_equal(states_a, states_c)
        self.assertFalse(np.array_equal(frames_a, frames_b))

    def test_bad_camera_arguments(self):
        for bad in [(0, 84), (84,), "84x84", (84, 84, 3), (5000, 84)]:
            with self.assertRaisesRegex(ValueError, "camera"):
                DrivingEnv(camera=bad)
        with self.assertRaisesRegex(ValueError, r"VectorDrivingEnv: camera .*\(84,\)"):
            VectorDrivingEnv(2, camera=(84,))  # (camera batches: test_gym_vector)
