"""End-to-end tests of the data plane: protobuf datapack classes, numpy arrays in JSON
datapacks, shared memory vs inline bytes, camera images without copies.

Run with Debian's /usr/bin/python3 -m unittest test_dataplane."""

import hashlib
import json
import os
import socket
import subprocess
import textwrap
import unittest

from test_core import BIN_DIR, Experiment

CAM = textwrap.dedent("""\
    import os
    import numpy as np
    from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboJointDataPack, GazeboLinkDataPack
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self.rng = np.random.default_rng(5)
            self.cam = GazeboCameraDataPack("camera", self._name)
            self._registerDataPack("camera")
            self._registerDataPack("joint")
            self._registerDataPack("link")
            self._registerDataPack("blob")
            self._registerDataPack("cmd")
            self.runLoop(0)

        def runLoop(self, timestep_ns):
            d = self.cam.data
            d.imageHeight, d.imageWidth, d.imageDepth = 120, 160, 3      # NRP-Core 1.4 names
            d.image_data = self.rng.integers(0, 256, 120 * 160 * 3, dtype=np.uint8)
            self._setDataPack("camera", self.cam)
            j = GazeboJointDataPack("joint", self._name)
            j.data.position, j.data.velocity, j.data.effort = 0.5, -1.25, 3.0
            self._setDataPack("joint", j)
            l = GazeboLinkDataPack("link", self._name)
            l.data.position = [1, 2, 3]
            l.data.rotation = [0, 0, 0.6, 0.8]
            l.data.lin_vel = [4, 5, 6]
            self._setDataPack("link", l)
            # 200 KB of float64: a blob (shared memory when local)
            self._setDataPack("blob", {"a": self.rng.random((100, 256)), "plain": [1, 2, 3],
                                       "t": self._time_ns})
    """)

VIEW = textwrap.dedent("""\
    import hashlib, json, os
    import numpy as np
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self.log = open(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                         "view_%s.jsonl" % os.environ.get("TAG", "x")), "w")
            for n in ("camera_in", "report", "blob_in", "joint_cmd"):
                self._registerDataPack(n)

        def runLoop(self, timestep_ns):
            cam = self._getDataPack("camera_in")
            rep = self._getDataPack("report")
            blob = self._getDataPack("blob_in")
            entry = {"t": self._time_ns}
            if cam is not None:
                img = cam.image_data.reshape(cam.image_height, cam.image_width, cam.image_depth)
                img[0, 0, 0] = 0  # the engine's copy is its own
                entry["cam"] = hashlib.sha1(cam.image_data.tobytes()).hexdigest()
            if blob is not None:
                a = blob["a"]
                entry["blob"] = [type(a).__name__, str(a.dtype), list(a.shape),
                                 hashlib.sha1(a.tobytes()).hexdigest(), blob["plain"]]
            if rep is not None:
                entry["report"] = rep
            self.log.write(json.dumps(entry) + "\\n")

        def shutdown(self):
            self.log.close()
    """)

TF = textwrap.dedent("""\
    import numpy as np
    from nrp_core import *
    from nrp_core.data.nrp_json import *
    from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboJointDataPack, GazeboLinkDataPack

    @EngineDataPack(keyword='camera', id=DataPackIdentifier('camera', 'cam'))
    @EngineDataPack(keyword='joint', id=DataPackIdentifier('joint', 'cam'))
    @EngineDataPack(keyword='link', id=DataPackIdentifier('link', 'cam'))
    @EngineDataPack(keyword='blob', id=DataPackIdentifier('blob', 'cam'))
    @TransceiverFunction("view")
    def relay(camera, joint, link, blob):
        img = camera.data.image_data
        rep = {
            "names": [camera.data.image_height, camera.data.imageHeight, camera.data.image_width,
                      camera.data.imageWidth, camera.data.image_depth, camera.data.imageDepth],
            "dtype": str(img.dtype), "ndim": img.ndim,
            "zero_copy": (not img.flags["OWNDATA"]) and (not img.flags["WRITEABLE"]),
            "joint": [joint.data.position, joint.data.velocity, joint.data.effort],
            "pos": [float(v) for v in link.data.pos], "position": [float(v) for v in link.data.position],
            "rot": [float(v) for v in link.data.rot], "rotation": [float(v) for v in link.data.rotation],
            "lin_vel": [float(v) for v in link.data.lin_vel], "ang_vel": [float(v) for v in link.data.ang_vel],
            "link_dtype": str(link.data.pos.dtype),
            "blob_is_array": isinstance(blob.data["a"], np.ndarray),
        }
        cam_out = GazeboCameraDataPack("camera_in", "view")
        cam_out.data.image_height = camera.data.image_height
        cam_out.data.image_width = camera.data.image_width
        cam_out.data.image_depth = camera.data.image_depth
        cam_out.data.image_data = img
        b = JsonDataPack("blob_in", "view")
        b.data["a"] = blob.data["a"]
        b.data["plain"] = blob.data["plain"]
        cmd = GazeboJointDataPack("joint_cmd", "view")
        cmd.data.velocity = 2.5
        return [cam_out, b, JsonDataPack("report", "view", rep), cmd]
    """)


