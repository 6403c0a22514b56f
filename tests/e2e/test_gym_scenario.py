"""convoy_gym's scenario environments (docs/gym.md, "Scenario episodes", "Multi-agent"):
ScenarioDrivingEnv and MultiAgentDrivingEnv on the suite's scenarios, end to end through
NRPCoreSim, the scenario engine and the agents.

ScenarioEnv: the gymnasium contract (observations in their spaces with their dtypes, reset and
step tuples), the same seed gives the same episode bit for bit (another seed's in between),
another seed another, truncated at max_steps, the scenario's end terminates with the live
driving score, a lane change, a bad action's message. Infractions: terminated on a collision
(full throttle into the braking lead car), a red light run (its reward and the final score),
bad input, close() leaves no process. MultiAgent: the ParallelEnv contract (dict keys, agents removed when done,
reward dicts), and that the learning agents' actions move their road users (a vehicle steered
two ways ends in two places; a walker walks at the commanded speed, and stands when told).

Run: cd tests/e2e && CONVOY_BIN_DIR=../../build/bin /usr/bin/python3 -m unittest -v test_gym_scenario"""
import math
import os
import sys
import unittest

import numpy as np

from e2e_util import REPO

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_gym import MultiAgentDrivingEnv, ScenarioDrivingEnv  # noqa: E402
from test_gym import assert_gone, descendants  # noqa: E402

SUITE = os.path.join(REPO, "benchmarks", "suite")


def run_episode(env, seed, actions):
    obs, info = env.reset(seed=seed)
    out = [(obs, 0.0, info["start"])]
    for a in actions:
        obs, r, terminated, truncated, info = env.step(a)
        out.append((obs, r, terminated, truncated))
        if terminated or truncated:
            break
    return out


def same(a, b):
    """Bit for bit: observations (dicts of arrays), rewards, flags."""
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        for k in x[0]:
            if x[0][k].tobytes() != y[0][k].tobytes():
                return False
        if x[1:] != y[1:]:
            return False
    return True


