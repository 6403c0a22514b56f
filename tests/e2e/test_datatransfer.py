"""The data-transfer engine (datatransfer_grpc_engine): file dumps, MQTT streaming to a local
mosquitto broker, an unreachable broker, bad configs.

The experiment: a python_json engine `source` counts its steps into a JSON datapack (with a
numpy array); a TF relays it to the data-transfer engine `dt` as a JSON datapack, a
GazeboJointDataPack (a flat protobuf message) and a GazeboLinkDataPack (repeated fields).
"""

import glob
import json
import os
import struct
import unittest

from e2e_util import E2ETestCase
import mqtt_util

SOURCE = """\
import numpy as np
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self.step = 0
        self._registerDataPack("counter")

    def runLoop(self, timestep_ns):
        self.step += 1
        self._setDataPack("counter", {"step": self.step, "t": self._time_ns,
                                      "xs": np.array([self.step, self.step + 0.5])})
"""

TF = """\
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack, GazeboLinkDataPack


@EngineDataPack(keyword="c", id=DataPackIdentifier("counter", "source"))
@TransceiverFunction("dt")
def to_dt(c):
    if c.isEmpty():
        return []
    step = c.data["step"]
    joint = GazeboJointDataPack("joint", "dt")
    joint.data.position, joint.data.velocity, joint.data.effort = step, 0.5, -1.0
    link = GazeboLinkDataPack("link", "dt")
    link.data.position = [step, 2, 3]
    out = [JsonDataPack("counter", "dt", dict(c.data)), joint, link,
           JsonDataPack("netonly", "dt", {"step": step})]
    return out + EXTRA
"""


def joint_bytes(position, velocity, effort):
    """convoy.data.Joint serialized (proto3: zero fields left out)."""
    out = b""
    for number, value in ((1, position), (2, velocity), (3, effort)):
        if value:
            out += bytes([(number << 3) | 5]) + struct.pack("<f", value)
    return out


class DataTransferCase(E2ETestCase):
    def experiment(self, broker="localhost:1", extra_tf="[]", timeout=0.05, **dt_keys):
        self.write("source.py", SOURCE)
        self.write("tf.py", TF.replace("EXTRA", extra_tf))
        dt = {"EngineType": "datatransfer_grpc_engine", "EngineName": "dt",
              "MQTTBroker": broker, "MQTTPrefix": "convoy", "simulationID": "e2e",
              "dumps": [{"name": "counter", "network": True, "file": True},
                        {"name": "joint", "network": True, "file": True},
                        {"name": "link", "file": True},
                        {"name": "netonly", "network": True}]}
        dt.update(dt_keys)
        self.write_config({
            "SimulationName": "datatransfer",
            "SimulationTimeout": timeout,
            "EngineConfigs": [
                {"EngineType": "python_json", "EngineName": "source",
                 "PythonFileName": "source.py"},
                dt],
            "DataPackProcessingFunctions": [{"Name": "to_dt", "FileName": "tf.py"}]})

    def dump_files(self, data_dir=None):
        """{file name: lines} of the one timestamped folder under dataDirectory."""
        base = data_dir or os.path.join(self.run_dir, "data")
        folders = glob.glob(os.path.join(base, "*"))
        self.assertEqual(len(folders), 1, folders)
        self.assertRegex(os.path.basename(folders[0]), r"^\d{8}-\d{6}-\d+$")
        files = {}
        for path in sorted(glob.glob(os.path.join(folders[0], "*"))):
            with open(path) as f:
                files[os.path.basename(path)] = f.read().splitlines()
        return files

    def check_files(self, files):
        self.assertEqual(sorted(files), ["counter-0.data", "joint-0.data", "link-0.data"])
        counter = files["counter-0.data"]
        self.assertGreaterEqual(len(counter), 3, counter)
        for i, line in enumerate(counter):
            t, value = line.split(",", 1)
            data = json.loads(value)
            # Step k's datapack reaches dt before dt's step k+1, at dt's time k * 0.01 s.
            self.assertEqual(data, {"step": i + 1, "t": (i + 1) * 10_000_000,
                                    "xs": [i + 1, i + 1.5]})
            self.assertEqual(t, "%g" % ((i + 1) * 0.01))
        joint = files["joint-0.data"]
        self.assertEqual(joint[0], "sim_time,position,velocity,effort")
        self.assertEqual(joint[1:], ["%g,%d,0.5,-1" % ((i + 1) * 0.01, i + 1)
                                     for i in range(len(counter))])
        link = files["link-0.data"]
        self.assertEqual(link[0], "sim_time,position,rotation,linear_velocity,angular_velocity")
        self.assertEqual(link[1], "0.01,[1 2 3],[0 0 0 1],[0 0 0],[0 0 0]")
        self.assertEqual(len(link), len(counter) + 1)
        return len(counter)


