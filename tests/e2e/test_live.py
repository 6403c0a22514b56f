"""The live server (`convoy run --live [HOST:]PORT`, docs/architecture.md "Live server"):
Foxglove's own protocol client (@foxglove/ws-protocol's FoxgloveClient, tools/live_check,
when npm installed it) watches the wheeled-robot experiment (a world engine with a camera,
JSON and protobuf datapacks; about 2 s) while a client sends garbage and another one drops its
connection mid-frame; and the addresses that must be refused before any engine starts.
Control, View and the rest: test_live_control.py."""
import json
import os
import re
import shutil
import socket
import subprocess
import tempfile
import unittest

from e2e_util import CONVOY, REPO, free_port

LIVE_CHECK = os.path.join(REPO, "tools", "live_check")
CONFIG = os.path.join(REPO, "experiments", "wheeled_robot", "simulation_config.json")
SIM_S = "6"  # simulated seconds: about 1.5 s of wall time, 300 loop cycles
CAMERA = "gazebo/robot_camera::camera"


def have_client():
    return shutil.which("node") and os.path.isdir(
        os.path.join(LIVE_CHECK, "node_modules", "@foxglove", "ws-protocol"))



def convoy(tmp, name, *extra):
    return [CONVOY, "run", "-c", CONFIG, "-o", "SimulationTimeout=" + SIM_S, "--run-dir",
            os.path.join(tmp, name), *extra]


def read(path):
    with open(path, "rb") as f:
        return f.read()


