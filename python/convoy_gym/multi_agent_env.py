"""MultiAgentDrivingEnv: chosen road users of a scenario as learning agents, in PettingZoo's
ParallelEnv shape, beside the reactive ones.

    from convoy_gym import MultiAgentDrivingEnv

    with MultiAgentDrivingEnv("benchmarks/suite/cut_in.xosc", agents=["Ego", "Cutter"]) as env:
        obs, infos = env.reset(seed=0)
        while env.agents:
            actions = {a: env.action_space(a).sample() for a in env.agents}
            obs, rewards, terminations, truncations, infos = env.step(actions)

Each learning agent is a vehicle_agent (a Vehicle) or a pedestrian_agent (a Pedestrian) that
the scenario never commands (scenario_config.py): the client sends its `command` every step,
from the agent's action (scenario_core.Learner: a timed trajectory of a kinematic bicycle /
walker for "controls", speed and lane commands for "target_speed_lane"). The other entities
stay reactive: the scenario's player or their own agents' AI. No PettingZoo import: the class
has the ParallelEnv attributes and methods (pettingzoo.utils.conversions and its API test work
on it when PettingZoo is installed). See docs/gym.md.
"""
import numpy as np

from convoy_bench import road_map
from convoy_gym.closing import ClosesOnExit
from convoy_gym.scenario_core import (DT, Learner, ScenarioSim, check_action, default_reward,
                                      observation_space, pedestrian_route, start_pose)

__all__ = ["MultiAgentDrivingEnv"]


