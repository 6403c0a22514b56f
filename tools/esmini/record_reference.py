#!/usr/bin/python3
"""Records esmini's reference tracks of the example scenarios (tests/data/esmini/xosc) into
tests/data/esmini/reference: one NAME.csv.gz per scenario in Convoy's tracks.csv format
(t,entity,x,y,z,heading,speed,road,lane,s; cm, mrad, cm/s) and manifest.json (per scenario:
the esmini arguments, whether controllers were disabled, end time, entities, exit code, why
skipped). esmini is a measuring instrument here: it is run, never linked.

    /usr/bin/python3 tools/esmini/record_reference.py --esmini PATH/esmini [--only NAME...]

Each scenario runs from its folder:
    esmini --headless --fixed_timestep 0.05 --osc NAME.xosc --csv_logger OUT.csv --collision
           --seed 0 --disable_stdout
plus `--disable_controllers` when an entity has an interactive or external controller
(headless it gets no input and the scenario runs to its 1200 s stop; `--ego scenario` moves
that entity by the scenario's own actions, as esmini does with controllers disabled). Road ids
come from a second, identical run with `--record` (dat2csv --extended): the CSV has none.
Output is deterministic: two runs write identical files.
"""

import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import esmini_csv  # noqa: E402
import xosc_info  # noqa: E402

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
XOSC_DIR = os.path.join(REPO, "tests", "data", "esmini", "xosc")
OUT_DIR = os.path.join(REPO, "tests", "data", "esmini", "reference")
BASE_ARGS = ["--headless", "--fixed_timestep", "0.05", "--collision", "--seed", "0",
             "--disable_stdout"]
BUDGET_BYTES = 3_000_000
# Arguments some files need to find what esmini finds through its own installed resources
# folder (bin/../resources), which this build tree does not have.
EXTRA_ARGS = {
    "auto_light": (["--path", "Catalogs/Vehicles"],
                   "its VehicleCatalog Directory ../xosc/Vehicles does not exist; esmini finds "
                   "VehicleCatalog.xosc through its resources folder"),
}
SKIP_NOTES = {
    "car_walk": "needs an external asset catalog (/tmp/openx-assets/catalogs, and a map at an "
                "absolute Windows path) that esmini does not ship",
}


def esmini_version(esmini):
    out = subprocess.run([esmini, "--version"], capture_output=True, text=True).stdout
    m = re.search(r"GIT REV: (\S+)", out)
    return m.group(1) if m else "unknown"


def find_dat2csv(esmini):
    here = os.path.dirname(os.path.abspath(esmini))
    for candidate in (os.path.join(here, "dat2csv"),
                      os.path.join(here, "..", "replayer", "dat2csv")):
        if os.path.isfile(candidate):
            return os.path.normpath(candidate)
    return None


def run_esmini(esmini, xosc, args, out_stem):
    cmd = [esmini] + BASE_ARGS + args + ["--osc", os.path.basename(xosc),
                                         "--logfile_path", out_stem + ".log"]
    proc = subprocess.run(cmd, cwd=os.path.dirname(xosc), stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL, timeout=600)
    return proc.returncode


def last_error(log):
    try:
        with open(log, errors="replace") as f:
            errors = [line.strip() for line in f if "[error]" in line]
    except OSError:
        return "no log"
    errors = [e for e in errors if not e.startswith("[] [error] Exception")]
    return errors[-1].replace("[] [error] ", "") if errors else "no error logged"


def variant_parameters(log):
    """Parameter values of a distribution variant, from esmini's log."""
    values, active = {}, False
    with open(log, errors="replace") as f:
        for line in f:
            if "Parameter permutation" in line:
                active = True
                continue
            m = re.match(r"\[\] \[info\]\s{3,}(\w+): (.*)$", line.rstrip("\n"))
            if active and m:
                values[m.group(1)] = m.group(2)
            elif active:
                break
    return values


