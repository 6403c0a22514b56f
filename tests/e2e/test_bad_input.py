"""End-to-end tests of the coordinator on bad input, failing engines and signals.

Each test writes a small experiment into a temp folder, runs `convoy run` (from
$CONVOY_BIN_DIR) with `--run-dir <tmp>/run`, and checks:
  (a) the exit code: 2 user error, 3 engine error, 4 TF error, 130 interrupted;
  (b) one clear message on stderr naming the file / JSON pointer / engine / TF, with the
      Python traceback where there is one;
  (c) no engine process is left behind;
  (d) the run folder keeps logs/coordinator.log and the logs of the engines that started.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_bad_input
Keep the temp folders:  CONVOY_E2E_KEEP=1
"""

import csv
import json
import os
import re
import signal
import time
import unittest

from e2e_util import (E2ETestCase, NRPCORESIM, basic_config, engine_script, pid_alive,
                      relay_tf)

EXIT_USER, EXIT_ENGINE, EXIT_FUNCTION, EXIT_INTERRUPTED = 2, 3, 4, 130


class ExperimentMixin:
    """Writes the usual two-engine experiment, with the given pieces replaced."""

    def experiment(self, cfg=None, engines=None, tfs=None, **cfg_args):
        engines = dict(engines or {})
        for name in ("python_1", "python_2"):
            engines.setdefault(name, engine_script(name))
        for name, src in engines.items():
            if src is not None:
                self.write(name + ".py", src)
        for fname, src in (tfs or {}).items():
            self.write(fname, src)
        if cfg is None:
            cfg = basic_config(**cfg_args)
        self.write_config(cfg)
        return cfg


# ---------------------------------------------------------------------------------------------
# Config errors: exit 2 before any engine starts
# ---------------------------------------------------------------------------------------------

class ConfigErrors(ExperimentMixin, E2ETestCase):

    def check_config_error(self, r, *needles):
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, *needles)
        self.assertOneError(r)
        self.assertEqual(self.engine_pids(), {}, "no engine should have started")
        self.assertNoEngineLeft()
        # A config error is found before the run starts: only the message on stderr is asked
        # for, and no engine log may exist.
        logs = os.path.join(self.run_dir, "logs")
        if os.path.isdir(logs):
            self.assertEqual([f for f in os.listdir(logs) if f != "coordinator.log"], [])

    def test_missing_config_file(self):
        r = self.run_convoy()  # simulation_config.json was never written
        self.check_config_error(r, os.path.join(self.dir, "simulation_config.json"))

    def test_malformed_json(self):
        self.experiment()
        text = ('{\n'
                '    "SimulationName": "e2e",\n'
                '    "SimulationTimeout": 0.1,\n'
                '    "EngineConfigs": [\n'
                '        {"EngineType": "python_json", "EngineName": "python_1",\n'
                '         "PythonFileName": "python_1.py",}\n'   # trailing comma: line 6
                '    ]\n'
                '}\n')
        self.write("simulation_config.json", text)
        r = self.run_convoy()
        self.check_config_error(r, "simulation_config.json")
        self.assertRegex(r.stderr, r"(?i)line\D{0,3}6", "message gives the line: %r" % r)
        self.assertRegex(r.stderr, r"(?i)column\D{0,3}\d+", "message gives the column: %r" % r)

    def test_wrong_type_timestep(self):
        self.experiment(timestep="abc")
        r = self.run_convoy()
        self.check_config_error(r, "simulation_config.json", "/EngineConfigs/0/EngineTimestep")
        self.assertIn("abc", r.stderr)

    def test_nonpositive_timestep(self):
        for bad in (0, -0.01):
            with self.subTest(timestep=bad):
                cfg = self.experiment()
                cfg["EngineConfigs"][1]["EngineTimestep"] = bad
                self.write_config(cfg)
                r = self.run_convoy()
                self.check_config_error(r, "simulation_config.json",
                                        "/EngineConfigs/1/EngineTimestep")

    def test_unknown_engine_type(self):
        cfg = self.experiment()
        cfg["EngineConfigs"][1]["EngineType"] = "no_such_engine"
        self.write_config(cfg)
        r = self.run_convoy()
        self.check_config_error(r, "simulation_config.json", "/EngineConfigs/1/EngineType",
                                "no_such_engine")

    def test_duplicate_engine_name(self):
        cfg = self.experiment()
        cfg["EngineConfigs"][1]["EngineName"] = "python_1"
        self.write_config(cfg)
        r = self.run_convoy()
        self.check_config_error(r, "simulation_config.json", "python_1", "/EngineConfigs/1")
        self.assertRegex(r.stderr, r"(?i)duplicate|more than once|already|twice|unique")

    def test_missing_engine_script(self):
        cfg = self.experiment()
        cfg["EngineConfigs"][1]["PythonFileName"] = "no_such_script.py"
        self.write_config(cfg)
        r = self.run_convoy()
        self.check_config_error(r, "no_such_script.py", "/EngineConfigs/1/PythonFileName")

    def test_bad_override(self):
        self.experiment()
        for bad, needle in (("SimulationTimeout=abc", "SimulationTimeout"),
                            ("EngineConfigs/7/EngineTimestep=0.1", "EngineConfigs/7"),
                            ("NoEqualsSign", "NoEqualsSign")):
            with self.subTest(override=bad):
                r = self.run_convoy("-o", bad)
                self.check_config_error(r, needle)

    def test_missing_tf_file(self):
        self.experiment(cfg=basic_config(tfs=[("tf_missing", "no_such_tf.py")], timeout=0.1))
        r = self.run_convoy()
        self.check_config_error(r, "no_such_tf.py", "/DataPackProcessingFunctions/0/FileName")

    def test_engine_program_not_found(self):
        cfg = self.experiment()
        cfg["EngineConfigs"][1]["EngineProcCmd"] = os.path.join(self.dir, "no_such_engine_bin")
        self.write_config(cfg)
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "no_such_engine_bin", "python_2")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertLogsKept()
        self.assertEqual(self.summary()["exit_code"], EXIT_USER)


