"""Helpers for Convoy's end-to-end tests.

Each test builds a small experiment (config JSON, engine scripts, TF files) in a fresh temp
folder, runs the coordinator on it with `--run-dir <tmp>/run` and checks the exit code, the
message on stderr, the run folder and that no engine process outlives the run.

Engine scripts made with `engine_script()` write their pid to `<tmp>/pids/<name>.pid` when
the module is imported, and a marker `<tmp>/shutdown_<name>` in shutdown(), so that the tests
can check which processes ran and that they are gone.

Run with Debian's /usr/bin/python3. The binaries come from $CONVOY_BIN_DIR (default
<repo>/build/bin). Set CONVOY_E2E_KEEP=1 to keep the temp folders, CONVOY_E2E_SHOW=1 to print
every run's stderr.
"""

import json
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import textwrap
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
BIN_DIR = os.environ.get("CONVOY_BIN_DIR") or os.path.join(REPO, "build", "bin")
CONVOY = os.path.join(BIN_DIR, "convoy")
NRPCORESIM = os.path.join(BIN_DIR, "NRPCoreSim")

# A run of the coordinator that does not end by itself within this is a failure of its own.
RUN_TIMEOUT_S = 30.0


def engine_script(name, initialize="", run_loop="", shutdown="", imports="", extra=""):
    """Source of a python_json engine script that records its pid and its shutdown.

    `initialize`, `run_loop` and `shutdown` are code added to the methods of the same names
    (in run_loop, `timestep_ns` is the argument); the engine always registers a datapack
    `<name>_dp` holding its time.
    """
    ind = lambda code: textwrap.indent(textwrap.dedent(code).strip("\n"), " " * 8) if code.strip() else ""
    return textwrap.dedent("""\
        import os
        import sys
        import time
        {imports}
        from nrp_core.engines.python_json import EngineScript

        _HERE = os.path.dirname(os.path.abspath(__file__))
        os.makedirs(os.path.join(_HERE, "pids"), exist_ok=True)
        with open(os.path.join(_HERE, "pids", "{name}.pid"), "w") as _f:
            _f.write(str(os.getpid()))


        class Script(EngineScript):
            def initialize(self):
                self._registerDataPack("{name}_dp")
                self._setDataPack("{name}_dp", {{"time": self._time_ns}})
        {initialize}

            def runLoop(self, timestep_ns):
                self._setDataPack("{name}_dp", {{"time": self._time_ns}})
        {run_loop}

            def shutdown(self):
                with open(os.path.join(_HERE, "shutdown_{name}"), "w") as _f:
                    _f.write("shutdown")
        {shutdown}
        {extra}
        """).format(name=name, imports=imports, initialize=ind(initialize),
                    run_loop=ind(run_loop), shutdown=ind(shutdown), extra=extra)


RELAY_TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *


    @EngineDataPack(keyword='dp', id=DataPackIdentifier('{src}_dp', '{src}'))
    @TransceiverFunction("{dst}")
    def {fname}(dp):
    {body}
        return []
    """)


def relay_tf(src="python_1", dst="python_2", body="", fname="relay"):
    """A TF that reads engine `src`'s datapack and runs `body` (indented code, may use dp)."""
    body = textwrap.indent(textwrap.dedent(body).strip("\n"), "    ") if body.strip() else "    pass"
    return RELAY_TF.format(src=src, dst=dst, body=body, fname=fname)


def basic_config(engines=("python_1", "python_2"), timeout=0.2, timestep=None, tfs=(), **extra):
    cfg = {
        "SimulationName": "e2e",
        "SimulationTimeout": timeout,
        "EngineConfigs": [],
        "DataPackProcessingFunctions": [{"Name": n, "FileName": f} for n, f in tfs],
    }
    for name in engines:
        ec = {"EngineType": "python_json", "EngineName": name, "PythonFileName": name + ".py"}
        if timestep is not None:
            ec["EngineTimestep"] = timestep
        cfg["EngineConfigs"].append(ec)
    cfg.update(extra)
    return cfg


class Result:
    def __init__(self, proc, out, err, wall):
        self.code = proc.returncode
        self.pid = proc.pid
        self.stdout = out
        self.stderr = err
        self.wall = wall

    def __repr__(self):
        return "exit %s after %.2f s\n--- stderr ---\n%s\n--- stdout ---\n%s" % (
            self.code, self.wall, self.stderr, self.stdout)


def free_port():
    """A TCP port on the loopback that nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def pid_alive(pid):
    """True if `pid` exists and is not a zombie."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            stat = f.read()
    except (FileNotFoundError, ProcessLookupError):
        return False
    state = stat[stat.rfind(")") + 2:].split()[0]
    return state not in ("Z", "X")


