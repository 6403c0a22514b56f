"""End-to-end tests of NRP-Core's computational graph in the FTILoop ("DataPackProcessor": "cg")
and of ExternalProcesses.

FtiCg: a graph relays a datapack from one python_json engine to another (NRP-Core's tf_exchange
with FromEngine/ToEngine); the values arrive, and two runs are identical.
BadGraphs: a node cycle, an unknown input node or port, an engine not in EngineConfigs, a
Python error at load and in a node at run time: one clear message, the exit code, nothing left.
ExternalProcesses: started before the engines in the config's folder with their arguments and
environment, output in logs/<name>_<index>.log, stopped after the engines (SIGTERM, SIGKILL
after 5 s), none left when the coordinator is killed, a command that cannot run.

Run with Debian's /usr/bin/python3 -m unittest test_event_loop."""

import json
import os
import signal
import textwrap
import time
import unittest

from e2e_util import E2ETestCase, basic_config, engine_script, pid_alive

# The source engine: datapack "out" = {"x": its time in ms}.
SOURCE = engine_script("src", initialize='self._registerDataPack("out")\n'
                       'self._setDataPack("out", {"x": 0})',
                       run_loop='self._setDataPack("out", {"x": self._time_ns // 1000000})')
# The sink engine records what it got in each step into dst.jsonl.
SINK = engine_script("dst", initialize="""
    self._registerDataPack("in")
    self.log = open(os.path.join(_HERE, "dst.jsonl"), "w")
    """, run_loop="""
    self.log.write(json.dumps({"t": self._time_ns, "got": self._getDataPack("in")}) + "\\n")
    self.log.flush()
    """, imports="import json")

RELAY_GRAPH = textwrap.dedent("""\
    from nrp_core.event_loop import *
    from nrp_core.data.nrp_json import JsonDataPack

    @FromEngine(keyword="src", address="/src/out")
    @Clock(keyword="clock")
    @Iteration(keyword="iteration")
    @FunctionalNode(name="scale", outputs=["value"])
    def scale(src, clock, iteration):
        return [{"x": src.data["x"] * 2, "clock": clock, "iteration": iteration}]

    @FromFunctionalNode(keyword="value", address="/scale/value")
    @ToEngine(keyword="dp", address="/dst")
    @FunctionalNode(name="pack", outputs=["dp"])
    def pack(value):
        dp = JsonDataPack("in", "dst")
        for k, v in value.items():
            dp.data[k] = v
        return [dp]
    """)


class GraphCase(E2ETestCase):
    def experiment(self, graph=RELAY_GRAPH, timeout=0.05, source=SOURCE, **extra):
        self.write("src.py", source)
        self.write("dst.py", SINK)
        self.write("graph.py", graph)
        cfg = basic_config(engines=("src", "dst"), timeout=timeout, timestep=0.01,
                           DataPackProcessor="cg", ComputationalGraph=["graph.py"])
        cfg.update(extra)
        self.write_config(cfg)

    def received(self):
        with open(os.path.join(self.dir, "dst.jsonl")) as f:
            return [json.loads(line) for line in f]


class FtiCg(GraphCase):
    def test_graph_relays_between_engines(self):
        self.experiment()
        r = self.run_convoy()
        self.assertExit(r, 0)
        got = self.received()
        # Step k of dst (ending at 10(k+1) ms) gets what the graph computed at cycle k from
        # src's datapack of that time (k*10 ms): x doubled, the Clock in ms, the Iteration.
        self.assertEqual([g["t"] for g in got], [10_000_000 * k for k in range(1, 6)])
        for k, g in enumerate(got):
            self.assertEqual(g["got"], {"x": 20 * k, "clock": 10 * k, "iteration": k}, got)
        self.assertNotIn("DataPackProcessor", r.stderr)  # no "not available" warning
        self.assertNoEngineLeft(expect_pids=("src", "dst"))

    def test_two_runs_are_identical(self):
        self.experiment(timeout=0.2)
        runs = []
        for name in ("a", "b"):
            self.run_dir = os.path.join(self.dir, name)
            self.assertExit(self.run_convoy(), 0)
            runs.append(self.received())
        self.assertEqual(len(runs[0]), 20)
        self.assertEqual(runs[0], runs[1])

    def test_transceiver_functions_are_ignored_with_a_warning(self):
        self.write("tf.py", "raise RuntimeError('a TF must not load with cg')\n")
        self.experiment(DataPackProcessingFunctions=[{"Name": "tf", "FileName": "tf.py"}])
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertStderrHas(r, "/DataPackProcessingFunctions: ignored: DataPackProcessor is cg")
        self.assertEqual(len(self.received()), 5)

    def test_event_loop_keys_are_read_and_checked(self):
        self.experiment(EventLoop={"Timestep": 0})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "/EventLoop/Timestep")
        # (ROSNode is the graph's in the FTILoop too: test_event_loop_ros.py.)
        self.experiment(EventLoop={"ExecutionMode": "OutputDriven"})
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertStderrHas(r, "/EventLoop: ignored: used with SimulationLoop EventLoop only")


