"""`convoy campaign`: runs a suite of experiments over seeds and weathers, on this machine or
on Slurm, and merges the results (docs/campaigns.md).

    campaign.py SUITE_DIR [--seeds N] [--weathers clear,rain,fog,night] [--workers N]
                [--backend local|slurm] [--out DIR] [--seconds S] [--build DIR]
    campaign.py --task K --plan OUT/plan.json          (the worker, as Slurm runs it)

Steps: the suite and options are checked (suite.py); the plan (every task's `convoy run`
command) is written to OUT/plan.json; the backend runs the tasks (local.py, slurm.py), keeping
OUT/campaign.json (state.py); then OUT/leaderboard.csv, OUT/results.json (results.py) and
OUT/report.html (report.py) are written, and a line per failed task is printed.

Restart: the same command with the same --out runs only what is missing (state.py, local.py,
slurm.py). Every file the campaign keeps is written atomically (atomic.py); OUT/campaign.lock
keeps a second campaign process off the same --out; SIGTERM is taken as Ctrl-C (exit 130)
wherever the campaign is.

Exit codes: 0 every task succeeded; 1 a task failed (the leaderboard and report are still
written); 2 bad input (a missing suite folder or config, an unknown weather, no sbatch for
--backend slurm, another campaign running in --out, ...: one message naming the file or
option); 3 Slurm failed (sbatch refused the array, squeue/scontrol failing for 2 minutes); 130
interrupted (with --backend slurm the arrays keep running: the same command follows them
again).
"""

import argparse
import os
import signal
import sys

from . import atomic, local, report, results, slurm, worker
from .state import CampaignState, StateError
from .suite import DEFAULT_WEATHERS, SuiteError, load_suite, make_plan, parse_weathers

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
CAMPAIGN_PY = os.path.join(REPO, "tools", "campaign", "campaign.py")


def _parser():
    p = argparse.ArgumentParser(
        prog="campaign.py",
        description="Runs a suite of Convoy experiments over seeds and weathers and merges "
                    "their results into a leaderboard and a report (docs/campaigns.md).")
    p.add_argument("suite", nargs="?", metavar="SUITE_DIR",
                   help="a folder of simulation configs, or with a suite.json")
    p.add_argument("--seeds", type=int, default=1, help="seeds 0..N-1 (default 1)")
    p.add_argument("--weathers", default=",".join(DEFAULT_WEATHERS),
                   help="comma-separated: clear, rain, fog, night, snow, dusk (default clear)")
    p.add_argument("--workers", type=int, default=1, help="tasks running at once (default 1)")
    p.add_argument("--backend", choices=("local", "slurm"), default="local")
    p.add_argument("--out", help="output folder (default campaigns/<suite folder name>)")
    p.add_argument("--seconds", type=float, help="simulated seconds per run (default: the "
                                                 "config's SimulationTimeout)")
    p.add_argument("--record", action="store_true",
                   help="record each run (RUN_DIR/recording.mcap); report.html links each to the "
                        "dashboard: open it with `convoy view OUT_DIR`")
    p.add_argument("--perception", choices=("ground_truth", "sensors"),
                   help="the default ego's perception in OpenSCENARIO runs (convoy run --scenario "
                        "--perception; default: ground_truth); leaderboard.csv's perception column")
    p.add_argument("--build", help="Convoy's build folder, for bin/convoy (default "
                                   "<repo>/build, or $CONVOY_BIN_DIR/convoy when set)")
    p.add_argument("--poll", type=float, default=1.0, help="seconds between Slurm polls")
    p.add_argument("--task", type=int, help=argparse.SUPPRESS)
    p.add_argument("--plan", help=argparse.SUPPRESS)
    return p


def _convoy(build):
    if build:
        return os.path.join(os.path.abspath(build), "bin", "convoy"), "--build %s" % build
    if os.environ.get("CONVOY_BIN_DIR"):
        return os.path.join(os.path.abspath(os.environ["CONVOY_BIN_DIR"]), "convoy"), \
            "$CONVOY_BIN_DIR"
    return os.path.join(REPO, "build", "bin", "convoy"), "the default build folder"