def roads_of(dat2csv, dat):
    if not dat2csv or not os.path.isfile(dat):
        return {}
    subprocess.run([dat2csv, "--extended", "--file", dat], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, cwd=os.path.dirname(dat), timeout=600)
    csv = dat[:-4] + ".csv"
    return esmini_csv.read_dat2csv_roads(csv) if os.path.isfile(csv) else {}


def outputs(tmp, stem, distribution):
    """[(reference name, csv, dat, log)] written by one esmini run."""
    if not distribution:
        return [(stem, os.path.join(tmp, stem + ".csv"), os.path.join(tmp, "rec", stem + ".dat"),
                 os.path.join(tmp, stem + ".log"))]
    found = []
    for csv in glob.glob(os.path.join(tmp, stem + "_*_of_*.csv")):
        name = os.path.basename(csv)[:-4]
        found.append((name, csv, os.path.join(tmp, "rec", name + ".dat"),
                      os.path.join(tmp, name + ".log")))
    return sorted(found, key=lambda o: int(re.search(r"_(\d+)_of_", o[0]).group(1)))


def record_one(esmini, dat2csv, xosc, tmp):
    """(manifest entry, {reference name: rows, roads})."""
    stem = os.path.basename(xosc)[:-5]
    info = xosc_info.scenario_info(xosc)
    if info["distribution"]:
        # a ParameterValueDistribution: its scenario file's entities and controllers
        target = os.path.join(os.path.dirname(xosc), info["distribution"])
        info = dict(xosc_info.scenario_info(target), distribution=info["distribution"])
    disable = xosc_info.has_input_controller(info)
    args = (["--disable_controllers"] if disable else []) + EXTRA_ARGS.get(stem, ([], ""))[0]
    entry = {"file": "xosc/" + os.path.basename(xosc),
             "esmini_args": BASE_ARGS + args + ["--osc", stem + ".xosc", "--csv_logger",
                                                "OUT.csv"],
             "disable_controllers": disable, "controllers": info["controllers"],
             "xosc_entities": info["entities"], "figure_entities": xosc_info.figure_entities(info)}
    if stem in EXTRA_ARGS:
        entry["note"] = EXTRA_ARGS[stem][1]
    if info["distribution"] is not None:
        entry["distribution_of"] = info["distribution"]
    code = run_esmini(esmini, xosc, args + ["--csv_logger", os.path.join(tmp, stem + ".csv")],
                      os.path.join(tmp, stem))
    os.makedirs(os.path.join(tmp, "rec"), exist_ok=True)
    run_esmini(esmini, xosc, args + ["--record", os.path.join(tmp, "rec", stem + ".dat")],
               os.path.join(tmp, "rec", stem))
    entry["exit_code"] = code
    produced = [o for o in outputs(tmp, stem, info["distribution"] is not None)
                if os.path.isfile(o[1])]
    if code != 0 or not produced:
        log = os.path.join(tmp, stem + ".log")
        entry["skipped"] = "esmini exit %d: %s" % (code, last_error(log))
        if stem in SKIP_NOTES:
            entry["skipped"] += " (%s)" % SKIP_NOTES[stem]
        return entry, {}
    tracks = {}
    variants = []
    for name, csv, dat, log in produced:
        rows = esmini_csv.read_csv_logger(csv)
        tracks[name] = (rows, roads_of(dat2csv, dat))
        variant = {"reference": name + ".csv.gz", "end_time": rows[-1][0] if rows else 0.0,
                   "entities": esmini_csv.entities_in_order(rows)}
        if info["distribution"] is not None:
            variant["parameters"] = variant_parameters(log)
        variants.append(variant)
    if info["distribution"] is None:
        entry.update(variants[0])
    else:
        entry["variants"] = variants
    return entry, tracks


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--esmini", default=os.environ.get("ESMINI"),
                    help="esmini binary (default: $ESMINI)")
    ap.add_argument("--dat2csv", help="dat2csv binary (default: next to esmini's build)")
    ap.add_argument("--xosc-dir", default=XOSC_DIR)
    ap.add_argument("--out", default=OUT_DIR)
    ap.add_argument("--only", nargs="+", metavar="NAME")
    ap.add_argument("--every", type=int, choices=(1, 2),
                    help="keep every step (1) or every second step (2); default: 1 unless "
                         "the total is over %.0f MB" % (BUDGET_BYTES / 1e6))
    a = ap.parse_args()
    if not a.esmini or not os.path.isfile(a.esmini):
        sys.exit("record_reference: give esmini's binary with --esmini or $ESMINI (built as in "
                 "the esmini notes); got %r" % a.esmini)
    dat2csv = a.dat2csv or find_dat2csv(a.esmini)
    files = sorted(glob.glob(os.path.join(a.xosc_dir, "*.xosc")))
    if a.only:
        files = [f for f in files if os.path.basename(f)[:-5] in a.only]
    manifest_path = os.path.join(a.out, "manifest.json")
    manifest = {"scenarios": {}}
    if a.only and os.path.isfile(manifest_path):
        with open(manifest_path) as f:
            manifest = json.load(f)
    tracks = {}
    with tempfile.TemporaryDirectory(prefix="esmini-ref-") as tmp:
        for xosc in files:
            stem = os.path.basename(xosc)[:-5]
            work = os.path.join(tmp, stem)
            os.makedirs(work)
            entry, found = record_one(os.path.abspath(a.esmini), dat2csv, xosc, work)
            manifest["scenarios"][stem] = entry
            tracks.update(found)
            print("%-48s %s" % (stem, summary(entry)), flush=True)
            shutil.rmtree(work)
    every = a.every or manifest.get("every") or choose_every(tracks)
    manifest["esmini"] = "github.com/esmini/esmini %s" % esmini_version(a.esmini)
    write_all(a.out, tracks, every, manifest, replace=not a.only)
    done = [os.path.basename(f)[:-5] for f in files]
    print("recorded %d of %d files, every %d step(s) of 0.05 s; %s: %d bytes of tracks" % (
        sum(1 for n in done if "skipped" not in manifest["scenarios"][n]), len(files), every,
        os.path.relpath(a.out), sum(os.path.getsize(p) for p in glob.glob(
            os.path.join(a.out, "*.csv.gz")))))