# ---------------------------------------------------------------------------------------------
# Errors in the user's Python: scripts and TFs
# ---------------------------------------------------------------------------------------------

class PythonErrors(ExperimentMixin, E2ETestCase):

    def test_engine_script_syntax_error(self):
        src = engine_script("python_2") + "\ndef broken(:\n    pass\n"
        self.experiment(engines={"python_2": src}, timeout=0.1)
        r = self.run_convoy()
        # The script is the user's input; an error in it is reported like an engine failure
        # (the engine cannot initialize) or a user error. Either way it must name the engine,
        # the file and the SyntaxError.
        self.assertIn(r.code, (EXIT_USER, EXIT_ENGINE), repr(r))
        self.assertStderrHas(r, "python_2", "python_2.py", "SyntaxError")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertLogsKept("python_1", "python_2")

    def test_engine_script_without_script_class(self):
        src = "import os\nclass NotAnEngine:\n    pass\n"
        self.experiment(engines={"python_2": src}, timeout=0.1)
        r = self.run_convoy()
        self.assertIn(r.code, (EXIT_USER, EXIT_ENGINE), repr(r))
        self.assertStderrHas(r, "python_2", "python_2.py", "Script")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertLogsKept("python_1", "python_2")

    def test_engine_initialize_exception(self):
        src = engine_script("python_2", initialize='raise RuntimeError("init boom 1234")')
        self.experiment(engines={"python_2": src}, timeout=0.1)
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "python_2", "Traceback", "RuntimeError", "init boom 1234",
                             "python_2.py")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        s = self.summary()
        self.assertEqual(s["exit_code"], EXIT_ENGINE)
        self.assertIn("init boom 1234", s["error"])

    def test_engine_runloop_exception(self):
        src = engine_script("python_2", run_loop="""
            if self._time_ns >= 50_000_000:
                raise ValueError("runloop boom at %d" % self._time_ns)
            """)
        self.experiment(engines={"python_2": src}, timeout=1.0)
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "python_2", "Traceback", "ValueError",
                             "runloop boom at 50000000", "python_2.py")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        # The healthy engine was shut down properly.
        self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_python_1")),
                        "python_1's shutdown() did not run")
        s = self.summary()
        self.assertEqual(s["exit_code"], EXIT_ENGINE)
        self.assertLess(s["sim_time_s"], 0.1)

    def test_tf_exception(self):
        tf = relay_tf(fname="faulty_relay", body="""
            if dp.data["time"] >= 50_000_000:
                raise KeyError("tf boom %d" % dp.data["time"])
            """)
        self.experiment(engines={}, tfs={"tf_faulty.py": tf},
                        cfg=basic_config(tfs=[("tf_faulty", "tf_faulty.py")], timeout=1.0))
        r = self.run_convoy()
        self.assertExit(r, EXIT_FUNCTION)
        self.assertStderrHas(r, "faulty_relay", "tf_faulty.py", "Traceback", "KeyError",
                             "tf boom 50000000")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        for e in ("python_1", "python_2"):
            self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_" + e)),
                            "%s's shutdown() did not run" % e)
        self.assertEqual(self.summary()["exit_code"], EXIT_FUNCTION)

    def test_tf_syntax_error(self):
        tf = relay_tf() + "\nif True\n    pass\n"
        self.experiment(engines={}, tfs={"tf_bad.py": tf},
                        cfg=basic_config(tfs=[("tf_bad", "tf_bad.py")], timeout=0.1))
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "tf_bad.py", "tf_bad", "SyntaxError", "if True")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertEqual(self.engine_pids(), {}, "engines started despite the bad TF")
        self.assertLogsKept()
        self.assertEqual(self.summary()["exit_code"], EXIT_USER)

    def test_tf_unknown_engine_in_decorator(self):
        tf = relay_tf(dst="nope")
        self.experiment(engines={}, tfs={"tf_1.py": tf},
                        cfg=basic_config(tfs=[("relay_tf", "tf_1.py")], timeout=0.1))
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "tf_1.py", '"nope"', "relay_tf")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertEqual(self.engine_pids(), {}, "engines started despite the bad TF")
        self.assertLogsKept()
        self.assertEqual(self.summary()["exit_code"], EXIT_USER)

    def test_tf_unknown_engine_in_datapack_id(self):
        tf = relay_tf(src="nope")
        self.experiment(engines={}, tfs={"tf_1.py": tf},
                        cfg=basic_config(tfs=[("relay_tf", "tf_1.py")], timeout=0.1))
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "tf_1.py", "'nope'", "nope_dp", "relay_tf")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertEqual(self.engine_pids(), {}, "engines started despite the bad TF")
        self.assertLogsKept()
        self.assertEqual(self.summary()["exit_code"], EXIT_USER)


