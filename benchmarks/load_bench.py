#!/usr/bin/python3
"""Determinism under load (issue 30, part 4): the scenario suite (benchmarks/suite, 21
scenarios) as a local campaign twice, quietly and under load, compared row for row.

  /usr/bin/python3 benchmarks/load_bench.py [--scenarios a,b,...] [--seconds S]
      [--quiet-workers 1] [--load-workers 4] [--hogs N] [--out DIR] [--build DIR]

1. quiet: `convoy campaign SUITE --workers 1 --out OUT/quiet`;
2. under load: N CPU hogs (a Python busy loop each; N = --hogs, default the number of cores)
   and `convoy campaign SUITE --workers 4 --out OUT/load`: more runs than cores, next to
   processes that never yield the CPU.
SUITE is benchmarks/suite, or with --scenarios a suite.json in OUT naming those of its .xosc
files (absolute paths, so each runs where it is). --seconds caps each run's simulated time
(`convoy campaign --seconds`; the scores are then those of the shortened runs, still compared).

Both campaigns run a copy of BUILD/bin and BUILD/share made at the start (OUT/build; not with
--no-snapshot), so that a build on the machine meanwhile cannot change the program between them.

Then, for every task (scenario, seed, weather), compared between the two campaigns:
  - leaderboard.csv's row, every column but wall_s (documented as the same byte for byte for
    the same runs apart from wall_s: docs/campaigns.md);
  - the run's summary.json, every key but the wall-clock ones (WALL_KEYS) and the run's path;
  - tracks.csv / tracks.jsonl (every road user's pose each step) and ego_planner.json, by
    SHA-1, where the run wrote them.
A line per task names what differs. The last lines:
  leaderboard rows equal under load (all columns but wall_s): M/T
  driving scores equal under load: N/T
Exit 0 when every row, summary and track file is equal, 1 when one differs or a campaign failed,
2 on bad input. The campaigns are kept in OUT (default: a new folder under /tmp).
"""
import argparse
import csv
import fcntl
import glob
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
SUITE = os.path.join(HERE, "suite")
BUILD_LOCK = os.environ.get("CONVOY_BUILD_LOCK", "/tmp/convoy-build.lock")
sys.path.insert(0, HERE)
from machine import cpu_model  # noqa: E402

# summary.json keys measured on the wall clock, or naming the run's own folder or process: not
# compared
WALL_KEYS = {"config", "loop_wall_s", "pid", "real_time_factor", "startup", "startup_s", "wall_s"}
# files of a run folder compared by SHA-1 where the run wrote them: every road user's pose each
# step (tracks.csv: scenario runs; tracks.jsonl: city_traffic) and the planner's record
TRACK_FILES = ("tracks.csv", "tracks.jsonl", "ego_planner.json")
KEY = ("scenario", "seed", "weather", "parameters")


def bad_input(message):
    """One clear message and exit code 2."""
    print("load_bench: %s" % message, file=sys.stderr)
    sys.exit(2)


def suite_scenarios():
    return sorted(os.path.splitext(os.path.basename(p))[0]
                  for p in glob.glob(os.path.join(SUITE, "*.xosc")))


def make_suite(out, names):
    """A suite folder in OUT listing the named scenarios of benchmarks/suite."""
    known = suite_scenarios()
    unknown = [n for n in names if n not in known]
    if unknown:
        bad_input("no scenario %s in benchmarks/suite (it has: %s)"
                 % (", ".join(unknown), ", ".join(known)))
    folder = os.path.join(out, "suite")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "suite.json"), "w") as f:
        json.dump({"entries": [{"name": n, "config": os.path.join(SUITE, n + ".xosc")}
                               for n in names]}, f, indent=1)
    return folder


# A busy loop that ends by itself when this program is gone (no orphan hog)
HOG = ("import os\np = os.getppid()\nwhile os.getppid() == p:\n"
       "    for _ in range(100000):\n        pass\n")


def start_hogs(n):
    return [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(n)]


def stop_hogs(hogs):
    for h in hogs:
        h.kill()
    for h in hogs:
        h.wait()


