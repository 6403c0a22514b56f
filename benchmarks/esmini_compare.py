#!/usr/bin/python3
"""esmini's example scenarios through Convoy, against esmini's own tracks (issue 25's figures).

  /usr/bin/python3 benchmarks/esmini_compare.py [ESMINI_XOSC_DIR] [--convoy build/bin/convoy]
        [--only NAME ...] [--out DIR] [--json FILE] [--timeout S]

With --ego default each runs as `convoy run --scenario FILE` (the stack under test drives the
ego) and the figure is only how many run to their end (exit 0).

Runs each .xosc of ESMINI_XOSC_DIR (default tests/data/esmini/xosc, esmini's 69 examples) with
`convoy run --scenario FILE --ego scenario --run-dir OUT/NAME -q` and compares the run's
tracks.csv with esmini's reference tracks (tests/data/esmini/reference/NAME.csv.gz, recorded by
tools/esmini/record_reference.py; python/convoy_scenario/compare.py): per scenario the median
over its scenario-controlled entities (the manifest's figure_entities: named in the file, no
driver-model controller) of each entity's median position (x, y) and speed error, Convoy's
track interpolated at esmini's 0.05 s steps. Prints one line per scenario, `NAME: run,
position P m, speed V m/s, ...`, `NAME: refused: MESSAGE` (exit 2: the file is outside what
Convoy reads) or `NAME: failed: MESSAGE` (another exit, or no tracks.csv), then the medians over
the scenarios and last `scenarios run: N/M, within 0.5 m: K`: run is exit 0 with a
tracks.csv; within counts a run whose position error is at most 0.5 m over at least 95 % of
esmini's time steps (coverage; a run that stops early does not count). --json writes every
number.
A ParameterValueDistribution file is compared with its first variant's tracks.
"""
import argparse
import glob
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine import cpu_model  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_scenario import compare  # noqa: E402

XOSC_DIR = os.path.join(REPO, "tests", "data", "esmini", "xosc")
REFERENCE_DIR = os.path.join(REPO, "tests", "data", "esmini", "reference")
WITHIN_M = 0.5
MIN_COVERAGE = 0.95


def error_line(stderr):
    """The line of a failed run's stderr that says what went wrong: the first `error:` or
    `...Error: ` line, else the first line."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    exceptions = [line for line in lines if re.match(r"^[\w.]*(Error|Exception): ", line)]
    for i, line in enumerate(lines):
        if line.startswith("error:") or line in exceptions:
            if line.endswith(":"):   # the message goes on: its cause
                cause = [e for e in exceptions if e != line] or lines[i + 1:i + 2]
                return "%s %s" % (line, cause[-1]) if cause else line
            return line
    return lines[0] if lines else "no message"


def run_convoy(convoy, xosc, run_dir, timeout, ego="scenario"):
    """(exit code, stderr, wall s)."""
    cmd = [convoy, "run", "--scenario", xosc, "--run-dir", run_dir, "-q"]
    if ego == "scenario":
        cmd[4:4] = ["--ego", "scenario"]
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                           timeout=timeout)
        code, err = p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        code, err = None, "error: timed out after %g s" % timeout
    return code, err, time.monotonic() - t0


def reference_of(name, manifest, reference_dir):
    """(reference file or None, its manifest entry or {}, note)."""
    entry = manifest.get("scenarios", {}).get(name, {})
    if "skipped" in entry:
        return None, entry, "no reference: esmini did not run it"
    if entry.get("variants"):
        first = entry["variants"][0]
        return (os.path.join(reference_dir, first["reference"]), dict(entry, **first),
                "vs variant 1/%d" % len(entry["variants"]))
    path = os.path.join(reference_dir, name + ".csv.gz")
    return (path if os.path.isfile(path) else None), entry, ""


def last_time(tracks_csv):
    last = None
    with open(tracks_csv) as f:
        next(f, None)
        for line in f:
            last = line.split(",", 1)[0]
    return float(last) if last else None


def scenario(convoy, xosc, out, manifest, reference_dir, timeout, ego="scenario"):
    """Result dict of one scenario."""
    name = os.path.basename(xosc)[:-5]
    run_dir = os.path.join(out, name)
    code, err, wall = run_convoy(convoy, xosc, run_dir, timeout, ego)
    result = {"name": name, "exit_code": code, "wall_s": round(wall, 2)}
    if ego != "scenario":   # the stack under test drives: ran to the end or not, no comparison
        if code != 0:
            result.update(status="refused" if code == 2 else "failed", message=error_line(err))
            return result
        result.update(status="run", note=end_of(run_dir))
        return result
    tracks = os.path.join(run_dir, "tracks.csv")
    if code != 0 or not os.path.isfile(tracks):
        result["status"] = "refused" if code == 2 else "failed"
        result["message"] = error_line(err) if code != 0 else "exit 0 without tracks.csv"
        return result
    result["status"] = "run"
    result["end_time"] = last_time(tracks)
    ref, entry, note = reference_of(name, manifest, reference_dir)
    result["reference_end_time"] = entry.get("end_time")
    if note:
        result["note"] = note
    if ref is None:
        return result
    reference = compare.read_tracks(ref)
    figure = set(entry.get("figure_entities", reference))
    if not figure:
        result["note"] = "no scenario-controlled entity: driver models drive them all"
        return result
    a = compare.compare_tracks(compare.read_tracks(tracks), reference,
                               exclude=set(reference) - figure)
    result.update({
        "position_error_m": a.position_error, "speed_error_mps": a.speed_error,
        "max_position_error_m": a.max_position_error, "coverage": a.coverage,
        "missing": list(a.missing), "extra": list(a.extra), "excluded": list(a.excluded),
        "entities": {n: {"position_error_m": e.median_position_error,
                         "max_position_error_m": e.max_position_error,
                         "speed_error_mps": e.median_speed_error, "coverage": e.coverage}
                     for n, e in a.entities.items()}})
    return result


def end_of(run_dir):
    """How a default-ego run ended (its summary.json): the scenario's end or the time limit."""
    try:
        with open(os.path.join(run_dir, "summary.json")) as f:
            s = json.load(f)
    except (OSError, ValueError):
        return "no summary.json"
    how = "the scenario ended it" if s.get("status_function_done") else "SimulationTimeout"
    return "%s at %.2f s simulated, %.1f s wall" % (how, s.get("sim_time_s", 0.0), s.get("wall_s", 0.0))