class Watched(unittest.TestCase):
    """One run without a viewer and one with three clients: subscribed to everything, sending
    garbage, disconnecting mid-frame."""

    @classmethod
    def setUpClass(cls):
        if not have_client():
            raise unittest.SkipTest("@foxglove/ws-protocol not installed "
                                    "(scripts/setup.sh: npm ci in tools/live_check)")
        cls.tmp = tempfile.mkdtemp(prefix="convoy_live_")
        plain = subprocess.run(convoy(cls.tmp, "plain", "-q"), capture_output=True, text=True,
                               timeout=60)
        assert plain.returncode == 0, plain.stderr
        port = free_port()
        url = "ws://127.0.0.1:%d" % port
        clients = {}
        for mode in ("all", "garbage", "disconnect"):
            out = os.path.join(cls.tmp, mode + ".json")
            clients[mode] = (subprocess.Popen(
                ["node", os.path.join(LIVE_CHECK, "check.mjs"), "--url", url, "--mode", mode,
                 "--out", out, "--wait", "30", "--timeout", "60"],
                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True), out)
        # --record too: the recorder and the live server tap the same loop.
        cls.live = subprocess.run(convoy(cls.tmp, "live", "--live", str(port), "--record"),
                                  capture_output=True, text=True, timeout=60)
        cls.got = {}
        for mode, (proc, out) in clients.items():
            _, err = proc.communicate(timeout=30)
            cls.got[mode] = json.loads(read(out)) if os.path.exists(out) else {"stderr": err}
            cls.got[mode]["exit"] = proc.returncode
        with open(os.path.join(cls.tmp, "live", "summary.json")) as f:
            cls.summary = json.load(f)

    @classmethod
    def tearDownClass(cls):
        if os.environ.get("CONVOY_E2E_KEEP") != "1":
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_run_completes_as_without_viewers(self):
        self.assertEqual(self.live.returncode, 0, self.live.stderr)
        self.assertIn("live: serving at ws://127.0.0.1:", self.live.stderr)
        for name in ("trajectory.csv", "camera.png"):
            self.assertEqual(read(os.path.join(self.tmp, "plain", name)),
                             read(os.path.join(self.tmp, "live", name)), name)

    def test_the_recording_is_made_alongside(self):
        self.assertTrue(os.path.exists(os.path.join(self.tmp, "live", "recording.mcap")))
        recorded = re.search(r"recording: (\d+) messages", self.live.stderr)
        self.assertIsNotNone(recorded, self.live.stderr)
        # At least every message the full-speed client got of the datapack topics.
        got = self.got["all"]["messages"]
        datapacks = sum(m["count"] for t, m in got.items()
                        if not t.startswith("/convoy") and not t.endswith(("/image", "/calibration")))
        self.assertGreaterEqual(int(recorded.group(1)), datapacks)
        self.assertGreater(datapacks, 1000)

    def test_channels_are_advertised_with_their_schemas(self):
        got = self.got["all"]
        self.assertEqual(got["exit"], 0, got)
        self.assertTrue(got["closed"], "the server should close the connection at the end")
        self.assertTrue(got["serverInfo"]["name"].startswith("convoy"))
        self.assertIn("time", got["serverInfo"]["capabilities"])
        channels = {c["topic"]: c for c in got["channels"]}
        expect = {
            "/convoy/log": ("json", "foxglove.Log", "jsonschema"),
            CAMERA + "/image": ("json", "foxglove.CompressedImage", "jsonschema"),
            CAMERA + "/calibration": ("json", "foxglove.CameraCalibration", "jsonschema"),
            CAMERA + "::boxes": ("json", "convoy.JsonDataPack", "jsonschema"),
            "gazebo/robot::chassis": ("protobuf", "convoy.data.Link", "protobuf"),
            "gazebo/robot_joint_plugin::j_fl/in": ("protobuf", "convoy.data.Joint", "protobuf"),
            "logger/pose/in": ("json", "convoy.JsonDataPack", "jsonschema"),
            CAMERA: ("json", "convoy.BlobStub", "jsonschema"),
        }
        for topic, (encoding, schema, schema_encoding) in expect.items():
            self.assertIn(topic, channels)
            c = channels[topic]
            self.assertEqual((c["encoding"], c["schemaName"], c["schemaEncoding"]),
                             (encoding, schema, schema_encoding), topic)
            self.assertGreater(c["schemaBytes"], 20, topic)
        self.assertEqual(len(channels), len(got["channels"]), "a topic advertised twice")

    def test_each_kind_of_message_decodes(self):
        m = self.got["all"]["messages"]
        boxes = m[CAMERA + "::boxes"]["first"]["json"]
        self.assertEqual((boxes["width"], boxes["height"]), (320, 240))
        self.assertIsInstance(boxes["boxes"], list)
        pose = m["logger/pose/in"]["first"]["json"]
        self.assertIn("x", pose)
        self.assertIn("speed", pose)
        image = m[CAMERA + "/image"]["first"]
        self.assertEqual(image["format"], "jpeg")
        self.assertEqual((image["head"], image["tail"]), ("ffd8ff", "ffd9"))
        self.assertGreater(image["jpeg_bytes"], 1000)
        cal = m[CAMERA + "/calibration"]["first"]["json"]
        self.assertEqual((cal["width"], cal["height"], len(cal["K"])), (320, 240, 9))
        self.assertGreater(m["gazebo/robot::chassis"]["first"]["bytes"], 10)
        log = [line for line in (m["/convoy/log"]["first"]["json"]["message"],)]
        self.assertIn("live: serving at", log[0])
        self.assertEqual(m["/convoy/log"]["first"]["json"]["level"], 2)

    def test_rates_and_time(self):
        got = self.got["all"]
        m = got["messages"]
        cycles = self.summary["cycles"]
        # Every datapack of the run once it was subscribed (a few cycles pass first), the
        # camera at 10 frames per simulated second.
        self.assertGreater(m[CAMERA + "::boxes"]["count"], cycles * 0.45)  # a 30 Hz camera
        self.assertLessEqual(m["logger/pose/in"]["count"], cycles)
        self.assertGreater(m["logger/pose/in"]["count"], cycles * 0.8)
        self.assertGreaterEqual(m[CAMERA + "/image"]["count"], 40)
        self.assertLessEqual(m[CAMERA + "/image"]["count"], 61)
        self.assertEqual(got["time"]["last"], str(int(float(SIM_S) * 1e9)))
        self.assertGreater(got["time"]["count"], cycles * 0.8)
        self.assertEqual(got["status"], [])

    def test_garbage_and_unknown_channels_get_status_errors(self):
        got = self.got["garbage"]
        self.assertEqual(got["exit"], 0, got)
        texts = [s["message"] for s in got["status"] if s["level"] == 2]
        self.assertTrue(any("not a JSON message" in t for t in texts), texts)
        self.assertTrue(any("unknown channel id 987654" in t for t in texts), texts)
        # ...and it still gets its data.
        self.assertGreater(got["messages"][CAMERA + "/image"]["count"], 10)

    def test_a_client_leaving_mid_frame_changes_nothing(self):
        got = self.got["disconnect"]
        self.assertEqual(got["exit"], 0, got)
        self.assertTrue(got["closed"])
        self.assertEqual(sum(m["count"] for m in got["messages"].values()), 20)

    def test_summary_counts_what_each_client_got(self):
        live = self.summary["live"]
        self.assertEqual(len(live["clients"]), 3, live)
        self.assertEqual(live["dropped_messages"], 0)
        self.assertEqual(sorted(c["errors"] for c in live["clients"]), [0, 0, 2])
        self.assertGreater(live["camera_frames"], 40)
        self.assertIn("live: client 1 (127.0.0.1:", self.live.stderr)


