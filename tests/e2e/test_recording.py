"""Record, replay, re-score (docs/recording.md): `convoy run --record`, the MCAP file read back
by python/convoy_mcap and by the official @mcap/core (tools/mcap_check, when npm installed it),
`convoy replay` and `convoy score`, and their bad inputs."""
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import textwrap
import time
import unittest

from e2e_util import CONVOY, REPO, E2ETestCase

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_mcap import McapError, Recording, untag  # noqa: E402

MCAP_CHECK = os.path.join(REPO, "tools", "mcap_check")

# A python_json engine whose state needs every digit of its doubles, with a NaN, a numpy
# array and (with BIG) a numpy array large enough to travel as a blob.
CAR = textwrap.dedent('''\
    import math, os
    import numpy as np
    from nrp_core.engines.python_json import EngineScript

    def state(t):
        s = t * 1e-9
        return {"x": math.sin(s * 1.37) * 1000.0 / 7.0, "y": 0.1 + 0.2 + s, "t": t,
                "tiny": 5e-324, "nan": float("nan"), "inf": -math.inf, "tags": ["a", "b"],
                "arr": np.array([s, s / 3.0, -s], dtype=np.float64),
                "big": np.full(9000, s, dtype=np.float32)}

    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("state")
            self._registerDataPack("ctl")
            self._setDataPack("state", state(0))

        def runLoop(self, timestep_ns):
            self._setDataPack("state", state(self._time_ns))
    ''')

# A python_grpc engine: a protobuf double, and a frame-sized bytes value (a blob).
WORLD = textwrap.dedent('''\
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from nrp_protobuf import wrappers_pb2

    class Script(GrpcEngineScript):
        def initialize(self):
            self._registerDataPack("speed", wrappers_pb2.DoubleValue)
            self._registerDataPack("frame", wrappers_pb2.BytesValue)
            self._registerDataPack("cmd", wrappers_pb2.DoubleValue)
            self._registerDataPack("frame_echo", wrappers_pb2.BytesValue)
            self.n = 0
            self._publish()

        def _publish(self):
            self._setDataPack("speed", wrappers_pb2.DoubleValue(value=self.n / 3.0 + 1e-17))
            self._setDataPack("frame", wrappers_pb2.BytesValue(value=bytes([self.n % 251]) * 40000))

        def runLoop(self, timestep_ns):
            self.n += 1
            self._publish()
    ''')

CONTROL_TF = textwrap.dedent('''\
    from nrp_core import *
    from nrp_core.data.nrp_json import *
    from nrp_core.data.nrp_protobuf import WrappersDoubleValueDataPack, WrappersBytesValueDataPack

    GAIN = 0.7
    READ_BLOB = False  # the blob's contents are zeros in a replay without --record-blobs

    @EngineDataPack(keyword="car", id=DataPackIdentifier("state", "car"))
    @EngineDataPack(keyword="speed", id=DataPackIdentifier("speed", "world"))
    @EngineDataPack(keyword="frame", id=DataPackIdentifier("frame", "world"))
    @TransceiverFunction("world")
    def control(car, speed, frame):
        cmd = WrappersDoubleValueDataPack("cmd", "world")
        cmd.data.value = GAIN * car.data["x"] / (1.0 + speed.data.value)
        out = [cmd]
        if not frame.isEmpty():
            echo = WrappersBytesValueDataPack("frame_echo", "world")
            echo.data.value = frame.data.value
            out.append(echo)
        ctl = JsonDataPack("ctl", "car")
        ctl.data["steer"] = car.data["y"] * GAIN
        big = car.data["big"]
        ctl.data["sum"] = float(car.data["arr"].sum()) + (float(big[-1]) if READ_BLOB else big.shape[0])
        ctl.data["frame_len"] = 0 if frame.isEmpty() else len(frame.data.value)
        out.append(ctl)
        return out
    ''')

