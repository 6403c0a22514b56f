"""DrivingEnv: one car on a track as a gymnasium environment, on NRP-Core's Python client.

    from convoy_gym import DrivingEnv

    with DrivingEnv(max_steps=400) as env:
        obs, info = env.reset(seed=1)
        for _ in range(400):
            steer = max(-0.55, min(0.55, 0.8 * obs[4]))  # obs[4]: heading error
            obs, reward, terminated, truncated, info = env.step([steer, 6.0])
            if terminated or truncated:
                break

The simulation is experiments/rl_parkring's gym_config.json (or any config with its
conventions): the world engine "gazebo" with the smart car, whose joint targets the client
sets itself every step (CAR_JOINTS: the front wheels' steering angle, the rear wheels' speed
over WHEEL_RADIUS), and a status function
returning done=True and one JSON observation every step with the keys t, x, y, yaw, speed,
heading_error, off_path, waypoint, waypoints, episode_over and (optionally) ahead, a list of
[forward, left] route points in the car's frame. One step() is one run_loop(1), i.e. one
step of the smallest EngineTimestep (0.05 s on the Parkring), at a 10 ms physics step
(PHYSICS_STEP; physics_step=None keeps the world's own, 1 ms) with steering gains stable at
that step (STEERING_PID). A config with a python_json
engine "agent" (rl_parkring's simulation_config.json) gets the action as its datapack
"action" = {"steer": rad, "speed": m/s} instead, for a transceiver function to turn into the
joint targets (one more process and one more step of delay). With camera=(H, W), the
observation is a Dict {"state": that Box, "camera": uint8 H x W x 3}: the ego camera's frame
of the step, rendered at H x W by the world engine in a copy of the world (world_variant.py)
and returned by the status function `<name>_camera.py` (rl_parkring's observe_camera.py).
See docs/gym.md.
"""
import json
import os
import shutil
import socket

import numpy as np

from convoy_gym import spaces
from convoy_gym.closing import ClosesOnExit
from convoy_gym.world_variant import check_camera, variant_config
from nrp_client import NrpCore

__all__ = ["DrivingEnv", "default_reward", "OBSERVATION_KEYS"]

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_CONFIG = os.path.join(_REPO, "experiments", "rl_parkring", "gym_config.json")
PHYSICS_STEP = 0.01  # s: the world's physics step by default (the Parkring world's own: 1 ms)
# The steering joints' position controller (P, I, D) by default. The report's gains (40000, 200,
# 1) were tuned for its 1 ms step: on a steering axis of about 0.4 kg m^2 (the wheel about its
# diameter) they make an oscillator of omega = sqrt(P / I) = 316 rad/s, which the integrator
# keeps stable only while omega * dt < 2 (dt <= 5 ms; at 10 ms DART aborts). P 4000 gives
# omega 100 rad/s (omega * dt = 1 at 10 ms) and D 40 a damping ratio of 0.5: the wheels still
# reach a new angle within about 30 ms, under one 0.05 s step.
STEERING_PID = (4000.0, 0.0, 40.0)
# The server's and engines' environment without spinning waits (DrivingEnv(spin=False))
NO_SPIN = {"CONVOY_SPIN_US": "0", "CONVOY_ENGINE_SPIN_US": "0"}

MAX_STEER = 0.55   # rad, the smart car's steering limit (drive_tf.py clamps to it too)
MAX_SPEED = 15.0   # m/s
N_AHEAD = 5        # route points ahead in the observation (observe.py's AHEAD)
OBSERVATION_KEYS = ("x", "y", "yaw", "speed", "heading_error", "off_path") + tuple(
    "ahead%d_%s" % (i, axis) for i in range(N_AHEAD) for axis in ("forward", "left"))
ACTION_NAMES = ("steer", "speed")
OFF_TRACK_PENALTY = 10.0
STOP = {"steer": 0.0, "speed": 0.0}
# Without an "agent" engine: the smart car's joint datapacks the action sets (drive_tf.py's)
WORLD_ENGINE = "gazebo"
STEERING_JOINTS = ("smart_car_joint_plugin::front_left_steering_joint",
                   "smart_car_joint_plugin::front_right_steering_joint")