class ScenarioEnv(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = ScenarioDrivingEnv(os.path.join(SUITE, "cut_in.xosc"), action="target_speed_lane",
                                     start_speed=4.0)

    @classmethod
    def tearDownClass(cls):
        cls.env.close()

    def test_driving_env_with_a_scenario_is_a_scenario_env(self):
        from convoy_gym import DrivingEnv
        with DrivingEnv(scenario=os.path.join(SUITE, "cut_in.xosc")) as env:
            self.assertIsInstance(env, ScenarioDrivingEnv)
            obs, _ = env.reset(seed=1)
            self.assertTrue(env.observation_space.contains(obs))

    def test_spaces_and_tuples(self):
        env = self.env
        obs, info = env.reset(seed=3)
        self.assertEqual(set(obs), {"ego", "road_users", "route"})
        self.assertTrue(env.observation_space.contains(obs))
        self.assertEqual(obs["road_users"].shape, (8, 8))
        self.assertEqual(obs["road_users"].dtype, np.float32)
        self.assertEqual(env.action_space.shape, (2,))
        for _ in range(30):
            out = env.step([env.action_space.sample()[0], 0.0])
            self.assertEqual(len(out), 5)
            obs, reward, terminated, truncated, info = out
            self.assertTrue(env.observation_space.contains(obs), obs)
            self.assertIsInstance(reward, float)
            self.assertIsInstance(terminated, bool)
            self.assertIsInstance(truncated, bool)
        # the cutter is seen, in the ego's frame
        self.assertEqual(obs["road_users"][0][0], 1.0)
        self.assertGreater(info["t"], 1.0)

    def test_seeds(self):
        rng = np.random.default_rng(5)
        actions = [[float(v), 0.0] for v in rng.uniform(0.0, 12.0, 60)]
        a = run_episode(self.env, 11, actions)
        b = run_episode(self.env, 12, actions)
        c = run_episode(self.env, 11, actions)
        self.assertTrue(same(a, c), "the same seed gave another episode")
        self.assertFalse(same(a, b), "two seeds gave the same episode")
        self.assertNotEqual(a[0][2], b[0][2])

    def test_route_end_terminates_with_the_live_score(self):
        self.env.reset(seed=0, options={"start_offset": 0.0, "start_speed": 0.0})
        total, steps = 0.0, 0
        while True:
            obs, r, terminated, truncated, info = self.env.step([9.0, 0.0])
            total += r
            steps += 1
            if terminated or truncated:
                break
        self.assertTrue(terminated)
        self.assertTrue(info["scenario_done"])
        self.assertEqual(info["scenario_reason"], "route_end")
        self.assertAlmostEqual(info["route_completion"], 100.0)
        self.assertGreater(info["driving_score"], 50.0)
        # the default reward: about the route's length (150 m) driven, no infractions
        self.assertGreater(total, 140.0)
        self.assertLess(total, 151.0)
        with self.assertRaises(RuntimeError):
            self.env.step([9.0, 0.0])

    def test_lane_change_moves_the_ego(self):
        obs, _ = self.env.reset(seed=0, options={"start_offset": 0.0, "start_speed": 0.0})
        y0 = float(obs["ego"][1])
        for _ in range(20):   # left of lane -1: the other direction's lane, no change
            obs, r, terminated, truncated, info = self.env.step([5.0, 1.0])
        self.assertEqual(float(obs["ego"][1]), y0)
        for _ in range(80):   # 4 s: one 3 s lane change to the right, lane -1 to lane -2
            obs, r, terminated, truncated, info = self.env.step([5.0, -1.0])
        self.assertAlmostEqual(float(obs["ego"][1]) - y0, -3.5, delta=0.05)

    def test_truncated(self):
        env = self.env
        keep, env.max_steps = env.max_steps, 15
        try:
            out = run_episode(env, 1, [[3.0, 0.0]] * 30)
        finally:
            env.max_steps = keep
        self.assertEqual(len(out), 16)
        self.assertEqual(out[-1][2:], (False, True))

    def test_bad_action(self):
        self.env.reset(seed=0)
        with self.assertRaises(ValueError) as e:
            self.env.step([25.0, 0.0])
        self.assertEqual(str(e.exception),
                         "action[0] (target_speed) = 25.0 is above the action space's bound 20")
        with self.assertRaises(ValueError) as e:
            self.env.step([5.0])
        self.assertIn("shape (1,)", str(e.exception))
        obs, *_ = self.env.step([5.0, 0.0])   # still usable
        self.assertTrue(self.env.observation_space.contains(obs))


class Infractions(unittest.TestCase):
    def test_full_throttle_into_the_lead_terminates(self):
        with ScenarioDrivingEnv(os.path.join(SUITE, "lead_brake.xosc"), observation=("ego", "road_users")) as env:
            self.assertEqual(env.action_space.shape, (3,))
            env.reset(seed=0)
            with self.assertRaises(ValueError) as e:
                env.step([0.5, 0.0, 0.7])
            self.assertEqual(str(e.exception), "action[2] (steer) = 0.7 is above the action space's bound 0.6")
            for n in range(1000):
                obs, r, terminated, truncated, info = env.step([1.0, 0.0, 0.0])
                if terminated or truncated:
                    break
            self.assertTrue(terminated)
            self.assertTrue(info["collided"])
            self.assertEqual([i["kind"] for i in info["infractions"]], ["collision_vehicle"])
            self.assertLess(r, -15.0)    # -50 x (1 - 0.6), plus the step's progress (1 m)
            self.assertLess(info["infraction_penalty"], 0.61)
            self.assertFalse(info["scenario_done"])


    def test_red_light(self):
        # the ego drives on through junction 100's red: CARLA's red-light infraction, -15
        with ScenarioDrivingEnv(os.path.join(SUITE, "red_light.xosc"), action="target_speed_lane",
                                observation="ego") as env:
            env.reset(seed=0)
            found = []
            while True:
                obs, r, terminated, truncated, info = env.step([8.0, 0.0])
                if info["infractions"]:
                    found.append((r, info["infractions"]))
                if terminated or truncated:
                    break
            self.assertEqual(len(found), 1)
            self.assertEqual([(i["kind"], i["other"]) for i in found[0][1]], [("red_light", "1")])
            self.assertLess(found[0][0], -14.0)
            self.assertEqual(info["scenario_reason"], "route_end")
            self.assertAlmostEqual(info["infraction_penalty"], 0.7)

    def test_bad_input_and_close(self):
        xosc = os.path.join(SUITE, "jaywalker.xosc")
        with self.assertRaises(ValueError) as e:
            ScenarioDrivingEnv(xosc, observation=("ego", "camera"))
        self.assertIn("observation 'camera': scenario episodes run without the world engine", str(e.exception))
        with self.assertRaises(ValueError) as e:
            MultiAgentDrivingEnv(xosc, agents=["Ego", "Nobody"])
        self.assertEqual(str(e.exception), "jaywalker.xosc: no entity 'Nobody' to learn (entities: Ego, Walker)")
        env = ScenarioDrivingEnv(xosc)
        pids = descendants(env.sim.nrp._server.process.pid)
        self.assertGreater(len(pids), 3)      # the server and its engines
        env.close()
        assert_gone(self, pids)
        with self.assertRaises(RuntimeError):
            env.reset()


class MultiAgent(unittest.TestCase):
    def test_parallel_env_contract_and_removal(self):
        with MultiAgentDrivingEnv(os.path.join(SUITE, "cut_in.xosc"), agents=["Ego", "Cutter"],
                                  action="target_speed_lane") as env:
            self.assertEqual(env.possible_agents, ["Ego", "Cutter"])
            obs, infos = env.reset(seed=0)
            self.assertEqual(set(obs), {"Ego", "Cutter"})
            self.assertEqual(set(infos), {"Ego", "Cutter"})
            self.assertEqual(env.agents, ["Ego", "Cutter"])
            for a in env.agents:
                self.assertTrue(env.observation_space(a).contains(obs[a]))
            with self.assertRaises(ValueError) as e:
                env.step({"Ego": [5.0, 0.0]})
            self.assertIn("no action for agent(s) ['Cutter']", str(e.exception))
            with self.assertRaises(ValueError) as e:
                env.step({"Ego": [5.0, 0.0], "Cutter": [5.0, 3.0]})
            self.assertIn("agent 'Cutter': action[1] (lane_change) = 3.0 is above", str(e.exception))
            # the cutter changes lane into the ego, beside it: both collide and leave
            for n in range(200):
                actions = {a: ([8.0, 0.0] if a == "Ego" else [8.0, 1.0]) for a in env.agents}
                obs, rewards, terms, truncs, infos = env.step(actions)
                for d in (obs, rewards, terms, truncs, infos):
                    self.assertEqual(set(d), set(actions))
                self.assertTrue(all(isinstance(r, float) for r in rewards.values()))
                if any(terms.values()):
                    break
            self.assertEqual(terms, {"Ego": True, "Cutter": True})
            self.assertTrue(infos["Ego"]["collided"])
            self.assertEqual(env.agents, [])
            self.assertLess(rewards["Cutter"], -15.0)

    def test_actions_move_the_road_users(self):
        """A vehicle steered left and right ends in two places, as the bicycle model says; a
        walker walks at its action's speed and stands at 0."""
        with MultiAgentDrivingEnv(os.path.join(SUITE, "jaywalker.xosc"), agents=["Ego", "Walker"],
                                  observation=("ego",), start_offset=0.0) as env:
            ends = []
            for steer in (0.2, -0.2):
                obs, _ = env.reset(seed=0)
                x0, y0, yaw0 = (float(v) for v in obs["Ego"]["ego"][:3])
                w0 = obs["Walker"]["ego"][:3].astype(float)
                for _ in range(40):
                    obs, *_ = env.step({"Ego": [0.5, 0.0, steer], "Walker": [1.5, 0.0]})
                e = obs["Ego"]["ego"]
                ends.append((float(e[0]), float(e[1]), float(e[2])))
                # the kinematic bicycle (wheelbase 0.6 x 2.7 m, 3 m/s^2 x throttle), 39 steps:
                # the states returned are those at the start of the step just run
                v = yaw = 0.0
                for _ in range(39):
                    v += 1.5 * 0.05
                    yaw += v / (0.6 * 2.7) * math.tan(steer) * 0.05
                self.assertAlmostEqual(float(e[2]) - yaw0, yaw, delta=1e-4)
                self.assertAlmostEqual(float(e[3]), v, delta=1e-4)
                w = obs["Walker"]["ego"][:3].astype(float)
                walked = math.hypot(w[0] - w0[0], w[1] - w0[1])
                self.assertAlmostEqual(walked, 1.5 * 40 * 0.05, delta=0.2)
                for _ in range(10):
                    obs, *_ = env.step({"Ego": [0.0, 1.0, 0.0], "Walker": [0.0, 0.0]})
                w1 = obs["Walker"]["ego"][:3].astype(float)
                obs, *_ = env.step({"Ego": [0.0, 1.0, 0.0], "Walker": [0.0, 0.0]})
                self.assertEqual(obs["Walker"]["ego"][:2].tolist(), w1[:2].astype(np.float32).tolist())
            self.assertGreater(abs(ends[0][1] - ends[1][1]), 1.0)


if __name__ == "__main__":
    unittest.main()