def summary(entry):
    if "skipped" in entry:
        return entry["skipped"]
    runs = entry.get("variants", [entry])
    return "%d entities, %.2f s%s%s" % (
        len(runs[0]["entities"]), runs[0]["end_time"],
        " (%d variants)" % len(runs) if "variants" in entry else "",
        ", controllers disabled" if entry["disable_controllers"] else "")


def choose_every(tracks):
    total = sum(len(esmini_csv.gzip_bytes(esmini_csv.format_rows(rows, roads, 1)))
                for rows, roads in tracks.values())
    return 1 if total <= BUDGET_BYTES else 2


def write_all(out, tracks, every, manifest, replace):
    os.makedirs(out, exist_ok=True)
    if replace:
        for old in glob.glob(os.path.join(out, "*.csv.gz")):
            os.remove(old)
    for name, (rows, roads) in sorted(tracks.items()):
        with open(os.path.join(out, name + ".csv.gz"), "wb") as f:
            f.write(esmini_csv.gzip_bytes(esmini_csv.format_rows(rows, roads, every)))
    manifest.update({
        "about": "esmini's reference tracks of tests/data/esmini/xosc, written by "
                 "tools/esmini/record_reference.py; columns t,entity,x,y,z,heading,speed,road,"
                 "lane,s (m rounded to cm, rad to mrad, m/s to cm/s); heading wrapped to "
                 "[-pi, pi); figure_entities: named in the file and scenario-controlled",
        "dt": 0.05 * every,
        "every": every})
    with open(os.path.join(out, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