class BadAddresses(unittest.TestCase):
    """Refused before any engine starts: exit 2 and one message naming --live and the address."""

    def run_live(self, *args):
        tmp = tempfile.mkdtemp(prefix="convoy_live_bad_")
        try:
            r = subprocess.run(convoy(tmp, "run", *args), capture_output=True, text=True,
                               timeout=60)
            started = os.path.exists(os.path.join(tmp, "run", "logs", "gazebo.log"))
            summary = os.path.join(tmp, "run", "summary.json")
            code = json.loads(read(summary))["exit_code"] if os.path.exists(summary) else None
            return r, started, code
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    def test_a_port_in_use(self):
        with socket.socket() as busy:
            busy.bind(("127.0.0.1", 0))
            busy.listen(1)
            port = busy.getsockname()[1]
            r, started, code = self.run_live("--live", str(port))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("error: --live 127.0.0.1:%d: cannot listen there" % port, r.stderr)
        self.assertIn("in use", r.stderr)
        self.assertFalse(started, "an engine started")
        self.assertEqual(code, 2)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)

    def test_a_non_loopback_address_without_insecure(self):
        port = free_port()
        r, started, code = self.run_live("--live", "0.0.0.0:%d" % port)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("error: --live 0.0.0.0:%d is not a loopback address" % port, r.stderr)
        self.assertIn("--insecure", r.stderr)
        self.assertFalse(started, "an engine started")
        self.assertIsNone(code, "refused before the run folder is made")

    def test_not_an_address(self):
        for bad in ("abc", "127.0.0.1:99999", "[::1]"):
            r = subprocess.run([CONVOY, "run", "-c", CONFIG, "--live", bad], capture_output=True,
                               text=True, timeout=60)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("--live " + bad, r.stderr)
            self.assertIn("[HOST:]PORT", r.stderr)

    def test_insecure_allows_any_address_with_a_warning(self):
        r, started, code = self.run_live("--live", "0.0.0.0:%d" % free_port(), "--insecure",
                                         "-o", "SimulationTimeout=0.2")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("warning: --insecure: the live server listens at 0.0.0.0:", r.stderr)
        self.assertTrue(started)

    def test_the_help_names_the_options(self):
        r = subprocess.run([CONVOY, "run", "--help"], capture_output=True, text=True, timeout=30)
        for option in ("--live [HOST:]PORT", "--insecure", "--live-camera-hz",
                       "view PATH [--port P]"):
            self.assertIn(option, r.stdout)
