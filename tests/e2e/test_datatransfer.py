"""The data-transfer engine (datatransfer_grpc_engine): file dumps, MQTT streaming to a local
mosquitto broker, an unreachable broker, bad configs.

The experiment: a python_json engine `source` counts its steps into a JSON datapack (with a
numpy array); a TF relays it to the data-transfer engine `dt` as a JSON datapack, a
GazeboJointDataPack (a flat protobuf message) and a GazeboLinkDataPack (repeated fields), which
dt dumps and streams under NRP-Core's names Gazebo.Joint / Gazebo.Link.

NrpMessages: NRP-Core's message set from a python_grpc engine `pg` (Dump.String, a 2-D
Dump.ArrayFloat, NrpGenericProto.ArrayBool, a 100 KB Wrappers.BytesValue and a 128x96 camera,
both in blobs / shared memory) relayed by a TF, and Dump messages the TF makes itself
(DumpStringDataPack, 1-D and 2-D DumpArrayFloatDataPack), to files and MQTT; the MQTT payloads
decoded with nrp_protobuf.engine_grpc_pb2.DataPackMessage as an NRP-Core client would.
"""

import glob
import json
import os
import struct
import sys
import unittest

import e2e_util
from e2e_util import E2ETestCase
import mqtt_util

# The nrp_protobuf modules the build generates (build/python).
sys.path.insert(0, os.path.join(os.path.dirname(e2e_util.BIN_DIR), "python"))

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
    """Gazebo.Joint (convoy.data.Joint) serialized (proto3: zero fields left out)."""
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
              "ProtobufPackages": ["Gazebo"],
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
        self.assertEqual(link[0], "sim_time,position,rotation,linearVelocity,angularVelocity")
        self.assertEqual(link[1], "0.01,[1 2 3],[0 0 0 1],[0 0 0],[0 0 0]")
        self.assertEqual(len(link), len(counter) + 1)
        return len(counter)


class BrokerCase(DataTransferCase):
    """Runs a local mosquitto broker and subscribes to convoy/#."""

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