def line_of(r):
    if r["status"] != "run":
        return "%s: %s: %s" % (r["name"], r["status"], r["message"])
    if "position_error_m" not in r:
        return "%s: run, %s" % (r["name"], r.get("note", "no reference"))
    fmt = lambda v: "-" if v is None else "%.3f" % v  # noqa: E731
    missing = [m for m in r["missing"] if m not in r["excluded"]]
    return "%s: run, position %s m, speed %s m/s (max %s m, coverage %.0f%%, end %.2f s / "\
           "esmini %s s%s%s)" % (
               r["name"], fmt(r["position_error_m"]), fmt(r["speed_error_mps"]),
               fmt(r["max_position_error_m"]), 100 * r["coverage"], r["end_time"] or 0.0,
               r["reference_end_time"], ", missing " + " ".join(missing) if missing else "",
               ", " + r["note"] if r.get("note") else "")


def main():
    ap = argparse.ArgumentParser(description="esmini's examples through convoy --ego scenario")
    ap.add_argument("xosc_dir", nargs="?", default=XOSC_DIR, metavar="ESMINI_XOSC_DIR")
    ap.add_argument("--convoy", default=os.path.join(REPO, "build", "bin", "convoy"))
    ap.add_argument("--only", nargs="+", metavar="NAME", help="these scenarios (file stems)")
    ap.add_argument("--out", help="run folders (default: a new temporary folder, kept)")
    ap.add_argument("--reference", default=REFERENCE_DIR, help="reference tracks and manifest")
    ap.add_argument("--json", help="write every number to this file")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per scenario, s")
    ap.add_argument("--ego", choices=("scenario", "default"), default="scenario",
                    help="scenario (default): the scenario moves the ego, compared with esmini; "
                         "default: the stack under test drives the ego (the default `convoy run "
                         "--scenario`): only whether each runs to its end")
    ap.add_argument("--min-coverage", type=float, default=MIN_COVERAGE,
                    help="fraction of esmini's steps a run must cover to count as within "
                         "(default %(default)s)")
    a = ap.parse_args()
    files = sorted(glob.glob(os.path.join(a.xosc_dir, "*.xosc")))
    if a.only:
        files = [f for f in files if os.path.basename(f)[:-5] in a.only]
        unknown = set(a.only) - {os.path.basename(f)[:-5] for f in files}
        if unknown:
            sys.exit("esmini_compare: no %s in %s" % (", ".join(sorted(unknown)), a.xosc_dir))
    if not files:
        sys.exit("esmini_compare: no .xosc files in %s" % a.xosc_dir)
    if not os.access(a.convoy, os.X_OK):
        sys.exit("esmini_compare: %s is not an executable (build it, or --convoy)" % a.convoy)
    try:
        with open(os.path.join(a.reference, "manifest.json")) as f:
            manifest = json.load(f)
    except OSError:
        manifest = {}
    out = a.out or tempfile.mkdtemp(prefix="esmini_compare-")
    os.makedirs(out, exist_ok=True)
    print("CPU: %s (%d cores)" % (cpu_model(), os.cpu_count()))
    print("%d scenarios from %s, runs in %s" % (len(files), a.xosc_dir, out), flush=True)
    results = []
    for xosc in files:
        results.append(scenario(os.path.abspath(a.convoy), os.path.abspath(xosc), out, manifest,
                                a.reference, a.timeout, a.ego))
        print(line_of(results[-1]), flush=True)
    compared = [r for r in results if r.get("position_error_m") is not None]
    ran = sum(1 for r in results if r["status"] == "run")
    within = sum(1 for r in compared
                 if r["position_error_m"] <= WITHIN_M and r["coverage"] >= a.min_coverage)
    if compared:
        print("median over %d compared scenarios: position %.3f m, speed %.3f m/s" % (
            len(compared), statistics.median(r["position_error_m"] for r in compared),
            statistics.median(r["speed_error_mps"] for r in compared)))
    print("scenarios run: %d/%d, within %g m: %d" % (ran, len(results), WITHIN_M, within))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"cpu": cpu_model(), "cores": os.cpu_count(), "xosc_dir": a.xosc_dir,
                       "run": ran, "total": len(results), "within_m": WITHIN_M,
                       "min_coverage": a.min_coverage,
                       "within": within, "scenarios": results}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
