"""End-to-end tests of SimulationLoop "EventLoop" with NRP-Core 1.4's examples, unchanged
(experiments/nrp_event_loop/tf_exchange_async and mqtt_simple), run with NRPCoreSim.

TfExchangeAsync: two asynchronous engines (async_python_json_engine.py /
async_python_grpc_engine.py, started as ExternalProcesses) exchange engine 1's time through
the graph over MQTT: engine 2 prints the values engine 1 published (JSON and protobuf); the
coordinator starts mosquitto on the free local port it is given and stops it.
MqttSimple: each of cg_mqtt.py's five nodes receives its own messages (str, protobuf, protobuf
datapack, JSON, JSON datapack) from a broker the test runs; the payloads on the wire have
NRP-Core's formats; no mosquitto of the coordinator's when a broker answers.
BadInput: an unreachable broker, an asynchronous engine's bad config (in a run and alone): one
message naming the key / the file and field, exit 2, no process left (mosquitto, engines).

The examples' MQTTNode is {} (localhost:1883): the tests point it at a free port with
-o MQTTNode/MQTTBroker=localhost:PORT, which the engines follow ($CONVOY_MQTT_BROKER).
Run with Debian's /usr/bin/python3 -m unittest test_event_loop_examples."""

import ast
import json
import os
import re
import shutil
import signal
import subprocess
import time
import unittest

from e2e_util import BIN_DIR, NRPCORESIM, REPO, E2ETestCase, free_port
from mqtt_util import MOSQUITTO, Broker, Subscriber

EXAMPLES = os.path.join(REPO, "experiments", "nrp_event_loop")


def _skip_without_mosquitto():
    if not os.access(MOSQUITTO, os.X_OK):
        raise unittest.SkipTest("no %s (Debian package mosquitto)" % MOSQUITTO)