# The test's scoring function: non-trivial float arithmetic over the recorded datapacks,
# written into summary.json as driving_score, as a metrics TF would.
METRIC_TF = textwrap.dedent('''\
    import json, math, os
    from nrp_core import *

    ACC = {"s": 0.0, "p": 1.0, "n": 0}

    @EngineDataPack(keyword="car", id=DataPackIdentifier("state", "car"))
    @EngineDataPack(keyword="speed", id=DataPackIdentifier("speed", "world"))
    @SimulationTime(keyword="t")
    @TransceiverFunction("car")
    def metric(car, speed, t):
        ACC["s"] += math.sqrt(car.data["x"] ** 2 + car.data["y"] ** 2) / (3.0 + speed.data.value)
        ACC["p"] *= 1.0 - 1e-3 * math.fabs(math.sin(car.data["x"]))
        ACC["n"] += 1
        path = os.path.join(os.environ["CONVOY_RUN_DIR"], "summary.json")
        try:
            with open(path) as f:
                s = json.load(f)
        except (OSError, ValueError):
            s = {}
        s.update({"driving_score": ACC["s"] / ACC["n"] * ACC["p"], "route_completion": ACC["s"] / 7.0,
                  "infraction_penalty": ACC["p"], "infractions": [{"time_ns": t, "kind": "none"}][:ACC["n"] % 2]})
        with open(path, "w") as f:
            json.dump(s, f)
        return []
    ''')


def config(timeout=0.2, tfs=("control_tf.py", "metric_tf.py")):
    return {
        "SimulationName": "recording",
        "SimulationTimeout": timeout,
        "EngineConfigs": [
            {"EngineType": "python_json", "EngineName": "car", "PythonFileName": "car.py",
             "EngineTimestep": 0.01},
            {"EngineType": "python_grpc", "EngineName": "world", "PythonFileName": "world.py",
             "EngineTimestep": 0.02},
        ],
        "DataPackProcessingFunctions": [{"Name": os.path.splitext(f)[0], "FileName": f}
                                        for f in tfs],
    }


