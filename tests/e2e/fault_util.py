"""Fault injection for Convoy's end-to-end tests (tests/e2e/test_faults.py; docs/faults.md).

A fault run starts the coordinator on an experiment, waits until steps.csv holds k rows (the
loop finished k cycles), then injects the fault: SIGKILL of one engine (found among the
coordinator's children by the log file its stdout goes to), of a remote engine's server, of
the coordinator itself, or the loss of a remote engine's connection (a TCP relay that cuts
both sides at once). Afterwards it collects what it finds:

- the exit code and the "error:" messages on stderr;
- the run folder: summary.json (whole JSON), steps.csv (every line whole, at least the rows
  seen before the fault), logs/ (the coordinator's and each engine's), camera.mp4 (read by
  ffprobe, when the experiment makes one), recording.mcap (read by python/convoy_mcap);
- leftovers: processes (the engines' pids and process groups, anything whose environment
  names the run folder or whose command line names it, e.g. ffmpeg), new entries in /dev/shm
  holding the run's pids or named convoy, socket files and temporary files in the run folder
  and the experiment folder, and new entries of the temp folder named after a pid of the run.

Kill steps are drawn from random.Random(seed) with the seed printed (CONVOY_FAULT_SEED sets it).
The default test run tries the first step drawn for each fault; the full set (test_faults.py's
*Full groups, label `long`) tries all of them.
"""

import glob
import json
import os
import random
import re
import shutil
import signal
import socket
import stat
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))

from convoy_mcap.reader import McapError, Recording  # noqa: E402

SEED = int(os.environ.get("CONVOY_FAULT_SEED", "30"))
EXIT_ENGINE = 3
# Processes that finish on their own after the coordinator ends (ffmpeg completing camera.mp4
# from the frames it got) have this long.
LEFTOVER_GRACE_S = 10.0
# The recorder closes a chunk after 1 s of wall time at most (src/record/mcap_writer.h): a
# coordinator killed after twice that has left at least one whole chunk.
CHUNK_S_MAX = 2.0
TEMP_PATTERNS = ("*.tmp", "*.tmp-*", "*.tmp.*", "*.*.tmp", "*.partial*", "*~", ".nfs*")


def kill_steps(what, n, low=3, high=40, take=None):
    """n distinct steps in [low, high) for `what`, from the printed seed; with `take`, only
    the first `take` of those n as drawn (the default test run's subset of the full set)."""
    drawn = random.Random("%d-%s" % (SEED, what)).sample(range(low, high), n)
    return sorted(drawn[:take] if take else drawn)


def pid_alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            st = f.read()
    except OSError:
        return False
    return st[st.rfind(")") + 2:].split()[0] not in ("Z", "X")


def _stat_fields(pid):
    with open("/proc/%d/stat" % pid) as f:
        st = f.read()
    return st[st.rfind(")") + 2:].split()  # [state, ppid, pgrp, session, ...]


def _pids():
    return [int(e) for e in os.listdir("/proc") if e.isdigit()]


def children(pid):
    out = []
    for p in _pids():
        try:
            if int(_stat_fields(p)[1]) == pid:
                out.append(p)
        except (OSError, IndexError, ValueError):
            continue
    return out


def engine_pids(coordinator_pid, run_dir):
    """{engine name: pid}: the coordinator's children whose stdout is logs/<name>.log."""
    logs = os.path.join(run_dir, "logs") + "/"
    out = {}
    for p in children(coordinator_pid):
        try:
            target = os.readlink("/proc/%d/fd/1" % p)
        except OSError:
            continue
        if target.startswith(logs) and target.endswith(".log"):
            out[target[len(logs):-4]] = p
    return out


def run_processes(run_dir, also=()):
    """Live pids whose environment or command line names run_dir, or in the groups `also`."""
    key = run_dir.encode()
    found = []
    me = os.getpid()
    for p in _pids():
        if p == me:
            continue
        try:
            with open("/proc/%d/environ" % p, "rb") as f:
                env = f.read()
            with open("/proc/%d/cmdline" % p, "rb") as f:
                cmd = f.read()
            pgrp = int(_stat_fields(p)[2])
        except (OSError, IndexError, ValueError):
            continue
        if (b"CONVOY_RUN_DIR=" + key in env.split(b"\0") or key in cmd or pgrp in also) \
                and pid_alive(p):
            found.append(p)
    return found


def describe(pid):
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as f:
            return "%d %s" % (pid, f.read().replace(b"\0", b" ").decode(errors="replace")[:120])
    except OSError:
        return str(pid)


