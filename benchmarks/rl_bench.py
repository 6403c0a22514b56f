#!/usr/bin/python3
"""convoy_gym benchmark (issue 28): DrivingEnv.step() calls per second, 1 process, without and
with an 84 x 84 camera, and VectorDrivingEnv(2)'s total steps per second against one
environment's (the parallel speed-up), without and with the camera.

  /usr/bin/python3 benchmarks/rl_bench.py [--steps 3000] [--runs 3] [--camera 84x84]
                                          [--envs 2] [--baseline] [--physics-step S]

Each figure is DrivingEnv's defaults (experiments/rl_parkring/gym_config.json: the smart car
in the world engine only, the client setting its joint targets; 10 ms physics step; 0.05 s
per step). A run resets with a new seed and times --steps step() calls of a heading-error
policy at 6 m/s, resetting when an episode ends (resets are timed too); the figure is the
median of --runs runs.

- without camera: DrivingEnv(); with camera: DrivingEnv(camera=(H, W)) (--camera none skips
  it), whose every step also brings the ego camera's H x W frame rendered by the world engine
  (with the sun's shadows, through a shadow map sized to the camera); also timed, and printed
  on its own line: DrivingEnv(camera=(H, W), shadows=False).
- parallel speed-up: VectorDrivingEnv(N) (--envs, default 2; 1 skips it; its defaults: each
  environment's processes pinned to one core, round-robin; no spinning waits) runs the same
  policy in each of its N environments for --steps vector steps; its total environment steps
  per second over the single environment's, the two timed in alternation (single, vector,
  single, ...) so that a machine busy with something else slows both alike.
- parallel speed-up with camera: the same with VectorDrivingEnv(N, camera=(H, W)) against
  DrivingEnv(camera=(H, W)) (with shadows), timed in alternation with the camera figures.
- --baseline also times, alternating with the figures above, the environment as it was
  before (rl_parkring's simulation_config.json: the python_json agent engine, drive_tf and the
  weather engine, at the world's own 1 ms physics step; with the camera, its 1024-texel
  shadow map), printed as `baseline ...` lines.
- --physics-step S: DrivingEnv(physics_step=S) instead of the default (0: the world's own).

Each run's line says when another NRPCoreSim was running meanwhile (its figures are then
contended). The last lines are the CPU model and `env steps/s without camera: N`, `env steps/s
with camera: N`, `parallel speed-up: R`, `parallel speed-up with camera: R`. Targets (issue
28): 2,000, 300, and 1.6 for 2 environments on 2 cores.
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine import cpu_model  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "python"))
import numpy as np  # noqa: E402

from convoy_gym import DrivingEnv, VectorDrivingEnv  # noqa: E402
from convoy_gym.driving_env import PHYSICS_STEP  # noqa: E402

BASELINE_CONFIG = os.path.join(REPO, "experiments", "rl_parkring", "simulation_config.json")
BASELINE = dict(config=BASELINE_CONFIG, physics_step=None)


def other_simulations():
    """NRPCoreSim processes that are not this benchmark's (they take cores from it)."""
    def pgrep(*args):
        return subprocess.run(["pgrep"] + list(args), capture_output=True,
                              text=True).stdout.split()
    try:
        return len(set(pgrep("-f", "NRPCoreSim")) - set(pgrep("-P", str(os.getpid()))))
    except OSError:
        return 0


def note():
    n = other_simulations()
    return "  [%d other NRPCoreSim running: figures are contended]" % n if n else ""


def state(obs):
    """The state vector of an observation (with a camera, obs["state"])."""
    return obs["state"] if isinstance(obs, dict) else obs