class E2ETestCase(unittest.TestCase):
    """Gives each test a temp experiment folder and runs the coordinator there."""

    maxDiff = None

    @classmethod
    def setUpClass(cls):
        if not os.access(CONVOY, os.X_OK):
            raise unittest.SkipTest("no coordinator at %s (set CONVOY_BIN_DIR)" % CONVOY)

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="convoy-e2e-%s-" % self._testMethodName)
        self.run_dir = os.path.join(self.dir, "run")
        self._procs = []

    def tearDown(self):
        # Whatever happened, leave nothing behind.
        for p in self._procs:
            if p.poll() is None:
                p.kill()
            p.communicate()
        for pid in self.engine_pids().values():
            if pid_alive(pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        for pid in self.scan_engine_processes():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        if os.environ.get("CONVOY_E2E_KEEP"):
            print("\n[kept %s]" % self.dir)
        else:
            shutil.rmtree(self.dir, ignore_errors=True)

    # -- building experiments ------------------------------------------------------------------

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(text if isinstance(text, str) else json.dumps(text, indent=2))
        return path

    def write_config(self, cfg, name="simulation_config.json"):
        return self.write(name, cfg)

    # -- running -------------------------------------------------------------------------------

    def start(self, args, binary=None, config="simulation_config.json", run_dir=True):
        cmd = [binary or CONVOY]
        if binary is None or binary == CONVOY:
            cmd.append("run")
        cmd += ["-c", os.path.join(self.dir, config)]
        if run_dir:
            cmd += ["--run-dir", self.run_dir]
        cmd += list(args)
        t0 = time.monotonic()
        p = subprocess.Popen(cmd, cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             stdin=subprocess.DEVNULL, text=True)
        p._t0 = t0
        self._procs.append(p)
        return p

    def finish(self, p, timeout=RUN_TIMEOUT_S):
        try:
            out, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            out, err = p.communicate()
            self.fail("coordinator did not end within %.0f s\n--- stderr ---\n%s" % (timeout, err))
        r = Result(p, out, err, time.monotonic() - p._t0)
        if os.environ.get("CONVOY_E2E_SHOW"):
            print("\n[%s] %s" % (self._testMethodName, r))
        return r

    def run_convoy(self, *args, binary=None, timeout=RUN_TIMEOUT_S, run_dir=True):
        return self.finish(self.start(args, binary=binary, run_dir=run_dir), timeout)

    # -- inspecting ----------------------------------------------------------------------------

    def engine_pids(self):
        """{engine name: pid} from the pid files the engine scripts wrote."""
        pids = {}
        d = os.path.join(self.dir, "pids")
        if os.path.isdir(d):
            for f in os.listdir(d):
                try:
                    with open(os.path.join(d, f)) as fh:
                        pids[f[:-4]] = int(fh.read().strip())
                except (ValueError, OSError):
                    pass
        return pids

    def scan_engine_processes(self):
        """Pids of live processes started for this experiment: their working folder or their
        command line is in the temp folder."""
        found = []
        me = os.getpid()
        for entry in os.listdir("/proc"):
            if not entry.isdigit() or int(entry) == me:
                continue
            pid = int(entry)
            try:
                cwd = os.readlink("/proc/%d/cwd" % pid)
                with open("/proc/%d/cmdline" % pid, "rb") as f:
                    cmdline = f.read().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if (cwd == self.dir or cwd.startswith(self.dir + "/") or self.dir in cmdline) \
                    and pid_alive(pid) and not any(p.pid == pid for p in self._procs):
                found.append(pid)
        return found

    def assertExit(self, r, code):
        self.assertEqual(r.code, code, "expected exit %d, got: %r" % (code, r))

    def assertStderrHas(self, r, *needles):
        for n in needles:
            self.assertIn(n, r.stderr, "stderr lacks %r: %r" % (n, r))

    def assertOneError(self, r):
        """Exactly one "error:" message on stderr (it may span several lines)."""
        n = len(re.findall(r"(?m)^error:", r.stderr))
        self.assertEqual(n, 1, "expected one error message, got %d: %r" % (n, r))

    def assertNoEngineLeft(self, within=2.0, expect_pids=()):
        """Every engine process is gone (after at most `within` s)."""
        pids = self.engine_pids()
        for name in expect_pids:
            self.assertIn(name, pids, "engine %s never started (no pid file)" % name)
        deadline = time.monotonic() + within
        while True:
            alive = {n: p for n, p in pids.items() if pid_alive(p)}
            strays = [p for p in self.scan_engine_processes() if p not in alive.values()]
            if not alive and not strays:
                return
            if time.monotonic() >= deadline:
                self.fail("processes left behind: engines %s, others %s" % (alive, strays))
            time.sleep(0.02)

    def assertLogsKept(self, *engines):
        logs = os.path.join(self.run_dir, "logs")
        self.assertTrue(os.path.isfile(os.path.join(logs, "coordinator.log")),
                        "no %s/coordinator.log" % logs)
        for e in engines:
            self.assertTrue(os.path.isfile(os.path.join(logs, e + ".log")),
                            "no %s/%s.log" % (logs, e))

    def summary(self):
        with open(os.path.join(self.run_dir, "summary.json")) as f:
            return json.load(f)

    def read_log(self, name):
        with open(os.path.join(self.run_dir, "logs", name + ".log")) as f:
            return f.read()


def start_local_slurm(cls, prefix):
    """A one-node Slurm cluster for a test class (tools/campaign/slurm_local.sh in a temp
    folder, stopped and removed when the class is done): the environment that reaches it, or
    SkipTest without sbatch."""
    if shutil.which("sbatch") is None:
        raise unittest.SkipTest("sbatch is not installed (scripts/setup.sh installs Slurm)")
    script = os.path.join(REPO, "tools", "campaign", "slurm_local.sh")
    cls.scratch = tempfile.mkdtemp(prefix=prefix)
    cls.addClassCleanup(shutil.rmtree, cls.scratch, True)
    cls.addClassCleanup(subprocess.run, [script, "stop", cls.scratch],
                        stdin=subprocess.DEVNULL, capture_output=True, timeout=60)
    for _ in range(2):  # the second start finds it running
        r = subprocess.run([script, "start", cls.scratch], stdin=subprocess.DEVNULL,
                           capture_output=True, text=True, timeout=90)
        if r.returncode != 0:
            raise AssertionError("slurm_local.sh start failed:\n%s%s" % (r.stdout, r.stderr))
    return {"SLURM_CONF": os.path.join(cls.scratch, "slurm.conf")}