def shm_entries():
    try:
        return set(os.listdir("/dev/shm"))
    except OSError:
        return set()


def tmp_entries():
    d = tempfile.gettempdir()
    try:
        return {os.path.join(d, e) for e in os.listdir(d)}
    except OSError:
        return set()


class Relay:
    """A TCP relay on the loopback (port chosen by the OS) to `target_port`; cut() closes the
    listening socket and every connection with a reset, as a lost network would."""

    def __init__(self, target_port):
        self.target = ("127.0.0.1", target_port)
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(16)
        self.port = self.listener.getsockname()[1]
        self.socks = []
        self.lock = threading.Lock()
        self.cut_done = False
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                a, _ = self.listener.accept()
            except OSError:
                return
            try:
                b = socket.create_connection(self.target)
            except OSError:
                a.close()
                continue
            with self.lock:
                if self.cut_done:
                    a.close()
                    b.close()
                    return
                self.socks += [a, b]
            for src, dst in ((a, b), (b, a)):
                threading.Thread(target=self._pump, args=(src, dst), daemon=True).start()

    @staticmethod
    def _pump(src, dst):
        try:
            while True:
                data = src.recv(65536)
                if not data:
                    break
                dst.sendall(data)
        except OSError:
            pass
        try:
            dst.shutdown(socket.SHUT_WR)
        except OSError:
            pass

    def cut(self):
        with self.lock:
            self.cut_done = True
            socks, self.socks = self.socks, []
        try:
            self.listener.close()
        except OSError:
            pass
        for s in socks:
            try:
                s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\1\0\0\0\0\0\0\0")
                s.close()
            except OSError:
                pass


