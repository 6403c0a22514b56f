#!/usr/bin/python3
"""The cross-entropy method (CEM) on a small linear policy, with convoy_gym's DrivingEnv on the
Parkring: the training example of issue 28 part 3 (docs/gym.md, "Training example").

Policy (18 parameters): features f = [heading error, distance from the path, the 5 route points'
left offsets / 10, speed / 10, 1]; steer = tanh(w . f) * 0.55 rad, target speed =
sigmoid(v . f) * 15 m/s. It starts from zero weights (straight ahead at 7.5 m/s, which leaves
the track at the first bend). Each iteration draws `--population` parameter vectors from a
diagonal Gaussian, runs one episode per vector (all from the same start, reset(seed=iteration)),
and refits the Gaussian to the `--elite` best. Everything is seeded: the same command gives the
same curve.

Writes DIR/curve.csv (episode, iteration, return) and the PNG of the returns (OpenCV drawing;
matplotlib is not needed), and prints the first 10 and the last 10 episodes' mean return.

    cd experiments/rl_parkring && /usr/bin/python3 train_cem.py            # ~4 min on 2 cores
"""
import argparse
import csv
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_gym import DrivingEnv  # noqa: E402
from convoy_gym.driving_env import MAX_SPEED, MAX_STEER  # noqa: E402

N_FEATURES = 9


def features(obs):
    """[heading error, off path, left offsets of the 5 route points / 10, speed / 10, 1]."""
    return np.array([obs[4], obs[5]] + [obs[7 + 2 * i] / 10.0 for i in range(5)]
                    + [obs[3] / 10.0, 1.0], dtype=np.float64)


def act(theta, obs):
    f = features(obs)
    w, v = theta[:N_FEATURES], theta[N_FEATURES:]
    steer = np.tanh(w @ f) * MAX_STEER
    speed = MAX_SPEED / (1.0 + np.exp(-(v @ f)))
    return np.array([np.clip(steer, -MAX_STEER, MAX_STEER), np.clip(speed, 0.0, MAX_SPEED)],
                    dtype=np.float32)


def episode(env, theta, seed):
    obs, _ = env.reset(seed=seed)
    total = 0.0
    while True:
        obs, reward, terminated, truncated, _ = env.step(act(theta, obs))
        total += reward
        if terminated or truncated:
            return total


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except (OSError, subprocess.SubprocessError):
        pass
    return "unknown CPU"