# ---------------------------------------------------------------------------------------------
# Engines that die or hang
# ---------------------------------------------------------------------------------------------

DIE_AT = """
if self._time_ns >= 50_000_000:
    print("last words of python_2", flush=True)
    with open(os.path.join(_HERE, "death_time"), "w") as f:
        f.write(repr(time.time()))
    {how}
"""


class EngineFailures(ExperimentMixin, E2ETestCase):

    def check_death(self, how, *needles):
        src = engine_script("python_2", run_loop=DIE_AT.format(how=how))
        cfg = basic_config(timeout=10.0)
        for ec in cfg["EngineConfigs"]:
            ec["EngineCommandTimeout"] = 0  # no timeout: only the death itself may end the run
        self.experiment(engines={"python_2": src}, cfg=cfg)
        r = self.run_convoy()
        end = time.time()
        self.assertExit(r, EXIT_ENGINE)
        with open(os.path.join(self.dir, "death_time")) as f:
            died = float(f.read())
        self.assertLess(end - died, 1.0, "death noticed %.2f s late: %r" % (end - died, r))
        self.assertLess(r.wall, 3.0, repr(r))
        # The engine's name, what became of it and the tail of its log.
        self.assertStderrHas(r, "python_2", "last words of python_2", *needles)
        self.assertRegex(r.stderr, r"(?i)died|exited|killed|crash", repr(r))
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_python_1")),
                        "python_1's shutdown() did not run")
        self.assertEqual(self.summary()["exit_code"], EXIT_ENGINE)

    def test_engine_exits_mid_run(self):
        self.check_death("os._exit(7)", "status 7")

    def test_engine_killed_mid_run(self):
        self.check_death("os.kill(os.getpid(), 9)", "signal 9")

    def test_engine_dies_in_initialize(self):
        src = engine_script("python_2", initialize="os._exit(5)")
        cfg = basic_config(timeout=1.0)
        for ec in cfg["EngineConfigs"]:
            ec["EngineCommandTimeout"] = 0
        self.experiment(engines={"python_2": src}, cfg=cfg)
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertLess(r.wall, 3.0, repr(r))
        self.assertStderrHas(r, "python_2", "status 5")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")

    def test_engine_hangs_past_command_timeout(self):
        src = engine_script("python_2", run_loop="""
            if self._time_ns >= 50_000_000:
                with open(os.path.join(_HERE, "hang_time"), "w") as f:
                    f.write(repr(time.time()))
                time.sleep(60)
            """)
        cfg = basic_config(timeout=10.0)
        for ec in cfg["EngineConfigs"]:
            ec["EngineCommandTimeout"] = 0.5
        self.experiment(engines={"python_2": src}, cfg=cfg)
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "python_2", "EngineCommandTimeout")
        self.assertOneError(r)
        self.assertLess(r.wall, 5.0, repr(r))
        with open(os.path.join(self.dir, "hang_time")) as f:
            hung = float(f.read())
        self.assertGreater(time.time() - hung, 0.45, "ended before the timeout ran out")
        pid = self.engine_pids().get("python_2")
        self.assertIsNotNone(pid)
        self.assertNoEngineLeft(within=0.5, expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        self.assertEqual(self.summary()["exit_code"], EXIT_ENGINE)


# ---------------------------------------------------------------------------------------------
# Signals to the coordinator
# ---------------------------------------------------------------------------------------------

SLOW_STEP = """
time.sleep(0.001)
if self._time_ns >= 50_000_000 and not os.path.exists(os.path.join(_HERE, "running_{name}")):
    open(os.path.join(_HERE, "running_{name}"), "w").close()
"""


class Signals(ExperimentMixin, E2ETestCase):

    def start_long_run(self):
        engines = {n: engine_script(n, run_loop=SLOW_STEP.format(name=n))
                   for n in ("python_1", "python_2")}
        self.experiment(engines=engines, cfg=basic_config(timeout=10000.0))
        p = self.start([])
        deadline = time.monotonic() + 10
        while not all(os.path.exists(os.path.join(self.dir, "running_" + n))
                      for n in ("python_1", "python_2")):
            if p.poll() is not None or time.monotonic() > deadline:
                r = self.finish(p)
                self.fail("the run did not get going: %r" % r)
            time.sleep(0.01)
        return p

    def test_sigint_shuts_engines_down(self):
        p = self.start_long_run()
        pids = self.engine_pids()
        os.kill(p.pid, signal.SIGINT)  # the coordinator only, as a shell's Ctrl-C would not be
        r = self.finish(p, timeout=10)
        self.assertExit(r, EXIT_INTERRUPTED)
        for n in ("python_1", "python_2"):
            self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_" + n)),
                            "%s's shutdown() did not run: %r" % (n, r))
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertEqual(set(pids), {"python_1", "python_2"})
        self.assertLogsKept("python_1", "python_2")
        s = self.summary()
        self.assertEqual(s["exit_code"], EXIT_INTERRUPTED)
        self.assertRegex(r.stderr, r"(?i)interrupt")

    def test_sigint_while_engine_hangs(self):
        # No EngineCommandTimeout: only the Ctrl-C can end this run. The coordinator gives
        # the hung Step a moment to finish, then ends the engine.
        src = engine_script("python_2", run_loop="""
            if self._time_ns >= 50_000_000:
                open(os.path.join(_HERE, "hanging"), "w").close()
                time.sleep(60)
            """)
        cfg = basic_config(timeout=10.0)
        for ec in cfg["EngineConfigs"]:
            ec["EngineCommandTimeout"] = 0
        self.experiment(engines={"python_2": src}, cfg=cfg)
        p = self.start([])
        deadline = time.monotonic() + 10
        while not os.path.exists(os.path.join(self.dir, "hanging")):
            if p.poll() is not None or time.monotonic() > deadline:
                self.fail("the engine never hung: %r" % self.finish(p))
            time.sleep(0.01)
        time.sleep(0.1)
        t0 = time.monotonic()
        os.kill(p.pid, signal.SIGINT)
        r = self.finish(p, timeout=10)
        self.assertExit(r, EXIT_INTERRUPTED)
        self.assertLess(time.monotonic() - t0, 5.0, "Ctrl-C took too long: %r" % r)
        self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_python_1")),
                        "python_1's shutdown() did not run: %r" % r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        self.assertEqual(self.summary()["exit_code"], EXIT_INTERRUPTED)

    def test_sigkill_of_coordinator_kills_engines(self):
        p = self.start_long_run()
        pids = self.engine_pids()
        self.assertEqual(set(pids), {"python_1", "python_2"})
        os.kill(p.pid, signal.SIGKILL)
        r = self.finish(p, timeout=5)
        self.assertEqual(r.code, -signal.SIGKILL)
        deadline = time.monotonic() + 2.0
        while any(pid_alive(pid) for pid in pids.values()) and time.monotonic() < deadline:
            time.sleep(0.02)
        alive = {n: pid for n, pid in pids.items() if pid_alive(pid)}
        self.assertEqual(alive, {}, "engines outlived the coordinator by 2 s")
        self.assertNoEngineLeft(within=0.1)
        self.assertLogsKept("python_1", "python_2")