class FaultRun:
    """One run of the coordinator with one fault. `cmd` is the command (convoy run ...),
    `cwd` the experiment folder, `run_dir` the run folder (named in cmd)."""

    def __init__(self, cmd, cwd, run_dir, label):
        self.cmd, self.cwd, self.run_dir, self.label = cmd, cwd, run_dir, label
        self.findings = []   # what is wrong
        self.notes = []      # what was found and is right
        self.killed = None
        self.rows_at_kill = 0
        self.shm_before = shm_entries()
        self.tmp_before = tmp_entries()
        self.out_path = run_dir + ".stdout"
        self.err_path = run_dir + ".stderr"
        with open(self.out_path, "w") as out, open(self.err_path, "w") as err:
            self.proc = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=err,
                                         stdin=subprocess.DEVNULL)
        self.t0 = time.monotonic()
        self.engines = {}
        self.groups = set()
        self.seen = set()   # every pid of the run seen alive

    # -- waiting and killing -------------------------------------------------------------------

    def rows(self):
        try:
            with open(os.path.join(self.run_dir, "steps.csv"), "rb") as f:
                return max(0, f.read().count(b"\n") - 1)
        except OSError:
            return 0

    def wait_rows(self, k, timeout=60.0):
        """Waits until steps.csv has k rows; False if the run ended or took too long."""
        deadline = time.monotonic() + timeout
        while True:
            n = self.rows()
            if n >= 1 and not self.engines:
                self._look()  # every engine runs before the first step
                self.note_others()
            if n >= k:
                break
            if self.proc.poll() is not None or time.monotonic() > deadline:
                return False
            time.sleep(0.001)
        return True

    def _look(self):
        """Notes the run's engines and their groups (and whatever else runs for it)."""
        if self.proc.poll() is not None:
            return
        for name, pid in engine_pids(self.proc.pid, self.run_dir).items():
            self.engines.setdefault(name, pid)
            try:
                self.groups.add(int(_stat_fields(pid)[2]))
            except (OSError, IndexError, ValueError):
                pass
        self.seen.update(self.engines.values())

    def note_others(self):
        self.seen.update(run_processes(self.run_dir, self.groups))

    def kill_at(self, k, what, pid_of):
        """At step k, SIGKILLs the pid `pid_of()` returns; `what` says what it is."""
        if not self.wait_rows(k):
            self.findings.append("the run ended or stalled before step %d (%d rows): %s"
                                 % (k, self.rows(), self._stderr_tail()))
            return False
        pid = pid_of()
        if not pid:
            self.findings.append("no pid for %s (engines seen: %s)" % (what, sorted(self.engines)))
            return False
        self.rows_at_kill = self.rows()
        os.kill(pid, signal.SIGKILL)
        self.killed = "%s (pid %d) at step %d" % (what, pid, self.rows_at_kill)
        return True

    def act_at(self, k, what, action):
        if not self.wait_rows(k):
            self.findings.append("the run ended or stalled before step %d (%d rows): %s"
                                 % (k, self.rows(), self._stderr_tail()))
            return False
        self.rows_at_kill = self.rows()
        action()
        self.killed = "%s at step %d" % (what, self.rows_at_kill)
        return True

    def _stderr_tail(self):
        with open(self.err_path, errors="replace") as f:
            return f.read()[-600:]

    def finish(self, timeout=60.0):
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            self.findings.append("the coordinator did not end within %.0f s" % timeout)
        self.wall = time.monotonic() - self.t0
        with open(self.err_path, errors="replace") as f:
            self.stderr = f.read()
        self.code = self.proc.returncode
        return self

    # -- checks --------------------------------------------------------------------------------

    def check_exit(self, code):
        if self.code != code:
            self.findings.append("exit %s, expected %d" % (self.code, code))
        else:
            self.notes.append("exit %d" % code)

    def check_one_message(self, engine):
        errors = [line for line in self.stderr.splitlines() if line.startswith("error:")]
        if len(errors) != 1:
            self.findings.append("%d error messages, expected one: %r"
                                 % (len(errors), self.stderr[-2000:]))
        elif "'%s'" % engine not in errors[0]:
            self.findings.append("the message does not name engine '%s': %s" % (engine, errors[0]))
        else:
            self.notes.append("one message: %s" % errors[0][:110])

    def check_summary(self, ended=True):
        path = os.path.join(self.run_dir, "summary.json")
        try:
            with open(path) as f:
                s = json.load(f)
        except (OSError, ValueError) as e:
            self.findings.append("summary.json unreadable: %s" % e)
            return None
        state = s.get("state")
        if ended and (state != "ended" or s.get("exit_code") != self.code):
            self.findings.append("summary.json: state %r, exit_code %r (exit %s)"
                                 % (state, s.get("exit_code"), self.code))
        elif not ended and state not in ("running", "ended"):
            self.findings.append("summary.json: state %r" % state)
        else:
            self.notes.append("summary.json %s" % state)
        return s

    def check_steps(self):
        path = os.path.join(self.run_dir, "steps.csv")
        try:
            with open(path) as f:
                text = f.read()
        except OSError as e:
            self.findings.append("steps.csv unreadable: %s" % e)
            return
        lines = text.split("\n")
        if lines and lines[-1] == "":
            lines.pop()
        elif lines:
            self.findings.append("steps.csv: its last line is cut: %r" % lines.pop()[-40:])
        width = len(lines[0].split(",")) if lines else 0
        bad = [i for i, line in enumerate(lines) if len(line.split(",")) != width]
        if bad:
            self.findings.append("steps.csv: lines %s are not whole" % bad[:5])
        if len(lines) - 1 < self.rows_at_kill:
            self.findings.append("steps.csv: %d rows, %d were there at the fault"
                                 % (len(lines) - 1, self.rows_at_kill))
        else:
            self.notes.append("steps.csv %d rows" % (len(lines) - 1))

    def check_logs(self, engines):
        logs = os.path.join(self.run_dir, "logs")
        missing = [n for n in ("coordinator",) + tuple(engines)
                   if not os.path.isfile(os.path.join(logs, n + ".log"))]
        if missing:
            self.findings.append("logs missing: %s" % missing)
            return
        try:
            with open(os.path.join(logs, "coordinator.log"), errors="replace") as f:
                log = f.read()
        except OSError as e:
            self.findings.append("coordinator.log unreadable: %s" % e)
            return
        if "run folder:" not in log:
            self.findings.append("coordinator.log lacks its first line")
        self.notes.append("logs/ %d files" % len(os.listdir(logs)))

    def check_video(self):
        path = os.path.join(self.run_dir, "camera.mp4")
        if shutil.which("ffprobe") is None:
            self.notes.append("camera.mp4 not read (no ffprobe)")
            return
        if not os.path.exists(path):
            self.findings.append("no camera.mp4")
            return
        r = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                            "-show_entries", "stream=codec_name,nb_read_frames", "-of", "json",
                            path], capture_output=True, text=True, timeout=60)
        try:
            stream = json.loads(r.stdout)["streams"][0]
            frames = int(stream["nb_read_frames"])
        except (ValueError, KeyError, IndexError):
            self.findings.append("camera.mp4 unreadable: %s" % r.stderr.strip()[:300])
            return
        if r.returncode != 0 or frames < 1:
            self.findings.append("camera.mp4: %d frames, ffprobe: %s" % (frames, r.stderr[:300]))
        else:
            self.notes.append("camera.mp4 %d frames (%s)" % (frames, stream.get("codec_name")))

    def loop_wall_s(self):
        """The loop's wall time in steps.csv (its cycle_wall_us column)."""
        try:
            with open(os.path.join(self.run_dir, "steps.csv")) as f:
                rows = [line.split(",") for line in f.read().split("\n")[1:] if line]
            return sum(float(r[2]) for r in rows if len(r) > 2) * 1e-6
        except (OSError, ValueError):
            return 0.0

    def check_recording(self, finished=True):
        """recording.mcap read by the project's reader (python/convoy_mcap). A run that ended
        finishes the file; a killed coordinator leaves the chunks it wrote whole (the open
        one is lost, so there may be none yet)."""
        path = os.path.join(self.run_dir, "recording.mcap")
        try:
            rec = Recording(path)
            n = sum(1 for _ in rec.messages())
        except (McapError, OSError) as e:
            self.findings.append("recording.mcap unreadable by convoy_mcap: %s" % e)
            return
        chunks = rec.records.get("Chunk", 0)
        loop_s = self.loop_wall_s()
        if not finished and loop_s >= CHUNK_S_MAX and chunks == 0:
            self.findings.append("recording.mcap: no whole chunk after %.1f s of loop (a chunk "
                                 "closes after %.0f s at most)" % (loop_s, CHUNK_S_MAX / 2))
        elif finished and not rec.complete:
            self.findings.append("recording.mcap not finished: %s" % rec.incomplete)
        elif finished and n == 0:
            self.findings.append("recording.mcap: no messages")
        else:
            self.notes.append("recording.mcap %d messages in %d chunks%s" % (
                n, chunks, "" if rec.complete else " (up to the cut)"))

    def check_leftovers(self, extra_pids=()):
        """Waits (LEFTOVER_GRACE_S at most) for every process of the run to end, then checks
        shared memory, sockets and temporary files."""
        deadline = time.monotonic() + LEFTOVER_GRACE_S
        while True:
            alive = sorted(set(p for p in self.seen | set(extra_pids) if pid_alive(p)) |
                           set(run_processes(self.run_dir, self.groups)))
            if not alive or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        waited = LEFTOVER_GRACE_S - max(0.0, deadline - time.monotonic())
        if alive:
            self.findings.append("processes left: %s" % [describe(p) for p in alive])
            for p in alive:
                try:
                    os.kill(p, signal.SIGKILL)
                except OSError:
                    pass
        else:
            self.notes.append("no process left (%d seen, %.1f s)" % (len(self.seen), waited))
        pids = {str(p) for p in self.seen | {self.proc.pid}}
        new_shm = [e for e in shm_entries() - self.shm_before
                   if "convoy" in e.lower() or any(p in e for p in pids)]
        if new_shm:
            self.findings.append("/dev/shm entries left: %s" % new_shm)
        left = []
        for root in {self.run_dir, self.cwd}:
            for dirpath, _, files in os.walk(root):
                for name in files:
                    path = os.path.join(dirpath, name)
                    try:
                        st = os.lstat(path)
                    except OSError:
                        continue
                    if stat.S_ISSOCK(st.st_mode) or stat.S_ISFIFO(st.st_mode):
                        left.append(path)
                for pattern in TEMP_PATTERNS:
                    left += glob.glob(os.path.join(glob.escape(dirpath), pattern))
        # Temporary files elsewhere: new entries of the temp folder named after a pid of the run.
        tokens = re.compile(r"(?<!\d)(%s)(?!\d)" % "|".join(sorted(pids)))
        left += [e for e in tmp_entries() - self.tmp_before
                 if tokens.search(os.path.basename(e))]
        with open("/proc/net/unix") as f:
            left += [line.split()[-1] for line in f
                     if line.split()[-1].startswith((self.run_dir, self.cwd))]
        if left:
            self.findings.append("socket or temporary files left: %s" % sorted(set(left)))
        else:
            self.notes.append("no shm, socket or temp file")

    def report(self, show=True):
        """One line: what was killed and what was found (printed unless show is False)."""
        verdict = "OK" if not self.findings else "FAILED"
        what = "; ".join(self.findings) if self.findings else ", ".join(self.notes)
        line = "[fault %s] %s: killed %s -> %s (%.1f s): %s" % (
            verdict, self.label, self.killed or "nothing", "exit %s" % self.code, self.wall, what)
        if show:
            print(line, flush=True)
        return line
