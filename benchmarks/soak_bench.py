#!/usr/bin/python3
"""Soak: one simulated hour of experiments/city_traffic with recording, and the memory, open
files and shared memory of every process of the run (issue 30, part 3).

  /usr/bin/python3 benchmarks/soak_bench.py [--sim-seconds 3600] [--density] [--interval 10]
                                            [--warmup 300] [--max-wall S] [--out DIR]

Runs `convoy run -c simulation_config.json --record -o SimulationTimeout=N` in
experiments/city_traffic (with --density: simulation_config_density.json, the run of
test_city_traffic.Density: every agent respawning, SUMO's flows doubled, no ego) and, every
--interval wall seconds, samples every process of the run: the coordinator, each engine process
(named by its log file, logs/<engine>.log) and their children (ffmpeg writing camera.mp4, the
Python interpreters' helpers). For each process it reads
  - /proc/PID/status: VmRSS, RssAnon, RssFile, RssShmem (resident shared memory);
  - /proc/PID/smaps_rollup: Pss;
  - /proc/PID/fd: the number of open files, and how many of them are memfds or /dev/shm files;
  - /proc/PID/maps: the number of memfd and /dev/shm mappings;
and the run's simulated time (the last line of steps.csv). The samples go to a CSV (one row a
process a sample; --csv, default OUT/soak_samples.csv) for a plot.

Growth is measured after a warm-up of --warmup simulated seconds (default 300): in the first
minutes SUMO's flows fill the map (its vehicle count and with it every road user list grows to
its steady state), the vehicle agents reach the ends of their routes (or respawn), the
recorder's chunk buffers, the Python interpreters' caches, glibc's arenas and x264's look-ahead
fill once. What grows after that is what a longer run keeps growing. For each process the table
prints RSS at the start (first sample), at the end of the warm-up (the baseline), at the end
(last sample), and the largest RSS after the warm-up minus the baseline ("max growth"); the
same for PSS, RssShmem and open files. The last line is `max growth MiB: N`, the largest of
these RSS growths (target < 10 MiB).

--experiment DIR runs a copy of the experiment folder instead (to try a change; its relative
paths to ../ego_planner etc. must hold there).

--max-wall S stops the run after S wall seconds (SIGINT to the coordinator, which ends the run
and writes what it has) and reports the simulated time reached; Ctrl-C does the same.
Exit code: 0 when the run ended well (or was stopped so), 1 when it failed (its stderr is in
OUT/convoy.stderr), 2 on bad input. The figures are printed in every case.
The run folder is kept in OUT (default: a new folder under /tmp) with the CSV.
"""
import argparse
import csv
import os
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
CITY = os.path.join(REPO, "experiments", "city_traffic")
sys.path.insert(0, HERE)
from machine import cpu_model  # noqa: E402

FIELDS = ["wall_s", "sim_s", "pid", "name", "rss_kib", "pss_kib", "anon_kib", "file_kib",
          "shmem_kib", "fds", "shm_fds", "shm_maps"]


def bad_input(message):
    """One clear message and exit code 2."""
    print("soak_bench: %s" % message, file=sys.stderr)
    sys.exit(2)


def children_map():
    """{ppid: [pid, ...]} of every live process."""
    kids = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                stat = f.read()
        except OSError:
            continue
        ppid = int(stat[stat.rfind(")") + 2:].split()[1])
        kids.setdefault(ppid, []).append(int(entry))
    return kids


def descendants(root):
    kids = children_map()
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(kids.get(pid, []))
    return out


def process_name(pid, root, run_dir, names):
    """The coordinator, an engine by its log file (logs/<engine>.log), or the program's name
    and its parent's (ffmpeg<recorder); `names` holds the names given so far (pid: name)."""
    if pid == root:
        return "coordinator"
    try:
        log = os.readlink("/proc/%d/fd/1" % pid)
    except OSError:
        log = ""
    logs = os.path.join(run_dir, "logs") + os.sep
    if log.startswith(logs) and log.endswith(".log"):
        name = log[len(logs):-4]
        if name != "coordinator":
            return name
    try:
        with open("/proc/%d/comm" % pid) as f:
            comm = f.read().strip()
        with open("/proc/%d/stat" % pid) as f:
            stat = f.read()
        ppid = int(stat[stat.rfind(")") + 2:].split()[1])
    except OSError:
        return "?"
    return "%s<%s" % (comm, names.get(ppid, ppid))


def read_kib(path, keys):
    vals = {}
    with open(path) as f:
        for line in f:
            k, _, rest = line.partition(":")
            if k in keys:
                vals[k] = int(rest.split()[0])
    return vals


