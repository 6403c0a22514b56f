"""End-to-end tests of SimulationLoop "EventLoop" WITH EngineConfigs (NRP-Core 1.4's
EventLoopSimManager with an FTILoopSimManager beside it), and of MQTT nodes in the FTILoop's
"cg" graph.

Engines: the engines' FTILoop runs unpaced on its own thread until EventLoop.Timeout; its
DataPackProcessor is the EventLoop's graph in slave mode (datapacks in and out, no compute);
the graph computes every EventLoop.Timestep with the EventLoop's Clock and Iteration.
SimulationTimeout and transceiver functions are not used (NRP-Core's semantics); the example
experiments/nrp_event_loop/engines_relay runs.
BadGraphs: a node cycle, an unknown input node, an unknown engine, a node that raises, an
engine that dies: one clear message naming the node (or engine), the exit code, nothing left.
Signals: Ctrl-C (exit 130, the engines shut down) and a killed coordinator leave nothing.
FtiCgMqtt: @MQTTPublisher / @MQTTSubscriber in an FTILoop "cg" graph with MQTTNode (the
coordinator starts mosquitto on the free local port given, or uses the test's broker).

Run with Debian's /usr/bin/python3 -m unittest test_event_loop_engines."""

import json
import os
import re
import shutil
import signal
import textwrap
import time
import unittest

from e2e_util import NRPCORESIM, REPO, E2ETestCase, engine_script, free_port
from mqtt_util import MOSQUITTO, Broker, Subscriber