def _error(msg):
    print("campaign: error: %s" % msg, file=sys.stderr)
    return 2


def _raise_interrupt(signum, _frame):
    raise KeyboardInterrupt("signal %d" % signum)


_lock_fd = None  # OUT/campaign.lock, held while this process runs the campaign


def _lock_out(out):
    global _lock_fd
    path = os.path.join(out, "campaign.lock")
    try:
        _lock_fd = atomic.try_lock(path)
    except atomic.Busy as e:
        raise SuiteError("%s is in use by another campaign process (pid %s, %s); wait for it to "
                         "end or stop it" % (out, e.args[0] or "unknown", path)) from None


def main(argv=None):
    args = _parser().parse_args(argv)
    if args.task is not None or args.plan is not None:
        if args.task is None or args.plan is None:
            return _error("--task and --plan go together")
        return worker.main(args.plan, args.task)
    if args.suite is None:
        return _error("no SUITE_DIR given (see --help)")
    old_term = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        return _campaign(args)
    except KeyboardInterrupt:
        print("campaign: interrupted; run the same command to continue", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, old_term)


def _campaign(args):
    try:
        if args.seeds < 1:
            raise SuiteError("--seeds: must be at least 1, got %d" % args.seeds)
        if args.workers < 1:
            raise SuiteError("--workers: must be at least 1, got %d" % args.workers)
        if args.seconds is not None and not args.seconds > 0:
            raise SuiteError("--seconds: must be > 0, got %g" % args.seconds)
        weathers = parse_weathers(args.weathers)
        convoy, where = _convoy(args.build)
        if not os.access(convoy, os.X_OK):
            raise SuiteError("no Convoy program at %s (from %s; build it, or give --build DIR)"
                             % (convoy, where))
        if args.backend == "slurm":
            missing = slurm.check_installed()
            if missing:
                raise SuiteError(missing)
        entries = load_suite(args.suite)
        out = os.path.abspath(args.out or os.path.join(
            "campaigns", os.path.basename(os.path.normpath(os.path.abspath(args.suite)))))
        plan = make_plan(entries, args.seeds, weathers, out, convoy, args.seconds, args.record,
                         args.perception)
        os.makedirs(out, exist_ok=True)
        _lock_out(out)
        state = CampaignState.open(out, plan, args.backend)
    except (SuiteError, StateError) as e:
        return _error(e)
    except OSError as e:
        return _error("%s: %s" % (e.filename or "--out", e.strerror))

    plan_path = atomic.write_json(os.path.join(out, "plan.json"), plan, indent=1)
    n = len(plan["tasks"])
    print("campaign: %d tasks (%d entries x %d seeds x %d weathers), backend %s, output %s"
          % (n, len(entries), args.seeds, len(weathers), args.backend, out), flush=True)
    log = lambda msg: print(msg, flush=True)
    state.check_done(plan, log=log)
    state.save()
    try:
        if args.backend == "local":
            local.run(plan, state, args.workers, log=log)
        else:
            slurm.run(plan, state, args.workers, plan_path, CAMPAIGN_PY, poll_s=args.poll, log=log)
    except KeyboardInterrupt:
        state.save()
        print("campaign: interrupted%s; run the same command to continue" % (
            " (the Slurm arrays keep running)" if args.backend == "slurm" else ""), file=sys.stderr)
        return 130
    except slurm.SlurmError as e:
        state.save()
        print("campaign: error: Slurm: %s" % e, file=sys.stderr)
        return 3

    scorer, why = results.load_scorer()
    records = results.collect(plan, state, scorer, why)
    board, _ = results.write(out, records)
    page = report.write(out, records, plan, why)
    print("campaign: %s\ncampaign: %s" % (board, page))
    failed = [r for r in records if r["state"] != "done"]
    if failed:
        print("campaign: %d of %d tasks failed:" % (len(failed), n), file=sys.stderr)
        for r in failed:
            print("  %s: exit %s%s, %d attempt(s), log %s" % (
                r["name"], r["exit_code"], " (%s)" % r["reason"] if r["reason"] else "",
                r["attempts"], r["log"]), file=sys.stderr)
        return 1
    print("campaign: all %d tasks succeeded" % n)
    return 0