class Streaming(DataTransferCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(mqtt_util.MOSQUITTO, os.X_OK):
            raise unittest.SkipTest("%s is missing (Debian package mosquitto): no MQTT tests"
                                    % mqtt_util.MOSQUITTO)

    def setUp(self):
        super().setUp()
        self.broker = mqtt_util.Broker()
        self.sub = mqtt_util.Subscriber(self.broker.port, "convoy/#")

    def tearDown(self):
        self.sub.close()
        self.broker.stop()
        super().tearDown()

    def run_and_collect(self):
        r = self.run_convoy()
        self.assertExit(r, 0)
        base = "convoy/nrp_simulation/e2e"
        # The last message of a run clears the retained topic list.
        messages = self.sub.wait_for(
            lambda ms: (base + "/data", b"", False) in ms)
        self.assertIn((base + "/data", b"", False), messages, r)
        return r, base, messages

    def test_datapacks_reach_files_and_broker(self):
        self.experiment(broker=self.broker.address)
        r, base, messages = self.run_and_collect()
        self.assertNotIn("warning", r.stderr)
        n = self.check_files(self.dump_files())

        self.assertEqual(self.sub.on(base + "/welcome"),
                         [b"NRP-core is connected!", b"Bye! NRP-core is disconnecting!", b""])
        times = self.sub.on(base + "/time")
        self.assertEqual(times, [("%g" % (k * 0.01)).encode() for k in range(1, 6)])

        counter = [json.loads(p) for p in self.sub.on(base + "/data/counter")]
        self.assertEqual(len(counter), n)
        self.assertEqual(counter[0], {
            "datapackId": {"dataPackName": "counter", "engineName": "dt", "dataPackType": "json"},
            "data": {"step": 1, "t": 10_000_000, "xs": [1, 1.5]}})
        joint = self.sub.on(base + "/data/joint")
        self.assertEqual(len(joint), n)
        # EngineGrpc.DataPackMessage{datapackId{name, engine, type}, Any{type_url, value}}
        for k, payload in enumerate(joint, start=1):
            for part in (b"joint", b"dt", b"convoy.data.Joint",
                         b"type.googleapis.com/convoy.data.Joint", joint_bytes(k, 0.5, -1.0)):
                self.assertIn(part, payload)
        self.assertEqual(len(self.sub.on(base + "/data/netonly")), n)
        self.assertEqual(self.sub.on(base + "/data/link"), [])  # file only

        topic_lists = [json.loads(p) for p in self.sub.on(base + "/data") if p]
        self.assertEqual(topic_lists[0], [
            {"topic": base + "/data/counter", "type": ""},
            {"topic": base + "/data/joint", "type": ""},
            {"topic": base + "/data/netonly", "type": ""}])
        self.assertEqual(topic_lists[-1], [
            {"topic": base + "/data/counter", "type": "json"},
            {"topic": base + "/data/joint", "type": "convoy.data.Joint"},
            {"topic": base + "/data/netonly", "type": "json"}])

    def test_stream_data_only(self):
        self.experiment(broker=self.broker.address, streamDataPackMessage=False)
        r, base, messages = self.run_and_collect()
        counter = [json.loads(p) for p in self.sub.on(base + "/data/counter")]
        self.assertEqual(counter[1], {"step": 2, "t": 20_000_000, "xs": [2, 2.5]})
        joint = self.sub.on(base + "/data/joint")
        self.assertEqual(joint, [joint_bytes(k, 0.5, -1.0) for k in range(1, len(joint) + 1)])
        self.assertGreaterEqual(len(joint), 3)


class Files(DataTransferCase):
    def test_broker_unreachable_warns_once_and_files_go_on(self):
        port = mqtt_util.free_port()  # nothing listens there
        self.experiment(broker="localhost:%d" % port)
        r = self.run_convoy()
        self.assertExit(r, 0)
        warning = ("warning: engine 'dt': MQTT broker \"localhost:%d\" (MQTTBroker) cannot be "
                   "reached" % port)
        self.assertEqual(r.stderr.count(warning), 1, r)
        self.assertIn("dropped: netonly", r.stderr)
        with open(os.path.join(self.run_dir, "logs", "dt.log")) as f:
            self.assertEqual(f.read().count("localhost:%d" % port), 1)
        self.check_files(self.dump_files())

    def test_broker_that_does_not_answer(self):
        # Accepts TCP (the kernel's backlog) and never answers CONNECT: 5 s, then files only.
        import socket
        with socket.socket() as silent:
            silent.bind(("127.0.0.1", 0))
            silent.listen(4)
            address = "127.0.0.1:%d" % silent.getsockname()[1]
            self.experiment(broker=address)
            r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertStderrHas(r, 'MQTT broker "%s" (MQTTBroker) cannot be reached: no answer '
                             'within 5 s' % address)
        self.check_files(self.dump_files())

    def test_unsupported_nrp_core_keys_warn_once_by_name(self):
        self.experiment()
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        cfg.update({"ProcessLauncherType": "Docker", "EventLoop": {"Timeout": 1},
                    "ROSNode": {}, "MQTTNode": {"MQTTBroker": "localhost:1"},
                    "EventLoopTimestep": 0.1})
        cfg["EngineConfigs"][1]["EngineExtraConfigs"] = {}
        self.write_config(cfg)
        r = self.run_convoy()
        self.assertExit(r, 0)
        for needle in ("ProcessLauncherType Docker is not available",
                       "EventLoop is not supported yet", "EventLoopTimestep is not supported yet",
                       "ROSNode is not supported yet", "MQTTNode is not supported yet",
                       "/EngineConfigs/1/EngineExtraConfigs: unknown key"):
            self.assertEqual(r.stderr.count(needle), 1, "%s: %r" % (needle, r))

    def test_same_config_same_files(self):
        self.experiment()
        first = self.run_convoy()
        self.assertExit(first, 0)
        files = self.dump_files()
        self.check_files(files)
        self.run_dir = os.path.join(self.dir, "run2")
        self.assertExit(self.run_convoy(), 0)
        self.assertEqual(self.dump_files(), files)

    def test_data_directory_as_given(self):
        target = os.path.join(self.dir, "elsewhere", "dumps")
        self.experiment(dataDirectory=target)
        self.assertExit(self.run_convoy(), 0)
        self.check_files(self.dump_files(target))
        self.assertFalse(os.path.exists(os.path.join(self.run_dir, "data")))

    def test_datapack_not_in_dumps_is_an_error(self):
        self.experiment(extra_tf='[JsonDataPack("stray", "dt", {})]')
        r = self.run_convoy()
        self.assertExit(r, 3)
        self.assertStderrHas(r, "'dt'", 'datapack "stray" is not listed in the "dumps" of engine '
                             '"dt" (listed: counter, joint, link, netonly)')


class BadConfig(DataTransferCase):
    def check_error(self, code, *needles, **dt_keys):
        self.experiment(**dt_keys)
        r = self.run_convoy()
        self.assertExit(r, code)
        self.assertStderrHas(r, *needles)
        self.assertOneError(r)

    def test_dump_name_escaping_the_folder(self):
        self.check_error(2, "/EngineConfigs/1/dumps/0/name: must not contain '/', '\\' or '..'",
                         dumps=[{"name": "../x", "file": True}])

    def test_dump_without_name(self):
        self.check_error(2, "/EngineConfigs/1/dumps/0", "name",
                         dumps=[{"file": True}])

    def test_dump_flag_not_boolean(self):
        self.check_error(2, "/EngineConfigs/1/dumps/0/network",
                         dumps=[{"name": "a", "network": "yes"}])

    def test_dump_listed_twice(self):
        self.check_error(3, "dumps/1/name: \"a\" is listed twice",
                         dumps=[{"name": "a", "file": True}, {"name": "a", "network": True}])

    def test_topic_with_wildcard(self):
        self.check_error(3, "dumps/0/name: an MQTT topic must not contain the wildcards",
                         dumps=[{"name": "a+b", "network": True}])

    def test_data_directory_that_cannot_be_made(self):
        self.write("a_file", "x")
        self.check_error(3, "dataDirectory: cannot create the folder",
                         dataDirectory=os.path.join(self.dir, "a_file", "sub"))

    def test_empty_data_directory(self):
        self.check_error(2, "/EngineConfigs/1/dataDirectory", dataDirectory="")

    def test_broker_scheme(self):
        self.check_error(3, "MQTTBroker: scheme ws:// is not supported", MQTTBroker="ws://h:1")


if __name__ == "__main__":
    unittest.main()