# src: datapack "out" = {"x": its time in ms}. dst: appends what it got each step to dst.jsonl.
SOURCE = engine_script("src", initialize='self._registerDataPack("out")\n'
                       'self._setDataPack("out", {"x": 0})',
                       run_loop='self._setDataPack("out", {"x": self._time_ns // 1000000})')
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
        x = src.data["x"] if src is not None and not src.isEmpty() else -1
        return [{"x": x, "clock": clock, "iteration": iteration}]

    @FromFunctionalNode(keyword="value", address="/scale/value")
    @ToEngine(keyword="dp", address="/dst")
    @FunctionalNode(name="pack", outputs=["dp"])
    def pack(value):
        dp = JsonDataPack("in", "dst")
        for k, v in value.items():
            dp.data[k] = v
        return [dp]
    """)


def _config(timeout=0.5, timestep=0.02, **extra):
    cfg = {"SimulationName": "el_engines", "SimulationLoop": "EventLoop",
           "SimulationTimeout": 0.05,  # not used by the EventLoop (NRP-Core)
           "EventLoop": {"Timestep": timestep, "Timeout": timeout},
           "EngineConfigs": [{"EngineType": "python_json", "EngineName": n,
                              "PythonFileName": n + ".py", "EngineTimestep": 0.01}
                             for n in ("src", "dst")],
           "ComputationalGraph": ["graph.py"]}
    cfg.update(extra)
    return cfg


class EngineCase(E2ETestCase):
    def experiment(self, graph=RELAY_GRAPH, source=SOURCE, **extra):
        self.write("src.py", source)
        self.write("dst.py", SINK)
        self.write("graph.py", graph)
        self.write_config(_config(**extra))

    def received(self):
        with open(os.path.join(self.dir, "dst.jsonl")) as f:
            return [json.loads(line) for line in f]


class Engines(EngineCase):
    def test_engines_step_beside_the_event_loop(self):
        self.experiment(timeout=0.6, timestep=0.02)
        r = self.run_convoy(binary=NRPCORESIM)
        self.assertExit(r, 0)
        self.assertNotIn("not available yet", r.stderr)
        self.assertStderrHas(r, "the engines' FTILoop beside it")
        got = self.received()
        # The FTILoop is not bound by SimulationTimeout (0.05 s = 5 steps) nor paced.
        self.assertGreater(len(got), 20, got[-3:])
        last = got[-1]["got"]
        # The graph ran on the EventLoop's clock: Clock in wall ms below the Timeout,
        # Iteration about Timeout / Timestep (never more than its cycles).
        self.assertLessEqual(last["clock"], 600)
        self.assertGreaterEqual(last["iteration"], 10)
        self.assertLessEqual(last["iteration"], 30)
        # What dst got came from src through the graph: x is src's time in ms, never ahead
        # of dst's own time (both step alike), and it moves.
        xs = [g["got"]["x"] for g in got if g["got"] and g["got"]["x"] >= 0]
        self.assertTrue(xs and xs[-1] > 0, got[-3:])
        for g in got:
            if g["got"] and g["got"]["x"] >= 0:
                self.assertLessEqual(g["got"]["x"], g["t"] // 1_000_000)
        self.assertEqual(xs, sorted(xs))
        s = self.summary()
        self.assertGreaterEqual(s.get("cycles", 0), 10)
        self.assertNoEngineLeft(expect_pids=("src", "dst"))

    def test_example_engines_relay(self):
        src = os.path.join(REPO, "experiments", "nrp_event_loop", "engines_relay")
        for f in os.listdir(src):
            if f.endswith((".py", ".json")):
                shutil.copy(os.path.join(src, f), self.dir)
        r = self.run_convoy("-o", "EventLoop/Timeout=0.5", binary=NRPCORESIM)
        self.assertExit(r, 0)
        with open(os.path.join(self.run_dir, "logs", "python_2.log")) as f:
            log = f.read()
        got = re.findall(r"Engine 2 at (\d+) ms received \{'engine_1_time_ms': (\d+), "
                         r"'event_loop_clock_ms': (\d+)\}", log)
        self.assertTrue(got, log[-2000:])
        for t, t1, clock in got:
            self.assertLessEqual(int(t1), int(t))
            self.assertLessEqual(int(clock), 500)
        self.assertIn("Engine 2 is shutting down", log)

    def test_timeout_is_wall_time(self):
        self.experiment(timeout=1.5, timestep=0.05)
        r = self.run_convoy(binary=NRPCORESIM)
        self.assertExit(r, 0)
        self.assertGreater(r.wall, 1.4, r)
        self.assertLess(r.wall, 10, r)
        last = self.received()[-1]["got"]
        self.assertGreaterEqual(last["clock"], 1200)
        self.assertLessEqual(last["iteration"], 31)

    def test_transceiver_functions_are_ignored_with_a_warning(self):
        self.write("tf.py", "raise RuntimeError('a TF must not load under the EventLoop')\n")
        self.experiment(DataPackProcessingFunctions=[{"Name": "tf", "FileName": "tf.py"}],
                        DataPackProcessor="tf")
        r = self.run_convoy(binary=NRPCORESIM)
        self.assertExit(r, 0)
        self.assertStderrHas(r, "/DataPackProcessingFunctions: ignored: SimulationLoop is "
                                "EventLoop")
        self.assertTrue(self.received())


class BadGraphs(EngineCase):
    def assertRefused(self, code, *needles, **kw):
        self.experiment(**kw)
        r = self.run_convoy(binary=NRPCORESIM)
        self.assertExit(r, code)
        self.assertOneError(r)
        self.assertStderrHas(r, *needles)
        self.assertNoEngineLeft()
        return r

    def test_node_cycle(self):
        graph = textwrap.dedent("""\
            from nrp_core.event_loop import *

            @FromFunctionalNode(keyword="a", address="/b_node/out")
            @FunctionalNode(name="a_node", outputs=["out"])
            def a(a):
                return [a]

            @FromFunctionalNode(keyword="b", address="/a_node/out")
            @FunctionalNode(name="b_node", outputs=["out"])
            def b(b):
                return [b]
            """)
        r = self.assertRefused(2, "Cycle", '"a_node"', '"b_node"', graph=graph)
        self.assertNotIn("started 2 engines", r.stderr)  # refused before any engine

    def test_unknown_input_node(self):
        graph = RELAY_GRAPH.replace('address="/scale/value"', 'address="/nowhere/value"')
        self.assertRefused(2, "nowhere", graph=graph)

    def test_unknown_engine(self):
        graph = RELAY_GRAPH.replace('address="/src/out"', 'address="/ghost/out"')
        self.assertRefused(2, 'FromEngine node "ghost_input"', 'engine "ghost"', graph=graph)

    def test_node_that_raises(self):
        graph = RELAY_GRAPH.replace('x = src.data["x"]', 'x = 1 / 0 if iteration == 3 else 0')
        r = self.assertRefused(4, "ZeroDivisionError", "scale", graph=graph, timeout=5)
        self.assertLess(r.wall, 4.5, r)

    def test_engine_that_dies(self):
        source = engine_script("src", initialize='self._registerDataPack("out")',
                               run_loop='if self._time_ns > 200_000_000: os._exit(7)\n'
                                        'self._setDataPack("out", {"x": 1})')
        r = self.assertRefused(3, "src", source=source, timeout=5)
        self.assertLess(r.wall, 4.5, r)


class Signals(EngineCase):
    def start_endless(self):
        self.experiment(timeout=0)
        p = self.start([], binary=NRPCORESIM)
        deadline = time.monotonic() + 20
        path = os.path.join(self.dir, "dst.jsonl")
        while not (os.path.isfile(path) and os.path.getsize(path) > 0):
            self.assertLess(time.monotonic(), deadline, "dst got nothing")
            time.sleep(0.05)
        return p

    def test_ctrl_c(self):
        p = self.start_endless()
        p.send_signal(signal.SIGINT)
        r = self.finish(p, 30)
        self.assertExit(r, 130)
        self.assertTrue(os.path.isfile(os.path.join(self.dir, "shutdown_dst")), r)
        self.assertNoEngineLeft(expect_pids=("src", "dst"))

    def test_killed_coordinator_leaves_nothing(self):
        p = self.start_endless()
        p.kill()
        p.communicate()
        self.assertNoEngineLeft(within=5.0, expect_pids=("src", "dst"))


MQTT_GRAPH = textwrap.dedent("""\
    from nrp_core.event_loop import *
    from nrp_core.data.nrp_json import JsonDataPack

    @FromEngine(keyword="src", address="/src/out")
    @MQTTPublisher(keyword="out", address="convoy_test/x", type=str)
    @FunctionalNode(name="publish", outputs=["out"])
    def publish(src):
        return ["x=%d" % src.data["x"]]

    @MQTTSubscriber(keyword="cmd", address="convoy_test/cmd", type=str)
    @ToEngine(keyword="dp", address="/dst")
    @FunctionalNode(name="forward", outputs=["dp"])
    def forward(cmd):
        dp = JsonDataPack("in", "dst")
        dp.data["cmd"] = cmd
        return [dp]
    """)


def _publish(sub, topic, payload):
    """A QoS 0 PUBLISH on the subscriber's connection (mqtt_util has no publisher)."""
    body = len(topic).to_bytes(2, "big") + topic.encode() + payload
    sub._sock.sendall(b"\x30" + bytes([len(body)]) + body)