class Streaming(BrokerCase):
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
        from nrp_protobuf import engine_grpc_pb2
        for k, payload in enumerate(joint, start=1):
            m = engine_grpc_pb2.DataPackMessage.FromString(payload)
            self.assertEqual((m.dataPackId.dataPackName, m.dataPackId.dataPackType,
                              m.dataPackId.engineName), ("joint", "Gazebo.Joint", "dt"))
            self.assertEqual(m.data.type_url, "type.googleapis.com/Gazebo.Joint")
            self.assertEqual(m.data.value, joint_bytes(k, 0.5, -1.0))
        self.assertEqual(len(self.sub.on(base + "/data/netonly")), n)
        self.assertEqual(self.sub.on(base + "/data/link"), [])  # file only

        topic_lists = [json.loads(p) for p in self.sub.on(base + "/data") if p]
        self.assertEqual(topic_lists[0], [
            {"topic": base + "/data/counter", "type": ""},
            {"topic": base + "/data/joint", "type": ""},
            {"topic": base + "/data/netonly", "type": ""}])
        self.assertEqual(topic_lists[-1], [
            {"topic": base + "/data/counter", "type": "json"},
            {"topic": base + "/data/joint", "type": "Gazebo.Joint"},
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
                       "/EventLoop: ignored", "EventLoopTimestep is not supported yet",
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


PG = """\
import numpy as np
from nrp_core.engines.python_grpc import GrpcEngineScript
from nrp_protobuf import dump_pb2, gazebo_pb2, nrpgenericproto_pb2, wrappers_pb2
from payloads import big_bytes, pixels


class Script(GrpcEngineScript):
    def initialize(self):
        self._registerDataPack("text", dump_pb2.String)
        self._registerDataPack("grid", dump_pb2.ArrayFloat)
        self._registerDataPack("flags", nrpgenericproto_pb2.ArrayBool)
        self._registerDataPack("big", wrappers_pb2.BytesValue)
        self._registerDataPack("cam", gazebo_pb2.Camera)
        self.seq = 0

    def runLoop(self, timestep_ns):
        self.seq += 1
        k = self.seq
        self._setDataPack("text", dump_pb2.String(string_stream="pg step %d, ok" % k))
        self._setDataPack("grid", dump_pb2.ArrayFloat(float_stream=[k, k + 0.5, 2, 3, 4, 5],
                                                      dims=[2, 3]))
        self._setDataPack("flags", nrpgenericproto_pb2.ArrayBool(
            array=[True, False, k % 2 == 0, True], shape=[2, 2]))
        self._setDataPack("big", wrappers_pb2.BytesValue(value=big_bytes(k)))
        self._setDataPack("cam", gazebo_pb2.Camera(imageWidth=128, imageHeight=96, imageDepth=3,
                                                   imageData=pixels(k)))
"""

# Shared by the engine and the test: the large values of step k.
PAYLOADS = """\
def big_bytes(k):
    return (k.to_bytes(4, "little") + bytes(range(256)) * 400)[:100000]


def pixels(k):
    return bytes((i * 7 + k) % 251 for i in range(128 * 96 * 3))
"""

NRP_TF = """\
from nrp_core import *
from nrp_core.data.nrp_protobuf import *

calls = [0]


@EngineDataPack(keyword="text", id=DataPackIdentifier("text", "pg"))
@EngineDataPack(keyword="grid", id=DataPackIdentifier("grid", "pg"))
@EngineDataPack(keyword="flags", id=DataPackIdentifier("flags", "pg"))
@EngineDataPack(keyword="big", id=DataPackIdentifier("big", "pg"))
@EngineDataPack(keyword="cam", id=DataPackIdentifier("cam", "pg"))
@TransceiverFunction("dt")
def to_dt(text, grid, flags, big, cam):
    calls[0] += 1
    t = DumpStringDataPack("tf_text", "dt")
    t.data.string_stream = "tf call %d" % calls[0]
    row = DumpArrayFloatDataPack("tf_row", "dt")
    row.data.float_stream.extend([0.25, -1, calls[0]])
    row.data.dims.extend([3])
    grid2 = DumpArrayFloatDataPack("tf_grid", "dt")
    grid2.data.float_stream.extend([1, 2, 3, 4, 5])  # 3 x 2, one value missing
    grid2.data.dims.extend([3, 2])
    out = [t, row, grid2]
    if text.isEmpty():
        return out
    for name, dp, cls in (("pg_text", text, DumpStringDataPack),
                          ("pg_grid", grid, DumpArrayFloatDataPack),
                          ("pg_flags", flags, NrpGenericProtoArrayBoolDataPack),
                          ("pg_big", big, WrappersBytesValueDataPack)):
        d = cls(name, "dt")
        d.data.CopyFrom(dp.data)
        out.append(d)
    c = GazeboCameraDataPack("pg_cam", "dt")
    c.data.imageWidth, c.data.imageHeight = cam.data.imageWidth, cam.data.imageHeight
    c.data.imageDepth, c.data.imageData = cam.data.imageDepth, cam.data.imageData
    return out + [c]
"""

NRP_DUMPS = ["tf_text", "tf_row", "tf_grid", "pg_text", "pg_grid", "pg_flags", "pg_big", "pg_cam"]


class NrpMessages(BrokerCase):
    def test_nrp_messages_to_files_and_broker(self):
        self.write("pg.py", PG)
        self.write("payloads.py", PAYLOADS)
        self.write("tf.py", NRP_TF)
        self.write_config({
            "SimulationName": "datatransfer_nrp",
            "SimulationTimeout": 0.03,
            "EngineConfigs": [
                {"EngineType": "python_grpc", "EngineName": "pg", "PythonFileName": "pg.py",
                 "ProtobufPackages": ["Dump", "Gazebo", "NrpGenericProto", "Wrappers"]},
                {"EngineType": "datatransfer_grpc_engine", "EngineName": "dt",
                 "MQTTBroker": self.broker.address, "MQTTPrefix": "convoy",
                 "simulationID": "e2e",
                 # Gazebo left out: one warning for pg_cam (NRP-Core would refuse it).
                 "ProtobufPackages": ["Dump", "NrpGenericProto", "Wrappers"],
                 "dumps": [{"name": n, "file": True, "network": True} for n in NRP_DUMPS]}],
            "DataPackProcessingFunctions": [{"Name": "to_dt", "FileName": "tf.py"}]})
        r, base, messages = self.run_and_collect()
        self.assertNotIn("warning", r.stderr)  # no unknown key ProtobufPackages
        # A warning during the run goes to the engine's log, once.
        log = self.read_log("dt")
        self.assertEqual(log.count("warning"), 1, log)
        self.assertIn('datapack "pg_cam" has type Gazebo.Camera, but ProtobufPackages does not '
                      'list package "Gazebo" (NRP-Core would not carry it; Convoy does)', log)
        sys.path.insert(0, self.dir)
        try:
            from payloads import big_bytes, pixels
        finally:
            sys.path.remove(self.dir)

        # Files. The TF runs before each of dt's 3 steps (dt's time then: 0, 0.01, 0.02); pg's
        # datapacks of step k reach it at the TF call k + 1, the registered messages' defaults
        # at the first.
        files = self.dump_files()
        self.assertEqual(sorted(files), sorted(n + "-0.data" for n in NRP_DUMPS))
        times = ["0", "0.01", "0.02"]
        self.assertEqual(files["tf_text-0.data"], ["%s,tf call %d" % (t, k + 1)
                                                   for k, t in enumerate(times)])
        self.assertEqual(files["tf_row-0.data"], ["%s,0,0.25,-1,%d" % (t, k + 1)
                                                  for k, t in enumerate(times)])
        self.assertEqual(files["tf_grid-0.data"], sum((["%s," % t, "0,1,2", "1,3,4", "2,5"]
                                                       for t in times), []))
        self.assertEqual(files["pg_text-0.data"], ["0,", "0.01,pg step 1, ok",
                                                   "0.02,pg step 2, ok"])
        self.assertEqual(files["pg_grid-0.data"], ["0,0", "0.01,", "0,1,1.5,2", "1,3,4,5",
                                                   "0.02,", "0,2,2.5,2", "1,3,4,5"])
        self.assertEqual(files["pg_flags-0.data"], ["sim_time,array,shape", "0,[],[]",
                                                    "0.01,[1 0 0 1],[2 2]",
                                                    "0.02,[1 0 1 1],[2 2]"])
        self.assertEqual(files["pg_big-0.data"], ["sim_time,value", "0,",
                                                  "0.01,<100000 bytes>", "0.02,<100000 bytes>"])
        self.assertEqual(files["pg_cam-0.data"], [
            "sim_time,imageWidth,imageHeight,imageDepth,imageData", "0,0,0,0,",
            "0.01,128,96,3,<36864 bytes>", "0.02,128,96,3,<36864 bytes>"])

        # MQTT: EngineGrpc.DataPackMessage, as NRP-Core's clients decode it.
        from nrp_protobuf import (dump_pb2, engine_grpc_pb2, gazebo_pb2, nrpgenericproto_pb2,
                                  wrappers_pb2)
        types = {"tf_text": dump_pb2.String, "tf_row": dump_pb2.ArrayFloat,
                 "tf_grid": dump_pb2.ArrayFloat, "pg_text": dump_pb2.String,
                 "pg_grid": dump_pb2.ArrayFloat, "pg_flags": nrpgenericproto_pb2.ArrayBool,
                 "pg_big": wrappers_pb2.BytesValue, "pg_cam": gazebo_pb2.Camera}
        got = {}
        for name, cls in types.items():
            got[name] = []
            for payload in self.sub.on(base + "/data/" + name):
                m = engine_grpc_pb2.DataPackMessage.FromString(payload)
                full = cls.DESCRIPTOR.full_name
                self.assertEqual((m.dataPackId.dataPackName, m.dataPackId.dataPackType,
                                  m.dataPackId.engineName), (name, full, "dt"))
                self.assertEqual(m.data.type_url, "type.googleapis.com/" + full)
                data = cls()
                self.assertTrue(m.data.Unpack(data))
                got[name].append(data)
        self.assertEqual([d.string_stream for d in got["tf_text"]],
                         ["tf call 1", "tf call 2", "tf call 3"])
        # NRP-Core's field numbers (nrp-core-msgs' dump_msgs.proto): string_stream and
        # float_stream 5, dims 6.
        first = engine_grpc_pb2.DataPackMessage.FromString(self.sub.on(base + "/data/tf_text")[0])
        self.assertEqual(first.data.value, b"\x2a\x09tf call 1")
        first = engine_grpc_pb2.DataPackMessage.FromString(self.sub.on(base + "/data/tf_row")[0])
        self.assertEqual(first.data.value,
                         b"\x2a\x0c" + struct.pack("<3f", 0.25, -1, 1) + b"\x32\x01\x03")
        self.assertEqual([list(d.float_stream) for d in got["tf_grid"]], [[1, 2, 3, 4, 5]] * 3)
        self.assertEqual([list(d.dims) for d in got["tf_grid"]], [[3, 2]] * 3)
        self.assertEqual([d.string_stream for d in got["pg_text"]],
                         ["", "pg step 1, ok", "pg step 2, ok"])
        self.assertEqual([list(d.float_stream) for d in got["pg_grid"]],
                         [[], [1, 1.5, 2, 3, 4, 5], [2, 2.5, 2, 3, 4, 5]])
        self.assertEqual([list(d.array) for d in got["pg_flags"]],
                         [[], [True, False, False, True], [True, False, True, True]])
        # The large values, whole: they came to dt in blobs, not in the message's bytes.
        self.assertEqual([len(d.value) for d in got["pg_big"]], [0, 100000, 100000])
        self.assertEqual([d.value == big_bytes(k) for k, d in enumerate(got["pg_big"][1:], 1)],
                         [True, True])
        self.assertEqual([(d.imageWidth, d.imageHeight, d.imageDepth, d.imageData == pixels(k))
                          for k, d in enumerate(got["pg_cam"][1:], 1)], [(128, 96, 3, True)] * 2)
        topic_list = [json.loads(p) for p in self.sub.on(base + "/data") if p][-1]
        self.assertEqual({t["topic"].rsplit("/", 1)[1]: t["type"] for t in topic_list},
                         {n: types[n].DESCRIPTOR.full_name for n in NRP_DUMPS})



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

    def test_unknown_protobuf_package(self):
        self.check_error(2, "/EngineConfigs/1/ProtobufPackages/1", "Gazebo2",
                         ProtobufPackages=["Dump", "Gazebo2"])

    def test_broker_scheme(self):
        self.check_error(3, "MQTTBroker: scheme ws:// is not supported", MQTTBroker="ws://h:1")


if __name__ == "__main__":
    unittest.main()