def sample(pid):
    """One process's figures, or None when it has gone."""
    try:
        st = read_kib("/proc/%d/status" % pid, ("VmRSS", "RssAnon", "RssFile", "RssShmem"))
        pss = read_kib("/proc/%d/smaps_rollup" % pid, ("Pss",)).get("Pss", 0)
        fds = shm_fds = 0
        for fd in os.listdir("/proc/%d/fd" % pid):
            fds += 1
            try:
                target = os.readlink("/proc/%d/fd/%s" % (pid, fd))
            except OSError:
                continue
            if target.startswith("/memfd:") or target.startswith("/dev/shm/"):
                shm_fds += 1
        shm_maps = 0
        with open("/proc/%d/maps" % pid) as f:
            for line in f:
                if "/memfd:" in line or "/dev/shm/" in line:
                    shm_maps += 1
    except (OSError, ValueError):
        return None
    if "VmRSS" not in st:  # a zombie
        return None
    return {"rss_kib": st["VmRSS"], "pss_kib": pss, "anon_kib": st.get("RssAnon", 0),
            "file_kib": st.get("RssFile", 0), "shmem_kib": st.get("RssShmem", 0), "fds": fds,
            "shm_fds": shm_fds, "shm_maps": shm_maps}


def sim_time(run_dir):
    """The simulated time of the last whole line of steps.csv (0 before the loop)."""
    try:
        with open(os.path.join(run_dir, "steps.csv"), "rb") as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - 65536))
            lines = f.read().split(b"\n")
    except OSError:
        return 0.0
    for line in reversed(lines[:-1]):  # the last piece may be a line being written
        cells = line.split(b",")
        try:
            return float(cells[1])
        except (IndexError, ValueError):
            continue
    return 0.0


def soak(args, run_dir, csv_path):
    config = "simulation_config_density.json" if args.density else "simulation_config.json"
    cmd = [os.path.join(args.build, "bin", "convoy"), "run", "-q", "-c", config, "--run-dir",
           run_dir, "--record", "-o", "SimulationTimeout=%g" % args.sim_seconds]
    print("command (in %s): %s" % (os.path.relpath(args.experiment, REPO), " ".join(cmd)),
          flush=True)
    with open(os.path.join(os.path.dirname(run_dir), "convoy.stderr"), "w") as err:
        proc = subprocess.Popen(cmd, cwd=args.experiment, stdout=err, stderr=subprocess.STDOUT)
    t0 = time.monotonic()
    rows, stopping = [], False
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        try:
            while proc.poll() is None:
                wall = time.monotonic() - t0
                sim = sim_time(run_dir)
                names = {}
                for pid in descendants(proc.pid):  # parents before their children
                    s = sample(pid)
                    if s is None:
                        continue
                    names[pid] = process_name(pid, proc.pid, run_dir, names)
                    s.update(wall_s=round(wall, 1), sim_s=sim, pid=pid, name=names[pid])
                    rows.append(s)
                    w.writerow(s)
                f.flush()
                if args.max_wall and wall > args.max_wall and not stopping:
                    print("--max-wall %g s reached at %.0f simulated s: stopping the run"
                          % (args.max_wall, sim), flush=True)
                    proc.send_signal(signal.SIGINT)
                    stopping = True
                deadline = time.monotonic() + args.interval
                while proc.poll() is None and time.monotonic() < deadline:
                    time.sleep(0.2)
        except KeyboardInterrupt:
            print("interrupted: stopping the run", flush=True)
            proc.send_signal(signal.SIGINT)
            stopping = True
    try:
        rc = proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        rc = proc.wait()
    return rows, rc, time.monotonic() - t0, stopping


def growth_table(rows, warmup):
    """Per process (by name): first, baseline (last sample at or before the warm-up's end, or
    the first after it), last, and the largest value after the warm-up minus the baseline."""
    by_name = {}
    for r in rows:
        by_name.setdefault(r["name"], []).append(r)
    table = []
    for name, rs in by_name.items():
        before = [r for r in rs if r["sim_s"] <= warmup]
        after = [r for r in rs if r["sim_s"] > warmup]
        base = before[-1] if before else (after[0] if after else rs[0])
        if not after:
            after = [base]

        def grow(k):
            return max(r[k] for r in after) - base[k]
        table.append({"name": name, "pids": sorted({r["pid"] for r in rs}), "n": len(rs),
                      "first": rs[0], "base": base, "last": rs[-1],
                      "rss_growth": grow("rss_kib"), "pss_growth": grow("pss_kib"),
                      "shmem_growth": grow("shmem_kib"), "fds_growth": grow("fds"),
                      "shm_maps_growth": grow("shm_maps"), "after_warmup": len(after)})
    table.sort(key=lambda t: -t["rss_growth"])
    return table


def mib(kib):
    return kib / 1024.0