def node_check(path):
    """@mcap/core's verdict on `path` (a dict), or None when it is not installed."""
    if not shutil.which("node") or not os.path.isdir(os.path.join(MCAP_CHECK, "node_modules", "@mcap")):
        return None
    r = subprocess.run(["node", os.path.join(MCAP_CHECK, "check.mjs"), path],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
    assert r.returncode == 0, "@mcap/core refused %s: %s %s" % (path, r.stdout, r.stderr)
    return json.loads(r.stdout)


class RecordingTestCase(E2ETestCase):
    def setUp(self):
        super().setUp()
        self.write("car.py", CAR)
        self.write("world.py", WORLD)
        self.write("control_tf.py", CONTROL_TF)
        self.write("metric_tf.py", METRIC_TF)
        self.write_config(config())

    def convoy(self, *args, timeout=60):
        t0 = time.monotonic()
        p = subprocess.run([CONVOY] + list(args), cwd=self.dir, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True,
                           timeout=timeout)
        p.wall = time.monotonic() - t0
        return p

    def record(self, *args):
        r = self.run_convoy(*args, timeout=60)
        return r

    @property
    def mcap(self):
        return os.path.join(self.run_dir, "recording.mcap")


class Record(RecordingTestCase):
    pass


def _reads_back(self):
    r = self.record("--record")
    self.assertExit(r, 0)
    rec = Recording(self.mcap)
    self.assertTrue(rec.complete, rec.incomplete)
    meta = rec.metadata["convoy"]
    self.assertEqual(meta["format"], "convoy-recording-1")
    self.assertEqual(json.loads(meta["config"])["SimulationName"], "recording")
    self.assertEqual(rec.metadata["convoy_end"]["exit_code"], "0")
    msgs = list(rec.messages())
    self.assertEqual({m.topic for m in msgs},
                     {"car/state", "world/speed", "world/frame", "world/cmd/in",
                      "world/frame_echo/in", "car/ctl/in"})
    # car steps every 10 ms, world every 20 ms: sequence = loop cycle, log_time = its time.
    states = [m for m in msgs if m.topic == "car/state"]
    self.assertEqual([m.log_time for m in states], [i * 10_000_000 for i in range(21)])
    self.assertEqual([m.sequence for m in states], list(range(21)))
    self.assertTrue(all(m.publish_time == m.log_time for m in msgs))
    speeds = [m for m in msgs if m.topic == "world/speed"]
    self.assertEqual([m.log_time for m in speeds], [i * 20_000_000 for i in range(11)])
    self.assertEqual([m.sequence for m in speeds], [0] + [2 * i for i in range(1, 11)])
    # Doubles that need 17 digits come back bit for bit; NaN, -inf and 5e-324 too.
    import math
    for m in states:
        s = m.log_time * 1e-9
        v = untag(m.value)
        self.assertEqual(struct.pack("<d", v["x"]),
                         struct.pack("<d", math.sin(s * 1.37) * 1000.0 / 7.0))
        self.assertEqual(struct.pack("<d", v["y"]), struct.pack("<d", 0.1 + 0.2 + s))
        self.assertEqual(v["tiny"], 5e-324)
        self.assertTrue(math.isnan(v["nan"]))
        self.assertEqual(v["inf"], -math.inf)
        self.assertEqual(list(v["arr"]), [s, s / 3.0, -s])
        big = m.value["big"]["__ndarray__"]  # a blob: a stub without --record-blobs
        self.assertEqual((big["dtype"], big["shape"], big["size"]), ("<f4", [9000], 36000))
        self.assertNotIn("data", big)
    self.assertIn('"y":0.30000000000000004', states[0].data.decode())
    # Protobuf: the message's bytes, its FileDescriptorSet as schema.
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    self.assertEqual(speeds[0].encoding, "protobuf")
    self.assertEqual(speeds[0].schema_name, "Wrappers.DoubleValue")
    schema = rec.schemas[speeds[0].channel.schema_id]
    self.assertEqual(schema.encoding, "protobuf")
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    pool = descriptor_pool.DescriptorPool()
    for f in fds.file:
        pool.Add(f)
    cls = message_factory.MessageFactory(pool).GetPrototype(
        pool.FindMessageTypeByName("Wrappers.DoubleValue"))
    self.assertEqual(cls.FromString(speeds[3].value).value, 3 / 3.0 + 1e-17)
    # The frame (a blob) without --record-blobs: a stub with its size.
    frames = [m for m in msgs if m.topic == "world/frame"]
    stub = frames[0].value["__stub__"]
    self.assertEqual((stub["type"], stub["size"], frames[0].schema_name),
                     ("Wrappers.BytesValue", 40000, "convoy.BlobStub"))
    self.assertLess(os.path.getsize(self.mcap), 200_000)
    # Chunks compressed with zstd (a chunk that zstd would not shrink may stay uncompressed).
    compressions = {ci["compression"] for ci in rec.chunk_indexes if ci["uncompressed"] > 1024}
    self.assertEqual(compressions, {"zstd"})
    # The official MCAP library reads it too: both readers, every CRC, the indexes.
    got = node_check(self.mcap)
    if got is None:
        raise unittest.SkipTest("@mcap/core not installed (scripts/setup.sh: npm ci in tools/mcap_check)")
    self.assertTrue(got["stream"]["done"])
    self.assertEqual(got["indexed"]["messages"], len(msgs))
    self.assertEqual(got["indexed"]["statistics_messages"], len(msgs))
    self.assertTrue(got["indexed"]["data_section_crc_ok"])
    self.assertTrue(got["indexed"]["log_time_ordered"])
    self.assertEqual(got["indexed"]["metadata_names"], ["convoy", "convoy_end"])
    self.assertIn("zstd", got["indexed"]["chunk_compressions"])
    self.assertLess(got["indexed"]["compressed_bytes"], got["indexed"]["uncompressed_bytes"])


Record.test_recording_reads_back_exactly = _reads_back


class Replay(RecordingTestCase):
    def test_replay_and_score_are_identical(self):
        self.assertExit(self.record("--record"), 0)
        live = self.summary()
        self.assertIn("driving_score", live)
        r = self.convoy("replay", self.run_dir)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("0 mismatches", r.stderr)
        with open(os.path.join(self.run_dir, "replay", "summary.json")) as f:
            replayed = json.load(f)
        self.assertEqual(replayed["replay"]["mismatches"], 0)
        self.assertEqual(replayed["replay"]["compared"], 33)  # cmd, frame_echo, ctl 11 times
        self.assertEqual(replayed["replay"]["blob_placeholders"], 32)  # 21 arrays + 11 frames
        self.assertEqual(replayed["cycles"], live["cycles"])
        # The functions' fields come out the same, bit for bit.
        self.assertEqual(json.dumps(replayed["driving_score"]), json.dumps(live["driving_score"]))
        s = self.convoy("score", self.run_dir)
        self.assertEqual(s.returncode, 0, s.stdout + s.stderr)
        self.assertIn("driving_score is bit-identical to the live one", s.stdout)
        self.assertRegex(s.stdout, r"(?m)^driving_score\s+\S+\s+\S+\s+yes$")
        self.assertTrue(os.path.isfile(os.path.join(self.run_dir, "rescore", "summary.json")))
        self.assertNoEngineLeft()

    def test_replay_with_blobs(self):
        self.write("control_tf.py", CONTROL_TF.replace("READ_BLOB = False", "READ_BLOB = True"))
        self.assertExit(self.record("--record-blobs"), 0)
        rec = Recording(self.mcap)
        frames = [m for m in rec.messages(topics={"world/frame"})]
        self.assertEqual(frames[0].encoding, "protobuf")
        self.assertEqual(len(frames[0].value), 40000 + 4)  # tag + length + bytes
        states = [m for m in rec.messages(topics={"car/state"})]
        self.assertEqual(len(untag(states[3].value)["big"]), 9000)
        # The blobs are all there (in zstd chunks, which shrink them: count before compression).
        self.assertGreater(sum(ci["uncompressed"] for ci in rec.chunk_indexes),
                           21 * 36000 + 11 * 40000)
        self.assertIsNotNone(node_check(self.mcap) or True)
        r = self.convoy("replay", self.run_dir, "--out", os.path.join(self.dir, "rb"))
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.dir, "rb", "summary.json")) as f:
            rep = json.load(f)["replay"]
        self.assertEqual((rep["mismatches"], rep["blob_placeholders"]), (0, 0))

    def test_a_changed_function_is_caught(self):
        self.assertExit(self.record("--record"), 0)
        self.write("control_tf.py", CONTROL_TF.replace("GAIN = 0.7", "GAIN = 0.7000001"))
        r = self.convoy("replay", self.run_dir)
        self.assertEqual(r.returncode, 5, r.stderr)
        self.assertIn("mismatch: car/ctl/in at cycle 0: different value: {\"steer\":0.21000003", r.stderr)
        with open(os.path.join(self.run_dir, "replay", "summary.json")) as f:
            rep = json.load(f)["replay"]
        self.assertEqual(rep["mismatches"], 21)  # ctl 11 times, cmd 10 (x = 0 at cycle 0)
        self.assertEqual(rep["first_mismatches"][1]["topic"], "world/cmd/in")
        # The scoring function changed: score says which field differs.
        self.write("control_tf.py", CONTROL_TF)
        self.write("metric_tf.py", METRIC_TF.replace("/ 7.0", "/ 7.000001"))
        s = self.convoy("score", self.run_dir)
        self.assertEqual(s.returncode, 5, s.stdout + s.stderr)
        self.assertRegex(s.stdout, r"(?m)^route_completion\s+\S+\s+\S+\s+NO$")
        self.assertRegex(s.stdout, r"(?m)^driving_score\s+\S+\s+\S+\s+yes$")

    def test_a_function_reading_what_was_not_recorded(self):
        self.assertExit(self.record("--record"), 0)
        other = config()
        self.write("extra_tf.py", textwrap.dedent('''\
            from nrp_core import *
            @EngineDataPack(keyword="ctl", id=DataPackIdentifier("ctl", "car"))
            @TransceiverFunction("car")
            def extra(ctl):
                return []
            '''))
        other["DataPackProcessingFunctions"].append({"Name": "extra", "FileName": "extra_tf.py"})
        self.write_config(other, "other.json")
        r = self.convoy("replay", self.run_dir, "-c", os.path.join(self.dir, "other.json"))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("recording.mcap: the functions read datapack 'ctl' of engine 'car', which "
                      "the recording does not hold (topic 'car/ctl')", r.stderr)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)