class ExampleCase(E2ETestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        _skip_without_mosquitto()

    def copy_example(self, name):
        src = os.path.join(EXAMPLES, name)
        for f in os.listdir(src):
            shutil.copy(os.path.join(src, f), self.dir)

    def run_sim(self, config, *args):
        return self.run_convoy(*args, binary=NRPCORESIM, timeout=60) if config is None else \
            self.finish(self.start(args, binary=NRPCORESIM, config=config), 60)

    def engine_log(self, index, kind="json"):
        path = os.path.join(self.run_dir, "logs", "async_python_%s_engine.py_%d.log"
                            % (kind, index))
        with open(path) as f:
            return f.read()

    def assertNothingLeft(self):
        self.assertNoEngineLeft(within=3.0)


class TfExchangeAsync(ExampleCase):
    def check_run(self, r, port):
        self.assertExit(r, 0)
        self.assertIn("MQTT: started mosquitto on localhost:%d" % port, r.stderr)
        self.assertNotIn("EventLoop runs FTILoop", r.stderr)
        self.assertNotIn("not available", r.stderr)
        self.assertNothingLeft()

    def test_json(self):
        self.copy_example("tf_exchange_async")
        port = free_port()
        r = self.run_sim("simulation_config_json.json", "-o",
                         "MQTTNode/MQTTBroker=localhost:%d" % port, "-o", "EventLoop/Timeout=2")
        self.check_run(r, port)
        sent = [ast.literal_eval(m) for m in
                re.findall(r"(?m)^DataPack 1 data is (\{.*\})$", self.engine_log(0))]
        got = [ast.literal_eval(m) for m in
               re.findall(r"(?m)^Engine 2 received data is (\{.*\})$", self.engine_log(1))]
        self.assertGreaterEqual(len(sent), 10, r)
        # Engine 2 starts with its own {"time": 0, ...}; then engine 1's values, via the graph.
        relayed = [d for d in got if d["time"] > 0]
        self.assertGreaterEqual(len(relayed), 8, got)
        sent_times = {d["time"] for d in sent}
        for d in relayed:
            self.assertIn(d["time"], sent_times)
            self.assertEqual(d["timestep"], 100000000)
        times = [d["time"] for d in relayed]
        self.assertEqual(times, sorted(times))
        self.assertGreater(len(set(times)), 5)

    def test_proto_unchanged(self):
        self.copy_example("tf_exchange_async")
        port = free_port()
        r = self.run_sim("simulation_config_proto.json", "-o",
                         "MQTTNode/MQTTBroker=localhost:%d" % port)
        self.check_run(r, port)
        sent = re.findall(r"(?m)^DataPack 1 data is  (\d+)$", self.engine_log(0, "grpc"))
        got = re.findall(r"(?m)^Engine 2 received data is  (\d*)$", self.engine_log(1, "grpc"))
        # Timeout 1 s at 0.1 s: ten cycles each; engine 2 gets engine 1's times 0.1 s ... later.
        self.assertEqual(sent[:3], ["100000000", "200000000", "300000000"])
        relayed = [int(t) for t in got if t]
        self.assertGreaterEqual(len(relayed), 6, got)
        self.assertTrue(set(map(str, relayed)) <= set(sent), (relayed, sent))
        self.assertEqual(relayed, sorted(relayed))
        summary = self.summary()
        self.assertEqual(summary["exit_code"], 0)
        self.assertGreaterEqual(summary["cycles"], 15)  # Timeout 2 s, Timestep 0.1 s


class MqttSimple(ExampleCase):
    def test_nodes_receive_their_messages(self):
        self.copy_example("mqtt_simple")
        broker = Broker()
        self.addCleanup(broker.stop)
        sub = Subscriber(broker.port, "#")
        self.addCleanup(sub.close)
        r = self.run_sim("simulation_config.json", "-o",
                         "MQTTNode/MQTTBroker=" + broker.address)
        self.assertExit(r, 0)
        self.assertNotIn("started mosquitto", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.run_dir, "logs", "mosquitto.log")))
        # Timeout 1 s at 0.1 s: ten cycles; from the second on, each node prints what it sent
        # in the cycle before.
        for kind, text in (("str", "Hi there!"), ("proto", "position: 10"),
                           ("proto datapack", "GazeboJointDataPack('a', 'b')"),
                           ("json", "{'hi': 'there'}"),
                           ("json datapack", "JsonDataPack('dp_name', 'engine_name')")):
            n = len(re.findall(r"(?m)^Message from mqtt %s: %s" % (kind, re.escape(text)),
                               r.stdout))
            self.assertGreaterEqual(n, 5, "%s: %d\n%s" % (kind, n, r.stdout))
        self.assertEqual(sub.on("test_topic")[0], b"Hi there!")
        self.assertEqual(json.loads(sub.on("test_topic_json")[0]), {"hi": "there"})
        dp = json.loads(sub.on("test_topic_json_dp")[0])
        self.assertEqual((dp["name"], dp["engine_name"], dp["data"]),
                         ("dp_name", "engine_name", {"hi": "there"}))
        # Gazebo.Joint: field 1 (position, float) = 10.0: tag 0x0d, little-endian 10.0f.
        self.assertEqual(sub.on("test_topic_proto")[0], b"\x0d\x00\x00\x20\x41")
        wrapped = sub.on("test_topic_proto_dp")[0]
        self.assertIn(b"type.googleapis.com/Gazebo.Joint", wrapped)
        self.assertIn(b"\x0d\x00\x00\x20\x41", wrapped)
        self.assertNothingLeft()