def time_env(env, steps, seed):
    obs, _ = env.reset(seed=seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        action = np.array([np.clip(0.8 * state(obs)[4], -0.55, 0.55), 6.0], dtype=np.float32)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            obs, _ = env.reset()
    return steps / (time.perf_counter() - t0)


def time_vector(envs, steps, seed):
    """Total environment steps per second of `steps` vector steps (autoresets included)."""
    obs, _ = envs.reset(seed=seed)
    speed = np.full(envs.num_envs, 6.0)
    t0 = time.perf_counter()
    for _ in range(steps):
        actions = np.stack([np.clip(0.8 * state(obs)[:, 4], -0.55, 0.55), speed], axis=1)
        obs, _, _, _, _ = envs.step(actions)
    return steps * envs.num_envs / (time.perf_counter() - t0)


def alternate(timers, runs):
    """Runs each (name, open environment, timer) in turn, `runs` times; prints each run and
    returns each name's median."""
    rates = {name: [] for name, _, _ in timers}
    for _, env, timer in timers:
        timer(env, 100, 99)  # warm-up
    for run in range(runs):
        for name, env, timer in timers:
            rates[name].append(timer(env, STEPS, run))
            print("%s, run %d: %.0f steps/s%s" % (name, run + 1, rates[name][-1], note()),
                  flush=True)
    return {name: statistics.median(r) for name, r in rates.items()}


def camera_size(text):
    if text.lower() == "none":
        return None
    try:
        height, width = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError("--camera: HxW (84x84) or none, got %r" % text)
    return height, width


STEPS = 3000


def main():
    global STEPS
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=3000, help="timed steps per run")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--camera", type=camera_size, default=(84, 84),
                        help="HxW of the camera figure (none: skip it)")
    parser.add_argument("--envs", type=int, default=2,
                        help="environments of the parallel figure (1: skip it)")
    parser.add_argument("--baseline", action="store_true",
                        help="also time the environment as it was before, alternating")
    parser.add_argument("--physics-step", type=float, default=PHYSICS_STEP,
                        help="DrivingEnv's physics_step (0: the world's own)")
    args = parser.parse_args()
    STEPS = args.steps
    kw = dict(max_steps=100000, physics_step=args.physics_step or None)
    base = dict(kw, **BASELINE)
    results = {}

    def single(env, steps, seed):
        return time_env(env, steps, seed)

    def vector(envs, steps, seed):
        return time_vector(envs, steps, 10 * seed)

    with DrivingEnv(**kw) as env:
        timers = [("no camera", env, single)]
        with _maybe(args.baseline, lambda: DrivingEnv(**base)) as old:
            if old is not None:
                timers.append(("baseline no camera", old, single))
            with _maybe(args.envs > 1, lambda: VectorDrivingEnv(args.envs, **kw)) as envs:
                if envs is not None:
                    timers.append(("VectorDrivingEnv(%d) total" % args.envs, envs, vector))
                results.update(alternate(timers, args.runs))
    if args.camera:
        size = "camera %dx%d" % args.camera
        with DrivingEnv(camera=args.camera, **kw) as env, \
                DrivingEnv(camera=args.camera, shadows=False, **kw) as flat:
            timers = [(size, env, single), (size + " without shadows", flat, single)]
            with _maybe(args.baseline, lambda: DrivingEnv(
                    camera=args.camera, args="-o EngineConfigs/0/ShadowMapSize=1024",
                    **base)) as old:
                if old is not None:
                    timers.append(("baseline " + size, old, single))
                with _maybe(args.envs > 1, lambda: VectorDrivingEnv(
                        args.envs, camera=args.camera, **kw)) as envs:
                    if envs is not None:
                        timers.append(("VectorDrivingEnv(%d) total, %s" % (args.envs, size),
                                       envs, vector))
                    results.update(alternate(timers, args.runs))

    print("CPU: %s (%d cores)" % (cpu_model(), os.cpu_count()))
    for name, rate in results.items():
        print("median %s: %.0f steps/s" % (name, rate))
    print("env steps/s without camera: %.0f" % results["no camera"])
    if args.camera:
        print("env steps/s with camera: %.0f" % results[size])
    if args.envs > 1:
        total = results["VectorDrivingEnv(%d) total" % args.envs]
        print("parallel speed-up: %.2f" % (total / results["no camera"]))
        if args.camera:
            total = results["VectorDrivingEnv(%d) total, %s" % (args.envs, size)]
            print("parallel speed-up with camera: %.2f" % (total / results[size]))


class _maybe:
    """`with _maybe(cond, make) as x`: x = make() (closed at the end) if cond, else None."""

    def __init__(self, cond, make):
        self.obj = make() if cond else None

    def __enter__(self):
        return self.obj

    def __exit__(self, *exc):
        if self.obj is not None:
            self.obj.close()


if __name__ == "__main__":
    main()