class FtiCgMqtt(EngineCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(MOSQUITTO, os.X_OK):
            raise unittest.SkipTest("no %s (Debian package mosquitto)" % MOSQUITTO)

    def fti_experiment(self, broker, timeout=2.0):
        self.write("src.py", SOURCE)
        self.write("dst.py", SINK.replace("self.log.flush()",
                                          "self.log.flush()\n        time.sleep(0.002)"))
        self.write("graph.py", MQTT_GRAPH)
        cfg = _config(SimulationLoop="FTILoop", DataPackProcessor="cg",
                      MQTTNode={"MQTTBroker": broker}, SimulationTimeout=timeout)
        del cfg["EventLoop"]
        self.write_config(cfg)

    def test_mqtt_nodes_in_the_fti_loop(self):
        broker = Broker()
        try:
            sub = Subscriber(broker.port, "convoy_test/#")
            self.fti_experiment(broker.address)
            p = self.start([])
            deadline = time.monotonic() + 15
            while not sub.on("convoy_test/x") and time.monotonic() < deadline:
                time.sleep(0.02)
            # The graph subscribed before the first step: a command reaches dst.
            _publish(sub, "convoy_test/cmd", b"go")
            r = self.finish(p)
            sub.close()
        finally:
            broker.stop()
        self.assertExit(r, 0)
        self.assertNotIn("MQTTNode is not supported", r.stderr)
        xs = [int(m.decode()[2:]) for m in sub.on("convoy_test/x")]
        self.assertTrue(xs, r)
        self.assertEqual(xs, sorted(xs))
        self.assertIn("go", [g["got"].get("cmd") for g in self.received() if g["got"]])
        self.assertNoEngineLeft()

    def test_coordinator_starts_mosquitto(self):
        self.fti_experiment("localhost:%d" % free_port(), timeout=0.1)
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertStderrHas(r, "MQTT: started mosquitto on")
        self.assertNoEngineLeft(within=3.0)  # mosquitto stopped with the run

    def test_node_cycle_stops_the_started_broker(self):
        self.fti_experiment("localhost:%d" % free_port())
        self.write("graph.py", MQTT_GRAPH + textwrap.dedent("""
            @FromFunctionalNode(keyword="a", address="/loop_b/out")
            @FunctionalNode(name="loop_a", outputs=["out"])
            def loop_a(a):
                return [a]

            @FromFunctionalNode(keyword="b", address="/loop_a/out")
            @FunctionalNode(name="loop_b", outputs=["out"])
            def loop_b(b):
                return [b]
            """))
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "Cycle", '"loop_a"', '"loop_b"', "MQTT: started mosquitto")
        self.assertNotIn("started 2 engines", r.stderr)
        self.assertNoEngineLeft(within=3.0)

    def test_unreachable_broker(self):
        self.fti_experiment("mqtt.invalid:1883")
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "MQTTNode.MQTTBroker", "mqtt.invalid:1883")
        self.assertNotIn("started 2 engines", r.stderr)
        self.assertNoEngineLeft()


if __name__ == "__main__":
    unittest.main()