def report(table, warmup, sim_reached):
    print("per process (RSS MiB: first sample / end of the %g s warm-up / last sample; max "
          "growth after the warm-up; PSS and RssShmem growth MiB; open files and shared-memory "
          "mappings: last (growth))" % warmup)
    print("%-22s %8s %8s %8s %8s %8s %8s %10s %10s" % (
        "process", "start", "warm", "end", "growth", "pss+", "shmem+", "fds", "shm maps"))
    for t in table:
        f, b, l = t["first"], t["base"], t["last"]
        print("%-22s %8.1f %8.1f %8.1f %+8.2f %+8.2f %+8.2f %5d (%+d) %5d (%+d)" % (
            t["name"][:22], mib(f["rss_kib"]), mib(b["rss_kib"]), mib(l["rss_kib"]),
            mib(t["rss_growth"]), mib(t["pss_growth"]), mib(t["shmem_growth"]), l["fds"],
            t["fds_growth"], l["shm_maps"], t["shm_maps_growth"]))
    total_first = sum(t["first"]["pss_kib"] for t in table)
    total_last = sum(t["last"]["pss_kib"] for t in table)
    print("all processes: PSS %.1f MiB at the first sample, %.1f MiB at the last; %d processes; "
          "simulated time reached %.1f s" % (mib(total_first), mib(total_last), len(table),
                                            sim_reached))
    worst = max(table, key=lambda t: t["rss_growth"]) if table else None
    if worst is not None:
        print("largest growth: %s (%+.2f MiB RSS)" % (worst["name"], mib(worst["rss_growth"])))
    return max([mib(t["rss_growth"]) for t in table] + [0.0])


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sim-seconds", type=float, default=3600.0)
    ap.add_argument("--density", action="store_true",
                    help="the density run (simulation_config_density.json)")
    ap.add_argument("--interval", type=float, default=10.0, help="wall seconds between samples")
    ap.add_argument("--warmup", type=float, default=300.0,
                    help="simulated seconds before growth is measured")
    ap.add_argument("--max-wall", type=float, default=0.0,
                    help="stop the run after this many wall seconds (0: never)")
    ap.add_argument("--fail-above", type=float, default=0.0,
                    help="exit 1 when a process grew by this many MiB or more after the "
                         "warm-up, or did not pass it (0: report only); the soak test's check")
    ap.add_argument("--out", help="folder for the run and the CSV (default: new under /tmp)")
    ap.add_argument("--csv", help="samples CSV (default OUT/soak_samples.csv)")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--experiment", default=CITY,
                    help="the city_traffic folder (default experiments/city_traffic; another: "
                         "a changed copy, e.g. to check a fix)")
    args = ap.parse_args()
    args.experiment = os.path.abspath(args.experiment)
    if args.sim_seconds <= 0 or args.interval <= 0 or args.warmup < 0:
        bad_input("--sim-seconds and --interval must be > 0, --warmup >= 0")
    if not os.access(os.path.join(args.build, "bin", "convoy-engine-sumo"), os.X_OK):
        bad_input("%s has no convoy-engine-sumo (city_traffic needs SUMO)"
                 % os.path.join(args.build, "bin"))
    config = "simulation_config_density.json" if args.density else "simulation_config.json"
    if not os.path.isfile(os.path.join(args.experiment, config)):
        bad_input("no %s in %s" % (config, args.experiment))
    out = args.out or tempfile.mkdtemp(prefix="convoy-soak-")
    os.makedirs(out, exist_ok=True)
    run_dir = os.path.join(out, "run")
    if os.path.exists(run_dir):
        bad_input("%s exists; give another --out" % run_dir)
    csv_path = args.csv or os.path.join(out, "soak_samples.csv")
    print("soak: city_traffic%s with --record, %g simulated s, a sample every %g wall s; CPU %s"
          % (" (density run)" if args.density else "", args.sim_seconds, args.interval,
             cpu_model()), flush=True)
    # Ctrl-C and SIGTERM stop the run (also when started in the background, where SIGINT may
    # come ignored)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    rows, rc, wall, stopped = soak(args, run_dir, csv_path)
    sim = max([r["sim_s"] for r in rows] + [sim_time(run_dir)])
    print("run ended with exit code %d after %.0f wall s (%.1f simulated s, %.2fx real time); "
          "run folder %s; samples %s" % (rc, wall, sim, sim / wall if wall else 0.0, run_dir,
                                         csv_path))
    if sim <= args.warmup:
        print("warning: the run did not pass the %g s warm-up: growth is from the last sample"
              % args.warmup)
    worst = report(growth_table(rows, args.warmup), args.warmup, sim)
    print("max growth MiB: %.1f" % worst)
    if args.fail_above > 0 and (worst >= args.fail_above or sim <= args.warmup):
        print("FAILED: max growth %.1f MiB, the limit is < %g MiB" % (worst, args.fail_above))
        sys.exit(1)
    # stopped by --max-wall or Ctrl-C: the run ends as on Ctrl-C (exit 130), not a failure
    sys.exit(0 if rc == 0 or (stopped and rc == 130) else 1)


if __name__ == "__main__":
    main()