class BadGraphs(GraphCase):
    def assertRefused(self, code, *needles, graph=None, **extra):
        self.experiment(graph=graph, **extra)
        r = self.run_convoy()
        self.assertExit(r, code)
        self.assertOneError(r)
        self.assertStderrHas(r, *needles)
        self.assertNoEngineLeft()
        return r

    def test_node_cycle(self):
        graph = textwrap.dedent("""\
            from nrp_core.event_loop import *

            @FromFunctionalNode(keyword="a", address="/b/out")
            @FunctionalNode(name="a_node", outputs=["out"])
            def a(a):
                return [a]

            @FromFunctionalNode(keyword="b", address="/a_node/out")
            @FunctionalNode(name="b", outputs=["out"])
            def b(b):
                return [b]
            """)
        r = self.assertRefused(2, "graph.py", "a_node", graph=graph)
        self.assertIn("cycle", r.stderr.lower())
        # Refused before any engine started.
        self.assertEqual(self.engine_pids(), {})

    def test_unknown_input_node_and_port(self):
        graph = RELAY_GRAPH.replace('address="/scale/value"', 'address="/nosuch/value"')
        self.assertRefused(2, "graph.py", "nosuch", graph=graph)
        graph = RELAY_GRAPH.replace('address="/scale/value"', 'address="/scale/nosuch"')
        self.assertRefused(2, "graph.py", "nosuch", graph=graph)

    def test_engine_not_in_engine_configs(self):
        graph = RELAY_GRAPH.replace('address="/dst"', 'address="/elsewhere"').replace(
            'JsonDataPack("in", "dst")', 'JsonDataPack("in", "elsewhere")')
        self.assertRefused(2, 'ToEngine node "elsewhere_output"', '"elsewhere"',
                           "not in EngineConfigs", graph=graph)
        graph = RELAY_GRAPH.replace('address="/src/out"', 'address="/nosrc/out"')
        self.assertRefused(2, 'FromEngine node "nosrc_input"', graph=graph)

    def test_python_error_at_load(self):
        graph = RELAY_GRAPH + "\nraise ValueError('broken graph file')\n"
        self.assertRefused(2, "graph.py", "ValueError: broken graph file", graph=graph)
        self.assertRefused(2, "missing.py", ComputationalGraph=["missing.py"], graph=RELAY_GRAPH)

    def test_python_error_in_a_node(self):
        graph = RELAY_GRAPH.replace('return [{"x"', 'assert iteration < 2, "node gave up"\n'
                                    '    return [{"x"')
        r = self.assertRefused(4, 'Functional Node with id "scale"', "node gave up",
                               "graph.py", graph=graph, SimulationTimeout=1.0)
        self.assertEqual(self.summary()["exit_code"], 4)
        self.assertLogsKept("src", "dst")
        self.assertIn("AssertionError", r.stderr)


# An external process: records its argv, cwd and environment, then waits for SIGTERM.
EXTERNAL = textwrap.dedent("""\
    import json, os, signal, sys, time
    name = sys.argv[1]
    def record(what):
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                               name + "." + what), "w") as f:
            f.write(str(time.monotonic()))
    if "--ignore-term" in sys.argv:
        signal.signal(signal.SIGTERM, lambda *a: record("ignored"))
    else:
        signal.signal(signal.SIGTERM, lambda *a: (record("terminated"), sys.exit(0)))
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), name + ".json")
    with open(path + ".tmp", "w") as f:
        json.dump({"argv": sys.argv[1:], "cwd": os.getcwd(), "pid": os.getpid(),
                   "greeting": os.environ.get("GREETING"), "both": os.environ.get("BOTH")}, f)
    os.rename(path + ".tmp", path)
    print("external %s running" % name, flush=True)
    while True:
        time.sleep(0.05)
    """)


