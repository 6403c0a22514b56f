#!/usr/bin/python3
"""A reinforcement-learning-style loop in plain Python: drives the smart car on the Parkring
through NRP-Core's Python client, one step (0.05 s) at a time.

    /usr/bin/python3 experiments/rl_parkring/rl_drive.py [--steps 800] [--gains 0.05 0.3 1.2]

Each episode starts from reset(): observe, act, run_loop(1), reward. The policy is
proportional steering on the heading error the status function returns (steer = gain *
heading_error) at a fixed speed; the "learning" is a search over the gain: every episode tries
one gain of --gains and the best return wins. Reward per step: waypoints gained, minus the
distance from the path, minus 10 for leaving the track.
"""
import argparse
import os
import socket
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "python"))
from nrp_client import NrpCore  # noqa: E402

SPEED = 6.0  # m/s


def free_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "127.0.0.1:%d" % s.getsockname()[1]


def step(nrp, action):
    """Sends the action, runs one step, returns the step's observation."""
    nrp.set_json_datapack("action", "agent", action)
    done, observations = nrp.run_loop(1)
    return observations[-1]


def reward(before, after):
    r = (after["waypoint"] - before["waypoint"]) - 0.1 * after["off_path"]
    return r - 10.0 if after["episode_over"] and after["waypoint"] < after["waypoints"] else r


def episode(nrp, gain, steps, verbose):
    nrp.reset()
    obs = step(nrp, {"steer": 0.0, "speed": 0.0})  # the first observation
    total = 0.0
    for i in range(steps):
        action = {"steer": gain * obs["heading_error"], "speed": SPEED}
        new = step(nrp, action)
        total += reward(obs, new)
        obs = new
        if verbose and (i + 1) % 50 == 0:
            print("    t=%5.2f s  x=%7.2f y=%7.2f  speed %.1f m/s  waypoint %d/%d  off path "
                  "%.2f m  return %.1f" % (obs["t"], obs["x"], obs["y"], obs["speed"],
                                           obs["waypoint"], obs["waypoints"], obs["off_path"],
                                           total), flush=True)
        if obs["episode_over"]:
            break
    return total, obs, i + 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=800, help="steps per episode (0.05 s each)")
    parser.add_argument("--gains", type=float, nargs="+", default=[0.05, 0.3, 1.2],
                        help="steering gains to try, one episode each")
    parser.add_argument("--address", default=None, help="HOST:PORT (default: a free port)")
    parser.add_argument("-q", "--quiet", action="store_true")
    args = parser.parse_args()

    t0 = time.monotonic()
    nrp = NrpCore(args.address or free_address(), experiment_folder=HERE,
                  config_file="simulation_config.json")
    try:
        first = nrp.initialize()
        print("initialized in %.1f s; the car's link at %s" % (
            time.monotonic() - t0, [round(v, 2) for v in first[0].position]), flush=True)
        results = []
        for gain in args.gains:
            print("episode: steering gain %.2f" % gain, flush=True)
            t1 = time.monotonic()
            total, obs, n = episode(nrp, gain, args.steps, not args.quiet)
            wall = time.monotonic() - t1
            print("  return %.1f after %d steps (%.1f s simulated, %.1f s wall, %.0f steps/s): "
                  "waypoint %d/%d%s" % (total, n, obs["t"], wall, n / wall, obs["waypoint"],
                                        obs["waypoints"],
                                        ", left the track" if obs["off_path"] > 3 else ""),
                  flush=True)
            results.append((total, gain))
        best = max(results)
        print("best steering gain %.2f (return %.1f)" % (best[1], best[0]))
    finally:
        nrp.shutdown()


if __name__ == "__main__":
    main()