class DataPlane(unittest.TestCase):
    def experiment(self, remote_port=None):
        ex = Experiment(self)
        ex.engine("cam", CAM)
        extra = {}
        if remote_port:
            extra = {"ServerAddress": "127.0.0.1:%d" % remote_port,
                     "EngineLaunchCommand": {"LaunchType": "EmptyLaunchCommand"}}
        ex.engine("view", VIEW, **extra)
        ex.function("tf_relay", TF)
        return ex

    def entries(self, ex, tag):
        with open(os.path.join(ex.dir, "view_%s.jsonl" % tag)) as f:
            return [json.loads(line) for line in f]

    def run_tagged(self, ex, tag, env_shm=None):
        old = dict(os.environ)
        os.environ["TAG"] = tag
        if env_shm is not None:
            os.environ["CONVOY_SHM_MB"] = env_shm
        try:
            ex.run(0.1, run_name="run_" + tag)
        finally:
            os.environ.clear()
            os.environ.update(old)
        return self.entries(ex, tag)

    def test_protobuf_classes_and_numpy_blobs(self):
        ex = self.experiment()
        entries = self.run_tagged(ex, "shm")
        self.assertEqual(len(entries), 10)
        rep = entries[-1]["report"]
        self.assertEqual(rep["names"], [120, 120, 160, 160, 3, 3])
        self.assertEqual(rep["dtype"], "uint8")
        self.assertEqual(rep["ndim"], 1)
        self.assertTrue(rep["zero_copy"], "camera image_data should be a read-only view")
        self.assertEqual(rep["joint"], [0.5, -1.25, 3.0])
        self.assertEqual(rep["pos"], [1, 2, 3])
        self.assertEqual(rep["position"], [1, 2, 3])
        self.assertAlmostEqual(rep["rot"][2], 0.6, places=6)
        self.assertEqual(rep["rot"], rep["rotation"])
        self.assertEqual(rep["lin_vel"], [4, 5, 6])
        self.assertEqual(rep["ang_vel"], [0, 0, 0])
        self.assertEqual(rep["link_dtype"], "float32")
        self.assertTrue(rep["blob_is_array"])
        blob = entries[-1]["blob"]
        self.assertEqual(blob[:3], ["ndarray", "float64", [100, 256]])
        self.assertEqual(blob[4], [1, 2, 3])

    def test_shared_memory_and_inline_give_identical_results(self):
        ex = self.experiment()
        shm = self.run_tagged(ex, "shm")
        inline = self.run_tagged(ex, "inline", env_shm="0")
        for e in shm + inline:  # how the image is handed over differs; nothing else may
            e["report"].pop("zero_copy", None)
        self.assertEqual(shm, inline)
        self.assertEqual(len({e["cam"] for e in shm}), 10, "a new frame every step")

    def test_remote_engine_gets_the_same_bytes_inline(self):
        ex = self.experiment()
        local = self.run_tagged(ex, "local")
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        ex2 = self.experiment(remote_port=port)
        env = dict(os.environ, TAG="remote")
        server = subprocess.Popen([os.path.join(BIN_DIR, "convoy-engine-python_json"), "--address",
                                   "127.0.0.1:%d" % port], cwd=ex2.dir, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            ex2.run(0.1)
            server.wait(timeout=5)
        finally:
            if server.poll() is None:
                server.kill()
                server.wait()
        remote = self.entries(ex2, "remote")
        for e in local + remote:
            e["report"].pop("zero_copy", None)
        self.assertEqual(remote, local)



# Any protobuf message the datapack registry knows travels with a Python class of its own,
# derived from the registration (here protobuf's well-known Timestamp and Duration, which are
# compiled into every Convoy program): no hand-written converter.
STAMP_SRC = textwrap.dedent("""\
    from google.protobuf import timestamp_pb2
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("stamp")
            self.runLoop(0)

        def runLoop(self, timestep_ns):
            self._setDataPack("stamp", timestamp_pb2.Timestamp(seconds=7, nanos=self._time_ns))
    """)

STAMP_DST = textwrap.dedent("""\
    import json, os
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self.log = open(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                         "stamps.jsonl"), "w")
            self._registerDataPack("stamp_in")
            self._registerDataPack("info")

        def runLoop(self, timestep_ns):
            m, info = self._getDataPack("stamp_in"), self._getDataPack("info")
            if m is not None:
                self.log.write(json.dumps({"type": m.DESCRIPTOR.full_name, "seconds": m.seconds,
                                           "nanos": m.nanos, "info": info}) + "\\n")

        def shutdown(self):
            self.log.close()
    """)

STAMP_TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *
    from nrp_core.data.nrp_protobuf import ProtobufDataPack, datapack_class

    datapack_class("google.protobuf.Timestamp")  # known to Convoy from now on, so importable:
    from nrp_core.data.nrp_protobuf import GoogleProtobufTimestampDataPack

    @EngineDataPack(keyword='stamp', id=DataPackIdentifier('stamp', 'src'))
    @TransceiverFunction("dst")
    def relay(stamp):
        out = GoogleProtobufTimestampDataPack("stamp_in", "dst")
        if not stamp.isEmpty():
            out.data.CopyFrom(stamp.data)  # a real protobuf message, mutable in place
            out.data.seconds += 1
        info = {"class": type(stamp).__name__, "generic": isinstance(stamp, ProtobufDataPack),
                "type": stamp.data.DESCRIPTOR.full_name}
        return [out, JsonDataPack("info", "dst", info)]
    """)


class RegisteredProtobufTypes(unittest.TestCase):
    def test_a_registered_message_gets_a_python_class_without_a_converter(self):
        ex = Experiment(self)
        ex.engine("src", STAMP_SRC)
        ex.engine("dst", STAMP_DST)
        ex.function("tf_stamp", STAMP_TF)
        ex.run(0.05)
        with open(os.path.join(ex.dir, "stamps.jsonl")) as f:
            entries = [json.loads(line) for line in f]
        self.assertGreaterEqual(len(entries), 4)
        last = entries[-1]
        self.assertEqual(last["type"], "google.protobuf.Timestamp")
        self.assertEqual(last["seconds"], 8)
        self.assertGreater(last["nanos"], 0)
        self.assertEqual(last["info"], {"class": "GoogleProtobufTimestampDataPack", "generic": True,
                                        "type": "google.protobuf.Timestamp"})

    def test_a_message_type_convoy_does_not_know_is_a_clear_function_error(self):
        ex = Experiment(self)
        ex.engine("src", STAMP_SRC)
        ex.engine("dst", STAMP_DST)
        ex.function("tf_unknown", textwrap.dedent("""\
            from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
            from nrp_core import *
            from nrp_core.data.nrp_json import *

            _file = descriptor_pb2.FileDescriptorProto(name="only_in_python.proto", package="xpkg")
            _file.message_type.add(name="Foo")
            _pool = descriptor_pool.DescriptorPool()
            _pool.Add(_file)
            Foo = message_factory.MessageFactory(_pool).GetPrototype(_pool.FindMessageTypeByName("xpkg.Foo"))

            @TransceiverFunction("dst")
            def send_unknown():
                return [JsonDataPack("stamp_in", "dst", Foo())]
            """))
        r = ex.run(0.05, expect=4)
        self.assertIn("tf_unknown", r.stderr)
        self.assertIn("datapack 'stamp_in' of engine 'dst'", r.stderr)
        self.assertIn("xpkg.Foo", r.stderr)


# ProtobufDataPack.from_bytes: a message sent as the bytes a function assembled, unparsed.
BYTES_TF = textwrap.dedent("""\
    from google.protobuf import timestamp_pb2
    from nrp_core import *
    from nrp_core.data.nrp_json import *
    from nrp_core.data.nrp_protobuf import datapack_class

    Stamp = datapack_class("google.protobuf.Timestamp")

    @EngineDataPack(keyword='stamp', id=DataPackIdentifier('stamp', 'src'))
    @TransceiverFunction("dst")
    def relay(stamp):
        if stamp.isEmpty():
            return []
        raw = timestamp_pb2.Timestamp(seconds=stamp.data.seconds + 2,
                                      nanos=stamp.data.nanos).SerializeToString()
        out = Stamp.from_bytes("stamp_in", "dst", PAYLOAD(raw))
        info = {"parsed": out.data.seconds}  # .data parses the bytes on first use
        return [Stamp.from_bytes("stamp_in", "dst", PAYLOAD(raw)), JsonDataPack("info", "dst", info)]
    """)


class SerializedDataPacks(unittest.TestCase):
    def test_bytes_travel_as_the_message(self):
        ex = Experiment(self)
        ex.engine("src", STAMP_SRC)
        ex.engine("dst", STAMP_DST)
        ex.function("tf_bytes", BYTES_TF.replace("PAYLOAD(raw)", "raw"))
        ex.run(0.05)
        with open(os.path.join(ex.dir, "stamps.jsonl")) as f:
            entries = [json.loads(line) for line in f]
        self.assertGreaterEqual(len(entries), 4)
        last = entries[-1]
        self.assertEqual(last["type"], "google.protobuf.Timestamp")
        self.assertEqual(last["seconds"], 9)
        self.assertGreater(last["nanos"], 0)
        self.assertEqual(last["info"], {"parsed": 9})

    def test_a_payload_that_is_not_bytes_is_a_function_error(self):
        ex = Experiment(self)
        ex.engine("src", STAMP_SRC)
        ex.engine("dst", STAMP_DST)
        ex.function("tf_bytes", BYTES_TF.replace("PAYLOAD(raw)", "raw.decode('latin-1')"))
        r = ex.run(0.05, expect=4)
        self.assertIn("tf_bytes", r.stderr)
        self.assertIn("from_bytes: payload must be bytes, not str", r.stderr)


if __name__ == "__main__":
    unittest.main()