class MultiAgentDrivingEnv(ClosesOnExit):
    """PettingZoo's ParallelEnv API over one scenario: possible_agents, agents,
    observation_space(agent), action_space(agent), reset(seed, options) -> (obs, infos),
    step(actions) -> (obs, rewards, terminations, truncations, infos), all dicts keyed by agent
    (the entity's name in the .xosc). An agent is removed from `agents` after the step that
    terminated (collision, its route ended, the scenario is done) or truncated it (max_steps).
    Observations and actions as ScenarioDrivingEnv's, per agent; a pedestrian's action:
    "controls" [speed 0-3 m/s, turn rate -1.5..1.5 rad/s], "target_speed_lane" [speed 0-3]."""

    metadata = {"render_modes": [], "name": "convoy_multi_agent_v0", "is_parallelizable": True}
    render_mode = None

    def __init__(self, scenario, agents=None, observation=("ego", "road_users", "route"), action="controls",
                 reward_fn=None, radius=50.0, max_steps=None, parameters=None, start_offset=2.0,
                 start_speed=None, args="", log_output=""):
        """agents: the entities that learn (the ego always among them; default: the ego alone).
        The other parameters as ScenarioDrivingEnv's; `action` one kind for every agent, or a
        dict {agent: kind}. reward_fn(agent, before, after, action) -> float."""
        self.sim = None
        self.parts = tuple([observation] if isinstance(observation, str) else observation)
        self._obs_space = observation_space(self.parts)
        self.reward_fn = reward_fn or (lambda agent, before, after, action: default_reward(before, after, action))
        self.radius = float(radius)
        self.start = (float(start_offset), start_speed)
        self.sim = ScenarioSim(scenario, agents, parameters, None, args, log_output)
        info = self.sim.info
        self.map = road_map.load(info["map"])
        self.possible_agents = list(info["learning"])
        self.learners = {}
        for name, spec in info["learning"].items():
            kind = action.get(name, "controls") if isinstance(action, dict) else action
            route = spec["route"] or pedestrian_route(spec)
            self.learners[name] = Learner(name, spec, kind, route, info["map"], self.map,
                                          self.sim.stop_lines)
        self.max_steps = int(max_steps) if max_steps else int(round(info["timeout"] / DT))
        self.agents = []
        self.np_random = np.random.Generator(np.random.PCG64())
        self._steps = 0

    def observation_space(self, agent):
        self._known(agent)
        return self._obs_space

    def action_space(self, agent):
        return self._known(agent).action_space

    @property
    def observation_spaces(self):
        return {a: self._obs_space for a in self.possible_agents}

    @property
    def action_spaces(self):
        return {a: self.learners[a].action_space for a in self.possible_agents}

    @property
    def num_agents(self):
        return len(self.agents)

    @property
    def max_num_agents(self):
        return len(self.possible_agents)

    def reset(self, seed=None, options=None):
        """Every agent back, at starts drawn from the seed (each moved up to start_offset m
        along its Init heading, in possible_agents order). Returns (obs, infos)."""
        self._check_open()
        if seed is not None:
            self.np_random = np.random.Generator(np.random.PCG64(seed))
        options = dict(options or {})
        unknown = set(options) - {"start_offset", "start_speed"}
        if unknown:
            raise ValueError("reset(): unknown options %s" % sorted(unknown))
        offset = float(options.get("start_offset", self.start[0]))
        speed = options.get("start_speed", self.start[1])
        self.sim.reset()
        starts = {}
        for name in self.possible_agents:
            starts[name] = start_pose(self.learners[name].spec, self.np_random, offset, speed)
            self.learners[name].start(starts[name])
        self.agents = list(self.possible_agents)
        self._run({})   # the teleports
        self._run({})   # a neutral step: the observations show the starts
        self._steps = 0
        infos = {a: dict(self._info(a), start=starts[a]) for a in self.agents}
        return {a: self._observation(a) for a in self.agents}, infos

    def step(self, actions):
        """actions: {agent: action} for every agent in `agents`. Returns the five dicts over
        the agents that were live at this step; those that ended leave `agents`."""
        self._check_open()
        if not self.agents:
            raise RuntimeError("MultiAgentDrivingEnv.step() with no live agents: call reset()")
        if not isinstance(actions, dict):
            raise ValueError("actions must be a dict {agent: action}, got %r" % (type(actions).__name__,))
        extra = sorted(set(actions) - set(self.agents))
        missing = sorted(set(self.agents) - set(actions))
        if extra:
            raise ValueError("actions for %s, which are not live agents (agents: %s)" % (extra, self.agents))
        if missing:
            raise ValueError("no action for agent(s) %s" % missing)
        checked = {a: check_action(actions[a], self.learners[a].action_space, self.learners[a].names,
                                   who="agent %r: " % a) for a in self.agents}
        before = {a: dict(self.learners[a].metrics) for a in self.agents}
        self._run(checked)
        self._steps += 1
        done = self.sim.raw["scenario"]["done"]
        obs, rewards, terms, truncs, infos = {}, {}, {}, {}, {}
        for a in self.agents:
            m = self.learners[a].metrics
            obs[a] = self._observation(a)
            rewards[a] = float(self.reward_fn(a, before[a], m, checked[a]))
            terms[a] = bool(m.get("collided") or m.get("absent") or done)
            truncs[a] = not terms[a] and self._steps >= self.max_steps
            infos[a] = self._info(a)
        self.agents = [a for a in self.agents if not (terms[a] or truncs[a])]
        return obs, rewards, terms, truncs, infos

    def close(self):
        sim, self.sim = getattr(self, "sim", None), None
        if sim is not None:
            sim.close()

    def render(self):
        return None

    def state(self):
        raise NotImplementedError("MultiAgentDrivingEnv has no global state observation")

    @property
    def unwrapped(self):
        return self

    # --- the rest ---------------------------------------------------------------------------
    def _known(self, agent):
        if agent not in self.learners:
            raise KeyError("no agent %r (possible_agents: %s)" % (agent, self.possible_agents))
        return self.learners[agent]

    def _check_open(self):
        if self.sim is None:
            raise RuntimeError("MultiAgentDrivingEnv is closed; make a new one")

    def _run(self, actions):
        # agents that ended are stopped where they are (a zero-speed command each step)
        commands = {}
        for name, lr in self.learners.items():
            if name in self.agents:
                commands[lr.engine] = lr.command(actions.get(name))
            else:
                commands[lr.engine] = {"speed": {"speed": 0.0, "target_speed": 0.0, "acceleration": 0.0}}
        raw, collisions = self.sim.step(commands)
        for name in self.agents:
            lr = self.learners[name]
            if lr.engine not in raw["users"]:
                raise RuntimeError("scenario episode: no state of agent %s's engine %s" % (name, lr.engine))
            lr.observe(raw["t"], raw["users"], collisions, raw.get("signals"))

    def _observation(self, agent):
        return self.learners[agent].observation(self.parts, self.sim.raw["users"], self.radius)

    def _info(self, agent):
        m = self.learners[agent].metrics
        return {"t": self.sim.raw["t"], "steps": self._steps, "engine": self.learners[agent].engine,
                "progress": m["progress"], "collided": m.get("collided", False),
                "infractions": [dict(i) for i in m["new_infractions"]]}