class ExternalProcesses(GraphCase):
    def external(self, *procs, timeout=0.05, ready=()):
        """An experiment with these ExternalProcesses; the source engine's initialize waits
        until the external processes named `ready` have written their <name>.json."""
        self.write("ext.py", EXTERNAL)
        wait = textwrap.dedent("""\
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline and not all(
                    os.path.exists(os.path.join(_HERE, n + ".json")) for n in %r):
                time.sleep(0.01)
            """) % (list(ready),)
        source = engine_script("src", initialize=wait + 'self._registerDataPack("out")\n'
                               'self._setDataPack("out", {"x": 0})',
                               run_loop='self._setDataPack("out", {"x": self._time_ns // 1000000})')
        self.experiment(timeout=timeout, source=source, ExternalProcesses=list(procs))

    def info(self, name):
        path = os.path.join(self.dir, name + ".json")
        deadline = time.monotonic() + 5
        while not os.path.exists(path) and time.monotonic() < deadline:
            time.sleep(0.02)
        with open(path) as f:
            return json.load(f)

    def test_started_before_engines_and_stopped_after(self):
        os.environ["CONVOY_E2E_OUTER"] = "outer"
        self.addCleanup(os.environ.pop, "CONVOY_E2E_OUTER")
        self.external({"ProcCmd": "python3 ext.py one", "ProcStartParams": ["--a 1", "b"],
                       "ProcEnvParams": ["GREETING=hi ${CONVOY_E2E_OUTER}", "BOTH=$GREETING!"]},
                      {"ProcCmd": "nothing-at-all", "LaunchCommand":
                       {"LaunchType": "EmptyLaunchCommand"}}, timeout=0.3, ready=["one"])
        p = self.start([])
        info = self.info("one")
        self.assertTrue(pid_alive(info["pid"]))
        r = self.finish(p)
        self.assertExit(r, 0)
        self.assertEqual(info["argv"], ["one", "--a", "1", "b"])
        self.assertEqual(os.path.realpath(info["cwd"]), os.path.realpath(self.dir))
        self.assertEqual(info["greeting"], "hi outer")
        self.assertEqual(info["both"], "hi outer!")
        log = self.read_log("coordinator")
        self.assertLess(log.index("started external process"), log.index("started 2 engines"))
        # Stopped after the engines shut down, politely.
        self.assertTrue(os.path.exists(os.path.join(self.dir, "one.terminated")))
        self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_dst")))
        self.assertIn("external one running", self.read_log("python3_0"))
        self.assertFalse(pid_alive(info["pid"]))
        self.assertNoEngineLeft()

    def test_sigterm_ignored_then_killed(self):
        self.external({"ProcCmd": "python3 ext.py stubborn --ignore-term"}, ready=["stubborn"])
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertGreater(r.wall, 4.5)  # the 5 s grace period
        self.assertTrue(os.path.exists(os.path.join(self.dir, "stubborn.ignored")))
        self.assertFalse(pid_alive(self.info("stubborn")["pid"]))
        self.assertNoEngineLeft()

    def test_killed_coordinator_leaves_nothing(self):
        self.external({"ProcCmd": "python3 ext.py orphan"}, timeout=0, ready=["orphan"])
        p = self.start([])
        pid = self.info("orphan")["pid"]
        deadline = time.monotonic() + 10
        while not os.path.exists(os.path.join(self.dir, "dst.jsonl")) and \
                time.monotonic() < deadline:
            time.sleep(0.02)
        p.send_signal(signal.SIGKILL)
        p.communicate()
        self.assertNoEngineLeft(within=3.0)
        self.assertFalse(pid_alive(pid))

    def test_command_that_cannot_run(self):
        self.external({"ProcCmd": "python3 ext.py first"}, {"ProcCmd": "no-such-program-xyz -v"})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "/ExternalProcesses/1/ProcCmd", "no-such-program-xyz")
        self.assertEqual(self.engine_pids(), {})  # no engine started
        self.assertTrue(os.path.exists(os.path.join(self.run_dir, "logs", "python3_0.log")))
        self.assertNoEngineLeft()  # "first" included: its working folder is the experiment's
        self.write("plain.txt", "not a program\n")
        self.external({"ProcCmd": "./plain.txt"})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "./plain.txt", "cannot execute")

    def test_bad_keys(self):
        self.external({"ProcStartParams": ["x"]})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "/ExternalProcesses/0/ProcCmd: is required")
        self.external({"ProcCmd": "true", "LaunchCommand": {"LaunchType": "DockerLauncher"}})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "/ExternalProcesses/0/LaunchCommand/LaunchType", "DockerLauncher")
        self.external({"ProcCmd": "true", "ProcEnvParams": ["NOEQ"]})
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "/ExternalProcesses/0/ProcEnvParams/0: must be KEY=VALUE")
        self.assertEqual(self.engine_pids(), {})


if __name__ == "__main__":
    unittest.main()