class BadRecordings(RecordingTestCase):
    def replay_fails(self, *needles):
        r = self.convoy("replay", self.run_dir)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)
        for n in needles:
            self.assertIn(n, r.stderr)
        return r

    def test_no_recording(self):
        self.assertExit(self.record(), 0)
        self.assertFalse(os.path.exists(self.mcap))
        self.replay_fails(self.mcap + ": no recording here (record a run with `convoy run --record`)")

    def test_truncated(self):
        self.assertExit(self.record("--record"), 0)
        size = os.path.getsize(self.mcap)
        with open(self.mcap, "r+b") as f:
            f.truncate(size // 2)
        with self.assertRaises(Exception):
            r = Recording(self.mcap)
            if not r.complete:
                raise McapError(r.incomplete)
        self.replay_fails(self.mcap + ": incomplete recording")

    def test_garbled(self):
        self.assertExit(self.record("--record"), 0)
        with open(self.mcap, "r+b") as f:
            f.seek(2000)
            b = f.read(1)
            f.seek(2000)
            f.write(bytes([b[0] ^ 0x40]))
        with self.assertRaises(McapError):
            Recording(self.mcap)
        # Inside a zstd chunk, a flipped byte may break the compressed stream before the
        # chunk's CRC (of its uncompressed records) can be checked.
        r = self.replay_fails(self.mcap + ": ")
        self.assertRegex(r.stderr, "CRC does not match|zstd chunk does not decompress")

    def test_not_mcap(self):
        os.makedirs(self.run_dir)
        with open(self.mcap, "w") as f:
            f.write("hello")
        self.replay_fails(self.mcap + ": not an MCAP file")


class FailedRuns(RecordingTestCase):
    def test_a_raising_function_leaves_a_valid_recording(self):
        self.write("metric_tf.py", METRIC_TF.replace('ACC["n"] += 1', 'ACC["n"] += 1\n'
                                                     '    if ACC["n"] == 6: raise ValueError("boom")'))
        r = self.record("--record")
        self.assertExit(r, 4)
        rec = Recording(self.mcap)
        self.assertTrue(rec.complete, rec.incomplete)
        self.assertEqual(rec.metadata["convoy_end"]["exit_code"], "4")
        self.assertIn("boom", rec.metadata["convoy_end"]["error"])
        self.assertEqual(max(m.sequence for m in rec.messages()), 5)
        if node_check(self.mcap) is None:
            pass
        self.assertNoEngineLeft()

    def test_ctrl_c_leaves_a_valid_recording(self):
        self.write_config(config(timeout=0))
        p = self.start(["--record"])
        time.sleep(3.0)
        p.send_signal(signal.SIGINT)
        r = self.finish(p)
        self.assertExit(r, 130)
        rec = Recording(self.mcap)
        self.assertTrue(rec.complete, rec.incomplete)
        self.assertEqual(rec.metadata["convoy_end"]["exit_code"], "130")
        self.assertGreater(sum(1 for _ in rec.messages()), 10)
        node_check(self.mcap)
        # A replay goes exactly as far.
        r = self.convoy("replay", self.run_dir)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_an_engine_crash_leaves_a_valid_recording(self):
        self.write("car.py", CAR.replace("self._setDataPack(\"state\", state(self._time_ns))",
                                         "self._setDataPack(\"state\", state(self._time_ns))\n"
                                         "        if self._time_ns >= 50_000_000: os._exit(9)"))
        r = self.record("--record")
        self.assertExit(r, 3)
        self.assertStderrHas(r, "engine 'car' died")
        rec = Recording(self.mcap)
        self.assertTrue(rec.complete, rec.incomplete)
        self.assertEqual(rec.metadata["convoy_end"]["exit_code"], "3")
        node_check(self.mcap)
        r = self.convoy("replay", self.run_dir)
        self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == "__main__":
    unittest.main()