def draw_curve(path, returns, iterations, means, title, note=""):
    """A scatter of the episodes' returns and a line of the iteration means, with OpenCV."""
    import cv2
    W, H = 900, 520
    left, right, top, bottom = 80, 20, 50, 60
    img = np.full((H, W, 3), 255, np.uint8)
    n = len(returns)
    lo, hi = min(min(returns), 0.0), max(returns)
    span = hi - lo or 1.0
    step = 10 ** np.floor(np.log10(span / 4))
    for mult in (1, 2, 5, 10):
        if span / (step * mult) <= 8:
            step *= mult
            break
    lo = np.floor(lo / step) * step
    hi = np.ceil(hi / step) * step
    px = lambda e: int(left + e / (n + 1) * (W - left - right))  # noqa: E731
    py = lambda r: int(H - bottom - (r - lo) / (hi - lo) * (H - top - bottom))  # noqa: E731
    font, black, grey = cv2.FONT_HERSHEY_SIMPLEX, (0, 0, 0), (225, 225, 225)
    for k in range(int(round((hi - lo) / step)) + 1):
        r = lo + k * step
        cv2.line(img, (left, py(r)), (W - right, py(r)), grey, 1)
        label = "%g" % r
        (tw, th), _ = cv2.getTextSize(label, font, 0.45, 1)
        cv2.putText(img, label, (left - 8 - tw, py(r) + th // 2), font, 0.45, black, 1, cv2.LINE_AA)
    xstep = 1
    while n / xstep > 10:
        xstep = xstep * 5 // 2 if str(xstep)[0] == "2" else xstep * 2
    for e in sorted({1} | set(range(xstep, n + 1, xstep))):
        x = px(e)
        cv2.line(img, (x, H - bottom), (x, H - bottom + 5), black, 1)
        label = str(e)
        (tw, _), _ = cv2.getTextSize(label, font, 0.45, 1)
        cv2.putText(img, label, (x - tw // 2, H - bottom + 20), font, 0.45, black, 1, cv2.LINE_AA)
    cv2.rectangle(img, (left, top), (W - right, H - bottom), black, 1)
    if lo < 0 < hi:
        cv2.line(img, (left, py(0)), (W - right, py(0)), (150, 150, 150), 1)
    blue, red = (200, 110, 30), (40, 40, 220)
    for e, r in enumerate(returns, 1):
        cv2.circle(img, (px(e), py(r)), 3, blue, -1, cv2.LINE_AA)
    # the iteration means, at the middle episode of each iteration
    centres = [np.mean([e for e, it in enumerate(iterations, 1) if it == i]) for i in range(len(means))]
    pts = np.array([[int(left + c / (n + 1) * (W - left - right)), py(m)]
                    for c, m in zip(centres, means)], np.int32)
    cv2.polylines(img, [pts], False, red, 2, cv2.LINE_AA)
    for p in pts:
        cv2.circle(img, tuple(int(v) for v in p), 4, red, -1, cv2.LINE_AA)
    scale = 0.55
    (tw, _), _ = cv2.getTextSize(title, font, scale, 1)
    if tw > W - 20:  # a long CPU name: a smaller title
        scale *= (W - 20) / tw
        (tw, _), _ = cv2.getTextSize(title, font, scale, 1)
    cv2.putText(img, title, ((W - tw) // 2, 30), font, scale, black, 1, cv2.LINE_AA)
    xl = "episode (CEM candidates, in order)"
    (tw, _), _ = cv2.getTextSize(xl, font, 0.5, 1)
    cv2.putText(img, xl, ((W - tw) // 2, H - 15), font, 0.5, black, 1, cv2.LINE_AA)
    yl = np.full((30, 200, 3), 255, np.uint8)
    cv2.putText(yl, "episode return", (10, 20), font, 0.5, black, 1, cv2.LINE_AA)
    yl = cv2.rotate(yl, cv2.ROTATE_90_COUNTERCLOCKWISE)
    y0 = top + (H - top - bottom - 200) // 2
    img[y0:y0 + 200, 8:38] = yl
    # legend
    lx, ly = W - right - 240, H - bottom - 62  # bottom right
    cv2.rectangle(img, (lx - 8, ly - 14), (lx + 225, ly + 48), (255, 255, 255), -1)
    cv2.rectangle(img, (lx - 8, ly - 14), (lx + 225, ly + 48), (160, 160, 160), 1)
    cv2.circle(img, (lx + 8, ly - 4), 3, blue, -1, cv2.LINE_AA)
    cv2.putText(img, "one episode", (lx + 25, ly), font, 0.45, black, 1, cv2.LINE_AA)
    cv2.line(img, (lx, ly + 16), (lx + 16, ly + 16), red, 2, cv2.LINE_AA)
    cv2.putText(img, "iteration mean", (lx + 25, ly + 20), font, 0.45, black, 1, cv2.LINE_AA)
    cv2.putText(img, note, (lx, ly + 40), font, 0.45, black, 1, cv2.LINE_AA)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if not cv2.imwrite(path, img, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
        raise OSError("cannot write %s" % path)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--iterations", type=int, default=18, help="CEM iterations (default 18)")
    p.add_argument("--population", type=int, default=8, help="episodes per iteration (8)")
    p.add_argument("--elite", type=int, default=2, help="best episodes refitted (2)")
    p.add_argument("--steps", type=int, default=400, help="steps per episode (400 = 20 s)")
    p.add_argument("--sigma", type=float, default=1.0, help="initial standard deviation (1.0)")
    p.add_argument("--seed", type=int, default=0, help="the CEM's random seed (0)")
    p.add_argument("--out", default=os.path.join(HERE, "runs", "train_cem"),
                   help="folder for curve.csv (default runs/train_cem)")
    p.add_argument("--png", default=os.path.join(REPO, "docs", "gym_training_curve.png"),
                   help="the curve's PNG (default docs/gym_training_curve.png)")
    a = p.parse_args(argv)
    if a.iterations < 1 or a.population < 2 or not 1 <= a.elite <= a.population or a.steps < 1:
        p.error("need --iterations >= 1, --population >= 2, 1 <= --elite <= --population, "
                "--steps >= 1")

    rng = np.random.default_rng(a.seed)
    dim = 2 * N_FEATURES
    mean, std = np.zeros(dim), np.full(dim, a.sigma)
    returns, iters, means = [], [], []
    t0 = time.monotonic()
    with DrivingEnv(max_steps=a.steps, physics_step=0.005) as env:
        for it in range(a.iterations):
            thetas = mean + std * rng.standard_normal((a.population, dim))
            r = np.array([episode(env, th, seed=it) for th in thetas])
            returns += r.tolist()
            iters += [it] * a.population
            means.append(float(r.mean()))
            elite = thetas[np.argsort(-r)[:a.elite]]
            mean = elite.mean(axis=0)
            # a noise floor that decays, so that the search keeps exploring early on
            std = np.sqrt(elite.var(axis=0) + (0.3 * a.sigma * max(0.0, 1 - it / 15)) ** 2 + 0.01)
            print("iteration %2d: mean return %7.1f, best %7.1f (%.0f s)"
                  % (it, r.mean(), r.max(), time.monotonic() - t0), flush=True)

    os.makedirs(a.out, exist_ok=True)
    csv_path = os.path.join(a.out, "curve.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["episode", "iteration", "return"])
        for e, (it, r) in enumerate(zip(iters, returns), 1):
            w.writerow([e, it, "%.4f" % r])
    np.save(os.path.join(a.out, "policy_mean.npy"), mean)
    first, last = float(np.mean(returns[:10])), float(np.mean(returns[-10:]))
    title = "CEM (population %d, elite %d) on DrivingEnv, Parkring, %d steps/episode, %s" % (
        a.population, a.elite, a.steps, cpu_model())
    draw_curve(a.png, returns, iters, means, title,
               note="first 10: %.1f, last 10: %.1f" % (first, last))
    print("episodes: %d in %.0f s" % (len(returns), time.monotonic() - t0))
    print("wrote %s and %s" % (csv_path, a.png))
    print("first 10 episodes mean return: %.1f" % first)
    print("last 10 episodes mean return: %.1f" % last)
    return 0


if __name__ == "__main__":
    sys.exit(main())