def build_stamp(build):
    """The newest modification time in BUILD/bin: a build between the two campaigns (another
    developer's, on a shared machine) would compare two programs."""
    times = [os.stat(p).st_mtime for p in glob.glob(os.path.join(build, "bin", "*"))]
    return max(times) if times else 0.0


def snapshot(build, out):
    """A copy of BUILD/bin and BUILD/share in OUT/build, which both campaigns run: a build on
    the machine meanwhile cannot give them different programs (the Python sources and
    BUILD/python are still read where they are)."""
    dest = os.path.join(out, "build")
    # under the project's build lock (docs: flock /tmp/convoy-build.lock cmake --build ...), so
    # that no half-linked program is copied
    with open(BUILD_LOCK, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        for sub in ("bin", "share"):
            shutil.copytree(os.path.join(build, sub), os.path.join(dest, sub), symlinks=True)
    return dest


def campaign(args, suite, out, workers):
    """Runs `convoy campaign` in a session of its own; an interruption of this program (Ctrl-C,
    SIGTERM) is passed on to the whole session, so that the campaign stops its runs."""
    cmd = [os.path.join(args.build, "bin", "convoy"), "campaign", suite, "--workers",
           str(workers), "--out", out]
    if args.seconds:
        cmd += ["--seconds", "%g" % args.seconds]
    print("  %s" % " ".join(cmd), flush=True)
    t0 = time.monotonic()
    with open(out + ".log", "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            rc = proc.wait()
        except KeyboardInterrupt:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait()
            raise
    return rc, time.monotonic() - t0


def leaderboard(out):
    """{(scenario, seed, weather, parameters): row} of OUT/leaderboard.csv."""
    path = os.path.join(out, "leaderboard.csv")
    if not os.path.exists(path):
        return {}
    with open(path, newline="") as f:
        return {tuple(r.get(k, "") for k in KEY): r for r in csv.DictReader(f)}


def run_folder(out, key):
    return os.path.join(out, "runs", "%s__s%s__%s" % (key[0], key[1], key[2]))


def summary(folder):
    try:
        with open(os.path.join(folder, "summary.json")) as f:
            s = json.load(f)
    except (OSError, ValueError):
        return None
    return {k: v for k, v in s.items() if k not in WALL_KEYS}


def file_sha1(folder, name):
    path = os.path.join(folder, name)
    if not os.path.exists(path):
        return None
    with open(path, "rb") as f:
        return hashlib.sha1(f.read()).hexdigest()


def compare_task(quiet_out, load_out, key, qrow, lrow):
    """What differs for one task: a list of short descriptions (empty: equal)."""
    diffs = []
    if lrow is None:
        return ["no leaderboard row under load"]
    for c in qrow:
        if c != "wall_s" and qrow[c] != lrow.get(c):
            diffs.append("leaderboard %s %r -> %r" % (c, qrow[c], lrow.get(c)))
    qs, ls = summary(run_folder(quiet_out, key)), summary(run_folder(load_out, key))
    if qs is None or ls is None:
        diffs.append("summary.json missing (quiet %s, load %s)" % (qs is not None, ls is not None))
    else:
        for k in sorted(set(qs) | set(ls)):
            if qs.get(k) != ls.get(k):
                a, b = json.dumps(qs.get(k))[:80], json.dumps(ls.get(k))[:80]
                diffs.append("summary %s %s -> %s" % (k, a, b))
    for name in TRACK_FILES:
        qt, lt = file_sha1(run_folder(quiet_out, key), name), file_sha1(run_folder(load_out, key), name)
        if qt != lt:
            diffs.append("%s SHA-1 %s -> %s" % (name, qt, lt))
    return diffs


def compare(quiet_out, load_out):
    """Prints a line per task; returns (tasks, rows equal, driving scores equal, all equal)."""
    q, l = leaderboard(quiet_out), leaderboard(load_out)
    rows_equal = ds_equal = all_equal = 0
    for key in sorted(q):
        lrow = l.get(key)
        diffs = compare_task(quiet_out, load_out, key, q[key], lrow)
        ds_same = lrow is not None and q[key]["driving_score"] == lrow["driving_score"]
        row_same = lrow is not None and all(q[key][c] == lrow.get(c) for c in q[key]
                                            if c != "wall_s")
        ds_equal += ds_same
        rows_equal += row_same
        all_equal += not diffs
        print("  %-30s seed %s %-6s DS %-22s %s" % (key[0], key[1], key[2], q[key]["driving_score"],
                                                   "equal" if not diffs else "DIFFERS: "
                                                   + "; ".join(diffs)))
    for key in sorted(set(l) - set(q)):
        print("  %-30s only under load" % key[0])
    return len(q), rows_equal, ds_equal, all_equal


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenarios", help="comma-separated scenarios of benchmarks/suite "
                                        "(default: all of them)")
    ap.add_argument("--seconds", type=float, help="simulated seconds per run (default: the "
                                                  "scenario's own end)")
    ap.add_argument("--quiet-workers", type=int, default=1)
    ap.add_argument("--load-workers", type=int, default=4)
    ap.add_argument("--hogs", type=int, default=os.cpu_count() or 2,
                    help="CPU hog processes during the loaded campaign (default: one a core)")
    ap.add_argument("--out", help="output folder (default: a new folder under /tmp)")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--no-snapshot", action="store_true",
                    help="run BUILD/bin itself, not a copy made at the start")
    args = ap.parse_args()
    # Ctrl-C and SIGTERM (SIGINT may come ignored in the background): the campaign in flight
    # is stopped and the hogs are killed
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    if args.quiet_workers < 1 or args.load_workers < 1 or args.hogs < 0:
        bad_input("--quiet-workers and --load-workers must be >= 1, --hogs >= 0")
    if args.seconds is not None and args.seconds <= 0:
        bad_input("--seconds must be > 0")
    if not os.access(os.path.join(args.build, "bin", "convoy"), os.X_OK):
        bad_input("no %s" % os.path.join(args.build, "bin", "convoy"))
    out = args.out or tempfile.mkdtemp(prefix="convoy-load-")
    os.makedirs(out, exist_ok=True)
    for sub in ("quiet", "load", "build"):
        if os.path.exists(os.path.join(out, sub)):
            bad_input("%s exists; give another --out" % os.path.join(out, sub))
    suite = SUITE
    if args.scenarios:
        suite = make_suite(out, [s for s in args.scenarios.split(",") if s])
    print("load: %s, quiet (%d worker%s) against loaded (%d workers on %d cores, %d CPU hogs); "
          "CPU %s" % (suite, args.quiet_workers, "s"[:args.quiet_workers != 1],
                      args.load_workers, os.cpu_count(), args.hogs, cpu_model()), flush=True)
    quiet_out, load_out = os.path.join(out, "quiet"), os.path.join(out, "load")
    if not args.no_snapshot:
        args.build = snapshot(args.build, out)
        print("programs: a copy of the build's bin/ and share/ in %s" % args.build)
    stamp = build_stamp(args.build)
    try:
        rc_q, wall_q = campaign(args, suite, quiet_out, args.quiet_workers)
        print("quiet campaign: exit %d, %.0f s wall" % (rc_q, wall_q), flush=True)
        hogs = start_hogs(args.hogs)
        try:
            rc_l, wall_l = campaign(args, suite, load_out, args.load_workers)
        finally:
            stop_hogs(hogs)
    except KeyboardInterrupt:
        print("load_bench: interrupted; the campaigns are in %s" % out, file=sys.stderr)
        sys.exit(130)
    print("loaded campaign: exit %d, %.0f s wall" % (rc_l, wall_l), flush=True)
    if build_stamp(args.build) != stamp:
        print("warning: %s/bin changed while the campaigns ran (a build): they may have run "
              "different programs" % args.build)
    tasks, rows, ds, equal = compare(quiet_out, load_out)
    print("tasks fully equal (leaderboard row, summary.json, tracks, planner): %d/%d" % (equal, tasks))
    print("leaderboard rows equal under load (all columns but wall_s): %d/%d" % (rows, tasks))
    print("driving scores equal under load: %d/%d" % (ds, tasks))
    ok = rc_q == 0 and rc_l == 0 and tasks > 0 and equal == tasks
    if rc_q or rc_l:
        print("a campaign failed: see %s.log and %s.log" % (quiet_out, load_out))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