WHEEL_JOINTS = ("smart_car_joint_plugin::rear_left_wheel_joint",
                "smart_car_joint_plugin::rear_right_wheel_joint")
CAR_JOINTS = STEERING_JOINTS + WHEEL_JOINTS
WHEEL_RADIUS = 0.3  # m
JOINT_TYPE = "convoy.data.Joint"  # GazeboJointDataPack's message
# The status function's observation's keys (checked every step)
RAW_KEYS = ("x", "y", "yaw", "speed", "heading_error", "off_path", "waypoint", "waypoints",
            "episode_over")
_RAW_KEY_SET = frozenset(RAW_KEYS)


def default_reward(before, after, action):
    """Waypoints gained (2 m each on the Parkring), minus 0.1 per metre from the path, minus
    OFF_TRACK_PENALTY when the episode ends off the track (before the lap's end).
    `before` and `after` are the status function's observation dicts, `action` the array."""
    r = (after["waypoint"] - before["waypoint"]) - 0.1 * after["off_path"]
    if after["episode_over"] and after["waypoint"] < after["waypoints"]:
        r -= OFF_TRACK_PENALTY
    return float(r)


def _free_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "127.0.0.1:%d" % s.getsockname()[1]


class DrivingEnv(ClosesOnExit):
    """The gymnasium API (reset, step, close, observation_space, action_space) over one
    NRPCoreSim server process, started by the constructor and stopped by close().

    Observation: Box float32 (16,) = OBSERVATION_KEYS: x, y (m, world), yaw (rad), speed
    (m/s), heading_error (rad, towards the route a few points ahead), off_path (m), then
    N_AHEAD route points ahead (2, 4, 8, 16, 24 m along the route) as [forward, left] m in
    the car's frame (zeros when the status function gives no `ahead`).
    With camera=(H, W): Dict {"state": that Box, "camera": Box uint8 (H, W, 3) in [0, 255]},
    the ego camera's frame at the end of the step (rendered H x W, one frame per step).
    Action: Box float32 (2,) = [steer in [-0.55, 0.55] rad, target speed in [0, 15] m/s].
    An action outside it raises ValueError.

    DrivingEnv(scenario="X.xosc", ...) is a ScenarioDrivingEnv instead: one OpenSCENARIO run an
    episode (scenario_env.py; docs/gym.md, "Scenario episodes").
    """

    def __new__(cls, *args, scenario=None, **kwargs):
        if scenario is not None:
            from convoy_gym.scenario_env import ScenarioDrivingEnv
            return ScenarioDrivingEnv(scenario, **kwargs)
        return super().__new__(cls)

    metadata = {"render_modes": []}
    render_mode = None

    def __init__(self, config=DEFAULT_CONFIG, max_steps=1000, reward_fn=None,
                 start_steps=20, start_speed=6.0, start_steer=0.05, physics_step=PHYSICS_STEP,
                 args="", address=None, log_output="", camera=None, shadows=True,
                 max_contacts=None, steering_pid="auto", spin=True):
        """:param config: the simulation config; its folder is the experiment folder
        :param max_steps: steps per episode before `truncated`
        :param reward_fn: reward_fn(before, after, action) -> float; default_reward if None
        :param start_steps, start_speed, start_steer: reset(seed) drives 1 to start_steps
            steps at a speed in [0, start_speed] m/s and a steer in +-start_steer rad, all
            drawn from the seed, so each seed starts the episode from its own state
        :param physics_step: the Gazebo world's physics step in s (default PHYSICS_STEP,
            10 ms; None: the world's own, 1 ms on the Parkring, several times slower)
        :param args: more NRPCoreSim options, e.g. "-o SimulationTimeout=600"
        :param address: HOST:PORT for the server (default: a free loopback port)
        :param log_output: file in the experiment folder for the server's output ("" none)
        :param camera: None, or (H, W): the observation also holds the ego camera's frame,
            rendered H x W pixels once per step (see the class's docstring), with the sun's
            shadow map sized to it (world_variant.shadow_map_size)
        :param shadows: with a camera, False renders it without the sun's shadows (about
            1.6x the steps/s at 84 x 84 on a CPU renderer)
        :param max_contacts: the world's <physics><max_contacts>: contacts kept per pair of
            collision shapes, the deepest (None: every contact, as the world's own physics)
        :param steering_pid: (P, I, D) of the steering joints' position controllers in the
            world's copy; "auto" (default): STEERING_PID (stable at a 10 ms physics step) when
            physics_step is over 5 ms, else the car's own (stable up to 5 ms); None: the car's
            own
        :param spin: True lets the server and its engine wait for each other's next message by
            yielding the CPU for a while rather than sleeping (quicker hand-overs when a core is
            free for each process); False makes them sleep at once (no CPU spent waiting: for
            several environments sharing few cores, VectorDrivingEnv's default)
        """
        self._nrp = None
        self._tmp = None
        self._joint = None
        config = os.path.abspath(config)
        if not os.path.isfile(config):
            raise FileNotFoundError("DrivingEnv: config %s not found" % config)
        if int(max_steps) <= 0:
            raise ValueError("DrivingEnv: max_steps must be > 0, got %r" % (max_steps,))
        if int(start_steps) < 1:
            raise ValueError("DrivingEnv: start_steps must be >= 1, got %r" % (start_steps,))
        self.config = config
        self.max_steps = int(max_steps)
        self.reward_fn = reward_fn or default_reward
        self.start = (int(start_steps), float(start_speed), float(start_steer))
        inf = np.inf
        self.state_space = spaces.Box(
            low=np.array([-inf, -inf, -np.pi, 0.0, -np.pi, 0.0] + [-inf] * (2 * N_AHEAD)),
            high=np.array([inf, inf, np.pi, inf, np.pi, inf] + [inf] * (2 * N_AHEAD)),
            dtype=np.float32)
        self.observation_space = self.state_space
        self._bounds = (self.state_space.low.astype(np.float32),
                        self.state_space.high.astype(np.float32))
        self.camera = None
        if camera is not None:
            self.camera = check_camera(camera)
            self.observation_space = spaces.Dict({
                "state": self.state_space,
                "camera": spaces.Box(0, 255, self.camera + (3,), dtype=np.uint8)})
        self._frame = None
        self._pending = None  # the action step_begin() sent
        self.action_space = spaces.Box(low=np.array([-MAX_STEER, 0.0]),
                                       high=np.array([MAX_STEER, MAX_SPEED]), dtype=np.float32)
        # The action's bounds as floats, for the check of every step
        self._action_bounds = tuple(zip(self.action_space.low.tolist(),
                                        self.action_space.high.tolist()))
        self.np_random = np.random.Generator(np.random.PCG64())
        self._raw = None
        self._steps = 0
        run_config = config
        with open(config) as f:
            engines = json.load(f).get("EngineConfigs", [])
        self._agent = any(e.get("EngineName") == "agent" for e in engines)
        gains = None
        if isinstance(steering_pid, str) and steering_pid == "auto":
            steering_pid = STEERING_PID if (physics_step or 0) > 0.005 else None
        if steering_pid is not None:
            gains = {name.split("::")[-1]: tuple(steering_pid) for name in STEERING_JOINTS}
        if physics_step is not None or camera is not None or max_contacts is not None or gains:
            run_config, self._tmp = variant_config(config, physics_step, self.camera,
                                                   shadows=bool(shadows),
                                                   max_contacts=max_contacts, gains=gains)
        self._nrp_config = run_config  # the config the server runs
        try:
            self._nrp = NrpCore(address or _free_address(),
                                experiment_folder=os.path.dirname(config),
                                config_file=run_config, args=args, log_output=log_output,
                                local_channel=True,
                                environment=None if spin else NO_SPIN)
            self._nrp.initialize()
            self._joint = None if self._agent else self._nrp._message_class(JOINT_TYPE)
        except BaseException:
            self.close()
            raise
        self._needs_reset = False  # the first episode starts from initialize()'s state

    # --- gymnasium's API -------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Starts an episode. `seed` (an int) reseeds the environment's generator: the same
        seed gives the same episode for the same actions, bit for bit. options may hold
        start_steps / start_speed / start_steer to fix the start instead of drawing it.
        Returns (observation, info)."""
        self._check_open()
        if self._pending is not None:
            raise RuntimeError("DrivingEnv.reset() between step_begin() and step_finish()")
        if seed is not None:
            self.np_random = np.random.Generator(np.random.PCG64(seed))
        options = dict(options or {})
        unknown = set(options) - {"start_steps", "start_speed", "start_steer"}
        if unknown:
            raise ValueError("reset(): unknown options %s" % sorted(unknown))
        max_steps, max_speed, max_steer = self.start
        rng = self.np_random
        n = int(options.get("start_steps", rng.integers(1, max_steps + 1)))
        speed = float(options.get("start_speed", rng.uniform(0.0, max_speed)))
        steer = float(options.get("start_steer", rng.uniform(-max_steer, max_steer)))
        if self._needs_reset:
            self._set_action(STOP["steer"], STOP["speed"])
            self._nrp.reset()
        self._needs_reset = True
        for _ in range(max(n, 1)):
            self._raw = self._run(steer, speed)
        self._steps = 0
        info = self._info()
        info["start"] = {"steps": n, "speed": speed, "steer": steer}
        return self._observation(), info

    def step(self, action):
        """Applies `action` for one step. Returns (obs, reward, terminated, truncated,
        info): terminated when the car left the track or finished the lap, truncated after
        max_steps steps."""
        self.step_begin(action)
        return self.step_finish()

    def step_begin(self, action):
        """step()'s first half: checks `action` (ValueError) and sends it; the server steps
        while the caller goes on, until step_finish() returns the step's result. Between
        the two, the environment takes no other call. VectorDrivingEnv steps its
        environments so, all at once from one thread."""
        self._check_open()
        if self._raw is None:
            raise RuntimeError("DrivingEnv.step() before reset()")
        if self._pending is not None:
            raise RuntimeError("DrivingEnv.step_begin() twice without step_finish()")
        a = self._check_action(action)
        self._set_action(float(a[0]), float(a[1]))
        self._nrp.run_loop_begin(1)
        self._pending = a

    def step_finish(self):
        """step()'s second half: (obs, reward, terminated, truncated, info) of the step
        step_begin() started."""
        a, self._pending = self._pending, None
        if a is None:
            raise RuntimeError("DrivingEnv.step_finish() without step_begin()")
        before = self._raw
        self._raw = self._observed(self._nrp.run_loop_finish()[1])
        self._steps += 1
        reward = float(self.reward_fn(before, self._raw, a))
        terminated = bool(self._raw["episode_over"])
        truncated = not terminated and self._steps >= self.max_steps
        return self._observation(), reward, terminated, truncated, self._info()

    def close(self):
        """Stops the simulation (the NRPCoreSim process and its engines). Safe to call twice."""
        nrp, self._nrp = getattr(self, "_nrp", None), None
        tmp, self._tmp = getattr(self, "_tmp", None), None
        try:
            if nrp is not None:
                nrp.shutdown()
        finally:
            if tmp:
                shutil.rmtree(tmp, ignore_errors=True)

    def render(self):
        return None

    @property
    def unwrapped(self):
        return self

    # --- the rest --------------------------------------------------------------------------
    def _check_open(self):
        if self._nrp is None:
            raise RuntimeError("DrivingEnv is closed; make a new one")

    def _check_action(self, action):
        try:
            a = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError("action %r is not an array of 2 numbers [steer, speed]"
                             % (action,)) from None
        if a.shape != self.action_space.shape:
            raise ValueError("action %r has shape %s, the action space %s"
                             % (action, a.shape, self.action_space.shape))
        (steer_low, steer_high), (speed_low, speed_high) = self._action_bounds
        steer, speed = a.tolist()
        if steer_low <= steer <= steer_high and speed_low <= speed <= speed_high:
            return a  # (NaN fails the comparisons: named below)
        for i, name in enumerate(ACTION_NAMES):
            low, high = float(self.action_space.low[i]), float(self.action_space.high[i])
            if not np.isfinite(a[i]):
                raise ValueError("action[%d] (%s) = %r is not a finite number" % (i, name, a[i]))
            if a[i] < low:
                raise ValueError("action[%d] (%s) = %r is below the action space's bound %g"
                                 % (i, name, a[i], low))
            if a[i] > high:
                raise ValueError("action[%d] (%s) = %r is above the action space's bound %g"
                                 % (i, name, a[i], high))
        return a

    def _set_action(self, steer, speed):
        """The action for the next run_loop() / reset(): the agent engine's datapack, or the
        car's joint targets (drive_tf.py's: steer clamped to MAX_STEER, speed / radius)."""
        nrp = self._nrp
        if self._agent:
            nrp.set_json_datapack("action", "agent", {"steer": steer, "speed": speed})
            return
        steering = self._joint(position=max(-MAX_STEER, min(MAX_STEER, steer)))
        for name in STEERING_JOINTS:
            nrp.set_proto_datapack(name, WORLD_ENGINE, steering)
        wheels = self._joint(velocity=speed / WHEEL_RADIUS)
        for name in WHEEL_JOINTS:
            nrp.set_proto_datapack(name, WORLD_ENGINE, wheels)

    def _run(self, steer, speed):
        self._set_action(steer, speed)
        return self._observed(self._nrp.run_loop(1)[1])

    def _observed(self, observations):
        """The status function's observation dict among a step's `observations` (and the
        camera frame taken from them)."""
        if self.camera is None and len(observations) == 1 and type(observations[0]) is dict:
            raw = observations[0]  # the usual step: one observation (checked as below)
            if _RAW_KEY_SET.issubset(raw):
                return raw
        dicts = [o for o in observations if isinstance(o, dict)]
        if self.camera is not None and (dicts or self._frame is None):
            self._take_frame([o for o in observations if not isinstance(o, dict)])
        if not dicts:  # the status function had no car pose yet
            if self._raw is None:
                raise RuntimeError("DrivingEnv: the status function returned no observation "
                                   "(%s)" % self.config)
            return self._raw
        raw = dicts[-1]
        missing = [k for k in RAW_KEYS if k not in raw]
        if missing:
            raise KeyError("DrivingEnv: the status function of %s returned no %s"
                           % (self.config, ", ".join(missing)))
        return raw

    def _take_frame(self, messages):
        """The step's camera frame from the status function's camera datapack(s): every
        step with an observation has one."""
        frames = [m for m in messages if hasattr(m, "imageData")]
        if not frames:
            raise RuntimeError("DrivingEnv: the status function of %s returned no camera "
                               "frame with its observation" % self.config)
        m = frames[-1]
        shape = (m.imageHeight, m.imageWidth, m.imageDepth)
        if shape != self.camera + (3,) or len(m.imageData) != shape[0] * shape[1] * shape[2]:
            raise RuntimeError("DrivingEnv: the camera frame is %s (%d bytes), not %s x 3"
                               % (shape, len(m.imageData), self.camera))
        self._frame = np.frombuffer(m.imageData, dtype=np.uint8).reshape(shape)

    def _observation(self):
        state = self._state()
        if self.camera is None:
            return state
        return {"state": state, "camera": self._frame.copy()}

    def _state(self):
        r = self._raw
        ahead = r.get("ahead") or [[0.0, 0.0]] * N_AHEAD
        values = [r["x"], r["y"], r["yaw"], r["speed"], r["heading_error"], r["off_path"]]
        for i in range(N_AHEAD):
            values += ahead[min(i, len(ahead) - 1)][:2]
        obs = np.asarray(values, dtype=np.float32)
        # np.clip's result, without its overhead for small arrays
        low, high = self._bounds
        return np.minimum(np.maximum(obs, low, out=obs), high, out=obs)

    def _info(self):
        r = self._raw
        return {"t": r.get("t"), "waypoint": r["waypoint"], "waypoints": r["waypoints"],
                "off_path": r["off_path"], "steps": self._steps,
                "lap_done": bool(r["episode_over"]) and r["waypoint"] >= r["waypoints"]}