# ---------------------------------------------------------------------------------------------
# Runs that work
# ---------------------------------------------------------------------------------------------

COUNT_STEPS = dict(
    initialize="self.steps = 0",
    run_loop="self.steps += 1",
    shutdown="""
        with open(os.path.join(_HERE, "steps_" + self._name), "w") as f:
            f.write(str(self.steps))
        """,
)


class GoodRuns(ExperimentMixin, E2ETestCase):

    def tf_exchange(self, timeout=0.2):
        engines = {n: engine_script(n, **COUNT_STEPS) for n in ("python_1", "python_2")}
        tf = relay_tf(body='assert dp.data["time"] >= 0')
        return self.experiment(engines=engines, tfs={"tf_1.py": tf},
                               cfg=basic_config(tfs=[("tf_1", "tf_1.py")], timeout=timeout))

    def steps_run(self):
        out = {}
        for n in ("python_1", "python_2"):
            with open(os.path.join(self.dir, "steps_" + n)) as f:
                out[n] = int(f.read())
        return out

    def check_ok_run(self, r, run_dir):
        self.assertExit(r, 0)
        with open(os.path.join(run_dir, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(s["exit_code"], 0)
        self.assertEqual(s["error"], "")
        with open(os.path.join(run_dir, "steps.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertGreater(len(rows), 1)
        for n in ("python_1", "python_2"):
            self.assertTrue(os.path.isfile(os.path.join(run_dir, "logs", n + ".log")))
        self.assertTrue(os.path.isfile(os.path.join(run_dir, "logs", "coordinator.log")))
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        return s, rows

    def test_tf_exchange_succeeds(self):
        self.tf_exchange()
        r = self.run_convoy()
        s, rows = self.check_ok_run(r, self.run_dir)
        self.assertAlmostEqual(s["sim_time_s"], 0.2, places=6)
        self.assertEqual(self.steps_run(), {"python_1": 20, "python_2": 20})
        self.assertEqual(len(rows), s["cycles"])

    def test_nrpcoresim_works_the_same(self):
        self.tf_exchange()
        r = self.run_convoy(binary=NRPCORESIM, run_dir=False)  # NRP-Core's command line
        runs = os.path.join(self.dir, "runs")
        self.assertTrue(os.path.isdir(runs), "no ./runs folder: %r" % r)
        (run,) = os.listdir(runs)
        s, rows = self.check_ok_run(r, os.path.join(runs, run))
        self.assertAlmostEqual(s["sim_time_s"], 0.2, places=6)
        self.assertEqual(self.steps_run(), {"python_1": 20, "python_2": 20})

    def test_override_simulation_timeout(self):
        self.tf_exchange(timeout=0.2)
        r = self.run_convoy("-o", "SimulationTimeout=0.05")
        s, rows = self.check_ok_run(r, self.run_dir)
        self.assertAlmostEqual(s["sim_time_s"], 0.05, places=6)
        self.assertEqual(self.steps_run(), {"python_1": 5, "python_2": 5})
        self.assertEqual(len(rows), s["cycles"])
        with open(os.path.join(self.run_dir, "config.json")) as f:
            self.assertEqual(json.load(f)["SimulationTimeout"], 0.05)

    def test_override_engine_timestep(self):
        self.tf_exchange(timeout=0.2)
        r = self.run_convoy("-o", "EngineConfigs/1/EngineTimestep=0.05")
        self.check_ok_run(r, self.run_dir)
        self.assertEqual(self.steps_run(), {"python_1": 20, "python_2": 4})

    def test_unknown_key_warns_without_failing(self):
        cfg = self.tf_exchange()
        cfg["SimulationTimout"] = 3  # misspelt
        self.write_config(cfg)
        r = self.run_convoy()
        self.check_ok_run(r, self.run_dir)
        self.assertStderrHas(r, "SimulationTimout")
        self.assertRegex(r.stderr, r"(?i)warning.*SimulationTimout|SimulationTimout.*warning")
        self.assertEqual(self.steps_run(), {"python_1": 20, "python_2": 20})


if __name__ == "__main__":
    unittest.main()
