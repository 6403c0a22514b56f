"""ScenarioDrivingEnv: one OpenSCENARIO run as a gymnasium episode, the ego driven by the client.

    from convoy_gym import ScenarioDrivingEnv

    with ScenarioDrivingEnv("benchmarks/suite/cut_in.xosc", action="target_speed_lane") as env:
        obs, info = env.reset(seed=1)
        while True:
            obs, reward, terminated, truncated, info = env.step([8.0, 0.0])
            if terminated or truncated:
                break
        info["driving_score"]

The scenario runs as `convoy run --scenario` runs it (the scenario engine, its storyboard, the
other road users' engines, traffic lights), but the ego is a kinematic vehicle_agent commanded
by the client each step and there is no world engine (scenario_config.py). One step() is one
run_loop(1): 0.05 s. Rewards come from the live metrics (convoy_bench.live.LiveScore: route
progress, infractions) and comfort (scenario_core.default_reward). See docs/gym.md.
"""
import numpy as np

from convoy_bench import road_map
from convoy_gym.closing import ClosesOnExit
from convoy_gym.scenario_core import (DT, Learner, ScenarioSim, check_action, default_reward,
                                      observation_space, start_pose)

__all__ = ["ScenarioDrivingEnv", "default_reward"]


class ScenarioDrivingEnv(ClosesOnExit):
    """The gymnasium API over one scenario, its ego driven by the agent's actions.

    Observation: Dict of the parts chosen (`observation`):
      "ego": Box float32 (7,) = x, y (m), yaw (rad), speed (m/s), acceleration (m/s^2),
             yaw rate (rad/s), distance from the route (m);
      "road_users": Box float32 (8, 8): the nearest road users within `radius` m, nearest
             first, rows [present 1/0, forward, left (m, the ego's frame), relative yaw,
             speed, length, width, pedestrian 1/0], zeros below;
      "route": Box float32 (5, 2): the route 5, 10, 20, 40, 80 m past the ego's progress as
             [forward, left] m in its frame.
    Action "controls": Box (3,) = [throttle 0-1, brake 0-1, steer -0.6..0.6 rad] (a kinematic
    bicycle: 3 m/s^2 at full throttle, 8 at full brake); "target_speed_lane": Box (2,) =
    [target speed 0-20 m/s, lane change -1..1: rounded, -1 right, +1 left, 0 keep].
    """

    metadata = {"render_modes": []}
    render_mode = None

    def __init__(self, scenario, observation=("ego", "road_users", "route"), action="controls",
                 reward_fn=None, radius=50.0, max_steps=None, parameters=None, start_offset=2.0,
                 start_speed=None, args="", log_output=""):
        """:param scenario: the .xosc (on an OpenDRIVE map)
        :param observation: the parts of the observation, from "ego", "road_users", "route"
        :param action: "controls" or "target_speed_lane"
        :param reward_fn: reward_fn(before, after, action) -> float over the ego's metrics dicts
            (progress, new_infractions, discomfort, ...); default_reward if None
        :param radius: m, road users farther away are not observed
        :param max_steps: steps before `truncated` (default: the scenario's time limit / 0.05 s)
        :param parameters: the scenario's parameters {name: value}
        :param start_offset, start_speed: reset(seed) moves the ego's start up to start_offset m
            along its heading and starts it at a speed in [0, start_speed] m/s (None: its Init
            speed), both drawn from the seed
        :param args, log_output: as DrivingEnv's (NRPCoreSim options; its output file)"""
        self.sim = None
        self.scenario = scenario
        self.parts = tuple([observation] if isinstance(observation, str) else observation)
        self.observation_space = observation_space(self.parts)
        self.reward_fn = reward_fn or default_reward
        self.radius = float(radius)
        self.start = (float(start_offset), start_speed)
        self.sim = ScenarioSim(scenario, None, parameters, None, args, log_output)
        info = self.sim.info
        self.ego = info["ego"]
        spec = info["learning"][self.ego]
        self.map = road_map.load(info["map"])
        self.learner = Learner(self.ego, spec, action, spec["route"], info["map"], self.map,
                               self.sim.stop_lines)
        self.action_space = self.learner.action_space
        self.max_steps = int(max_steps) if max_steps else int(round(info["timeout"] / DT))
        if self.max_steps <= 0:
            raise ValueError("ScenarioDrivingEnv: max_steps must be > 0, got %r" % (max_steps,))
        self.np_random = np.random.Generator(np.random.PCG64())
        self._steps = 0
        self._over = True

    def reset(self, seed=None, options=None):
        """Starts an episode: the scenario from its start, the ego at a start drawn from the
        seed (start_offset, start_speed; `options` may give "start_offset" / "start_speed").
        Returns (observation, info)."""
        self._check_open()
        if seed is not None:
            self.np_random = np.random.Generator(np.random.PCG64(seed))
        options = dict(options or {})
        unknown = set(options) - {"start_offset", "start_speed"}
        if unknown:
            raise ValueError("reset(): unknown options %s" % sorted(unknown))
        offset = float(options.get("start_offset", self.start[0]))
        speed = options.get("start_speed", self.start[1])
        pose = start_pose(self.learner.spec, self.np_random, offset, speed)
        self.sim.reset()
        self.learner.start(pose)
        self._run(None)   # the teleport
        self._run(None)   # a neutral step: the observation shows the start
        self._steps = 0
        self._over = False
        info = self._info()
        info["start"] = pose
        return self._observation(), info

    def step(self, action):
        """One step (0.05 s). terminated: the ego collided, its route ended or the scenario is
        done; truncated: max_steps steps. info["driving_score"] etc. at the episode's end."""
        self._check_open()
        if self._over:
            raise RuntimeError("ScenarioDrivingEnv.step() before reset() (or after the episode's end)")
        a = check_action(action, self.action_space, self.learner.names)
        before = dict(self.learner.metrics)
        self._run(a)
        self._steps += 1
        after = self.learner.metrics
        reward = float(self.reward_fn(before, after, a))
        sc = self.sim.raw["scenario"]
        terminated = bool(after.get("collided") or after.get("absent") or sc["done"])
        truncated = not terminated and self._steps >= self.max_steps
        info = self._info()
        if terminated or truncated:
            self._over = True
            info.update(self._final(timed_out=not (sc["done"] or after.get("collided"))))
        return self._observation(), reward, terminated, truncated, info

    def close(self):
        sim, self.sim = getattr(self, "sim", None), None
        if sim is not None:
            sim.close()

    def render(self):
        return None

    @property
    def unwrapped(self):
        return self

    # --- the rest ---------------------------------------------------------------------------
    def _check_open(self):
        if self.sim is None:
            raise RuntimeError("ScenarioDrivingEnv is closed; make a new one")

    def _run(self, a):
        lr = self.learner
        raw, collisions = self.sim.step({lr.engine: lr.command(a)})
        if lr.engine not in raw["users"]:
            raise RuntimeError("scenario episode: no state of the ego's agent %s" % lr.engine)
        lr.observe(raw["t"], raw["users"], collisions, raw.get("signals"))

    def _observation(self):
        return self.learner.observation(self.parts, self.sim.raw["users"], self.radius)

    def _info(self):
        m = self.learner.metrics
        sc = self.sim.raw["scenario"]
        return {"t": self.sim.raw["t"], "steps": self._steps, "progress": m["progress"],
                "route_length": float(self.learner.cum[-1]), "collided": m.get("collided", False),
                "infractions": [dict(i) for i in m["new_infractions"]],
                "scenario_done": sc["done"], "scenario_reason": sc.get("reason")}

    def _final(self, timed_out):
        """The live score of the episode (CARLA's driving score, nuPlan's): as a scenario run's
        summary.json says it."""
        r = self.learner.live.result(final=True, timed_out=timed_out)
        if r is None:
            return {}
        return {"driving_score": r["driving_score"], "route_completion": r["route_completion"],
                "infraction_penalty": r["infraction_penalty"],
                "nuplan_score": r["nuplan_score"]["score"],
                "all_infractions": [{k: v for k, v in i.items() if not k.startswith("_")}
                                    for i in r["infractions"]]}