class BadInput(ExampleCase):
    def test_unreachable_broker(self):
        self.copy_example("tf_exchange_async")
        r = self.run_sim("simulation_config_json.json", "-o",
                         "MQTTNode/MQTTBroker=mqtt.invalid:1883")
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "MQTTNode.MQTTBroker", "mqtt.invalid:1883")
        self.assertNotIn("started external process", r.stderr)  # nothing started
        self.assertNothingLeft()

    def test_bad_engine_config_in_a_run(self):
        self.copy_example("tf_exchange_async")
        with open(os.path.join(self.dir, "json_engine_async_conf_2.json")) as f:
            conf = json.load(f)
        conf["Timestep"] = "fast"
        self.write("json_engine_async_conf_2.json", conf)
        port = free_port()
        r = self.run_sim("simulation_config_json.json", "-o",
                         "MQTTNode/MQTTBroker=localhost:%d" % port, "-o", "EventLoop/Timeout=5")
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "json_engine_async_conf_2.json: /Timestep: must be a number",
                             "async_python_json_engine.py_1.log")
        self.assertLess(r.wall, 4.5, r)  # ended by the failure, not by the timeout
        self.assertNothingLeft()

    def engine(self, kind, config, env=None):
        return subprocess.run([os.path.join(BIN_DIR, "async_python_%s_engine.py" % kind),
                               "--config=" + config], cwd=self.dir, capture_output=True,
                              text=True, timeout=30, env=env)

    def test_bad_engine_configs_alone(self):
        self.copy_example("tf_exchange_async")
        cases = [({"Timestep": 0.1}, "/EngineConfig: is required"),
                 ({"EngineConfig": {"EngineName": "e"}}, "/EngineConfig/PythonFileName: is "
                                                          "required"),
                 ({"EngineConfig": {"EngineName": "e", "PythonFileName": "nope.py"}},
                  '/EngineConfig/PythonFileName: no file "nope.py"'),
                 ({"DataQueueSize": 0, "EngineConfig": {"EngineName": "e",
                                                        "PythonFileName": "engine_1.py"}},
                  "/DataQueueSize: must be an integer >= 1"),
                 ({"MQTTConfig": {"MQTTBroker": "ws://x"}, "EngineConfig": {
                     "EngineName": "e", "PythonFileName": "engine_1.py"}},
                  "/MQTTConfig/MQTTBroker"),
                 ("{not json", "not valid JSON")]
        for conf, needle in cases:
            path = self.write("bad.json", conf if isinstance(conf, dict) else conf)
            r = self.engine("json", path)
            self.assertEqual(r.returncode, 2, (conf, r.stderr))
            self.assertIn("bad.json: " + needle, r.stderr)
            self.assertEqual(len(re.findall(r"(?m)^error:", r.stderr)), 1, r.stderr)
        r = self.engine("grpc", os.path.join(self.dir, "nothing.json"))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("nothing.json: cannot read", r.stderr)
        # A broker that does not answer: exit 2 naming the key.
        env = dict(os.environ, CONVOY_MQTT_BROKER="localhost:%d" % free_port())
        r = self.engine("json", "json_engine_async_conf_1.json", env)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/MQTTConfig/MQTTBroker: cannot connect to the MQTT broker", r.stderr)
        self.assertNothingLeft()


class Signals(ExampleCase):
    def start_endless(self):
        self.copy_example("tf_exchange_async")
        p = self.start(["-o", "MQTTNode/MQTTBroker=localhost:%d" % free_port(), "-o",
                        "EventLoop/Timeout=0"], binary=NRPCORESIM,
                       config="simulation_config_json.json")
        deadline = time.monotonic() + 20
        log = os.path.join(self.run_dir, "logs", "async_python_json_engine.py_1.log")
        while "received data is {'time': 1" not in _read(log):
            self.assertLess(time.monotonic(), deadline, "engine 2 got nothing")
            time.sleep(0.05)
        self.assertGreaterEqual(len(self.scan_engine_processes()), 3)  # mosquitto, 2 engines
        return p

    def test_ctrl_c(self):
        p = self.start_endless()
        p.send_signal(signal.SIGINT)
        r = self.finish(p, 30)
        self.assertExit(r, 130)
        self.assertIn("Engine 2 is shutting down", _read(os.path.join(
            self.run_dir, "logs", "async_python_json_engine.py_1.log")))
        self.assertNothingLeft()

    def test_killed_coordinator_leaves_nothing(self):
        p = self.start_endless()
        p.kill()
        p.communicate()
        self.assertNothingLeft()


def _read(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return ""


if __name__ == "__main__":
    unittest.main()
