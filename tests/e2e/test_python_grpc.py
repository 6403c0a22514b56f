"""End-to-end tests of python_grpc engines (NRP-Core's Python GRPC engine) and NRP-Core's
message set (nrp_protobuf: Wrappers, NrpGenericProto, Dump, EngineTest, Gazebo).

  Messages:  every Wrappers and NrpGenericProto type, Dump and EngineTest, from an engine
             through a TF (NRP-Core's class names, asserts) to another engine (asserts), with
             multi-dimensional arrays, an Image, and large bytes fields (intact, one copy per
             process, the same bytes with shared memory off); RawData classes.
  Camera:    a gazebo_pb2.Camera published by one engine reaches a TF as GazeboCameraDataPack
             (a numpy view) and another engine as a gazebo_pb2.Camera.
  BadInput:  unknown ProtobufPackages entry, an unknown message type, _setDataPack with a
             wrong type, a TF sending the wrong type, an exception in runLoop.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_python_grpc
"""

import json
import os
import textwrap
import unittest

from e2e_util import E2ETestCase

EXIT_USER, EXIT_ENGINE = 2, 3

# Values shared by the engines and the TF: what the source engine sends (fwd) and what the TF
# sends on (back). Arrays carry a shape; ArrayDouble and ArrayInt32 are multi-dimensional.
SPEC = textwrap.dedent('''\
    import hashlib
    import numpy as np
    from nrp_protobuf import dump_pb2, enginetest_pb2, nrpgenericproto_pb2, wrappers_pb2

    WRAPPERS = {
        "BoolValue": (True, False),
        "Int32Value": (-7, 2**31 - 1),
        "UInt32Value": (4000000000, 5),
        "Int64Value": (-(2**40), 2**62),
        "UInt64Value": (2**63 + 5, 0),
        "FloatValue": (1.5, -2.25),
        "DoubleValue": (3.125, 1e300),
        "StringValue": ("h\\u00e9llo", "w\\u00f6rld"),
        "BytesValue": (b"\\x00\\x01\\xff", b"\\xfe"),
    }
    ARRAYS = {
        "ArrayBool": (([True, False, True], [3]), ([False, True], [2])),
        "ArrayBytes": (([b"a", b"\\x00b"], [2]), ([b"", b"c", b"dd"], [3])),
        "ArrayString": ((["x", "y\\u00fc"], [2]), (["z"], [1])),
        "ArrayFloat": (([0.5, -1.5], [2]), ([2.5, 3.5, 4.5, 5.5], [2, 2])),
        "ArrayDouble": ((list(np.arange(8) * 0.25), [2, 2, 2]),
                        (list(np.arange(8).reshape(2, 2, 2).transpose(2, 1, 0).ravel() * 0.5), [2, 2, 2])),
        "ArrayInt32": (([0, 1, 2, 3, 4, 5], [2, 3]), ([-1, -2, -3, -4, -5, -6], [3, 2])),
        "ArrayInt64": (([2**40, -3], [2]), ([7], [1])),
        "ArraySInt32": (([-12, 12], [2]), ([-1], [1])),
        "ArraySInt64": (([-(2**50)], [1]), ([2**50, 1], [2])),
        "ArrayUInt32": (([14, 2**32 - 1], [2]), ([0], [1])),
        "ArrayUInt64": (([2**64 - 1], [1]), ([15, 16], [2])),
    }
    IMAGE = ((2, 3, 9, nrpgenericproto_pb2.RGB8, True, bytes(range(18))),
             (3, 1, 3, nrpgenericproto_pb2.IMAGE_TYPE.BGR16, False, bytes(range(9, 0, -1))))
    DUMP_STRING = ("abc", "abc!")
    DUMP_FLOATS = (([1.0, 2.0, 3.0, 4.0], [2, 2]), ([5.0], [1]))
    TEST_PAYLOAD = (41, 42)

    # Large bytes fields: a 736x480x3 image, a 100 KB BytesValue, a 50 KB element of an
    # ArrayBytes between two small ones. The first 4 bytes hold the source's step number.
    BIG_SIZES = {"big_image": 736 * 480 * 3, "big_bytes": 100000, "big_array": 50000}

    def big(name, seq):
        b = bytearray(np.random.default_rng(seq * 7 + BIG_SIZES[name]).integers(
            0, 256, BIG_SIZES[name], dtype=np.uint8).tobytes())
        b[:4] = int(seq).to_bytes(4, "little")
        return bytes(b)

    def seq_of(data):
        return int.from_bytes(data[:4], "little")

    def check_big(name, data):
        """The step number of an intact large value (raises if it is not intact)."""
        seq = seq_of(data)
        assert len(data) == BIG_SIZES[name], (name, len(data))
        assert data == big(name, seq), "%s of step %d is not intact" % (name, seq)
        return seq

    def fill_array(msg, values_shape):
        values, shape = values_shape
        msg.array.extend(values)
        msg.shape.extend(shape)

    def check_array(name, msg, values_shape):
        values, shape = values_shape
        got = list(msg.array)
        if name in ("ArrayFloat",):
            assert np.allclose(got, values), (name, got, values)
        else:
            assert got == values, (name, got, values)
        assert list(msg.shape) == shape, (name, list(msg.shape), shape)
        assert np.reshape(got, shape).shape == tuple(shape)

    def check_scalar(name, got, want):
        if name == "FloatValue":
            assert abs(got - want) < 1e-6, (name, got, want)
        else:
            assert got == want, (name, got, want)
    ''')

SRC = textwrap.dedent('''\
    import os
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from spec import *

    _HERE = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(os.path.join(_HERE, "pids"), exist_ok=True)
    open(os.path.join(_HERE, "pids", "src.pid"), "w").write(str(os.getpid()))


    class Script(GrpcEngineScript):
        def initialize(self):
            for name, (fwd, _) in WRAPPERS.items():
                self._registerDataPack(name, getattr(wrappers_pb2, name))
                m = getattr(wrappers_pb2, name)()
                m.value = fwd
                self._setDataPack(name, m)
            for name, (fwd, _) in ARRAYS.items():
                self._registerDataPack(name, getattr(nrpgenericproto_pb2, name))
                fill_array(self._getDataPack(name), fwd)  # the message itself, in place
            self._registerDataPack("Image", nrpgenericproto_pb2.Image)
            img = self._getDataPack("Image")
            img.height, img.width, img.step, img.type, img.isBigEndian, img.data = IMAGE[0]
            self._registerDataPack("DumpString", dump_pb2.String)
            self._getDataPack("DumpString").string_stream = DUMP_STRING[0]
            self._registerDataPack("DumpFloats", dump_pb2.ArrayFloat)
            self._getDataPack("DumpFloats").float_stream.extend(DUMP_FLOATS[0][0])
            self._getDataPack("DumpFloats").dims.extend(DUMP_FLOATS[0][1])
            self._registerDataPack("Payload", enginetest_pb2.TestPayload)
            self._getDataPack("Payload").integer = TEST_PAYLOAD[0]
            self._registerDataPack("big_image", nrpgenericproto_pb2.Image)
            self._registerDataPack("big_bytes", wrappers_pb2.BytesValue)
            self._registerDataPack("big_array", nrpgenericproto_pb2.ArrayBytes)
            self.seq = 0
            self._publish()

        def _publish(self):
            img = nrpgenericproto_pb2.Image(height=480, width=736, step=736 * 3,
                                            type=nrpgenericproto_pb2.RGB8,
                                            data=big("big_image", self.seq))
            self._setDataPack("big_image", img)
            self._setDataPack("big_bytes", wrappers_pb2.BytesValue(value=big("big_bytes", self.seq)))
            arr = nrpgenericproto_pb2.ArrayBytes()
            arr.array.extend([b"head", big("big_array", self.seq), b"tail"])
            self._setDataPack("big_array", arr)

        def runLoop(self, timestep_ns):
            self.seq += 1
            self._publish()
    ''')

DST = textwrap.dedent('''\
    import json, os
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from spec import *

    _HERE = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(os.path.join(_HERE, "pids"), exist_ok=True)
    open(os.path.join(_HERE, "pids", "dst.pid"), "w").write(str(os.getpid()))


    class Script(GrpcEngineScript):
        def initialize(self):
            for name in WRAPPERS:
                self._registerDataPack(name, getattr(wrappers_pb2, name))
            for name in ARRAYS:
                self._registerDataPack(name, getattr(nrpgenericproto_pb2, name))
            self._registerDataPack("Image", nrpgenericproto_pb2.Image)
            self._registerDataPack("DumpString", dump_pb2.String)
            self._registerDataPack("DumpFloats", dump_pb2.ArrayFloat)
            self._registerDataPack("Payload", enginetest_pb2.TestPayload)
            self._registerDataPack("big_image", nrpgenericproto_pb2.Image)
            self._registerDataPack("big_bytes", wrappers_pb2.BytesValue)
            self._registerDataPack("big_array", nrpgenericproto_pb2.ArrayBytes)
            self.log = open(os.path.join(_HERE, "dst_%s.jsonl" % os.environ.get("TAG", "x")), "w")

        def runLoop(self, timestep_ns):
            for name, (_, back) in WRAPPERS.items():
                m = self._getDataPack(name)
                assert type(m) is getattr(wrappers_pb2, name), type(m)
                check_scalar(name, m.value, back)
            for name, (_, back) in ARRAYS.items():
                check_array(name, self._getDataPack(name), back)
            img = self._getDataPack("Image")
            assert (img.height, img.width, img.step, img.type, img.isBigEndian, img.data) == IMAGE[1]
            assert self._getDataPack("DumpString").string_stream == DUMP_STRING[1]
            assert list(self._getDataPack("DumpFloats").float_stream) == DUMP_FLOATS[1][0]
            assert list(self._getDataPack("DumpFloats").dims) == DUMP_FLOATS[1][1]
            assert self._getDataPack("Payload").integer == TEST_PAYLOAD[1]
            bi = self._getDataPack("big_image")
            assert (bi.height, bi.width, bi.step) == (480, 736, 736 * 3)
            arr = self._getDataPack("big_array").array
            assert len(arr) == 3 and arr[0] == b"head" and arr[2] == b"tail", len(arr)
            seqs = [check_big("big_image", bi.data),
                    check_big("big_bytes", self._getDataPack("big_bytes").value),
                    check_big("big_array", arr[1])]
            self.log.write(json.dumps({"t": self._time_ns, "seqs": seqs}) + "\\n")

        def shutdown(self):
            self.log.close()
    ''')


def relay_tf():
    names = (["W:" + n for n in ("BoolValue", "Int32Value", "UInt32Value", "Int64Value",
                                 "UInt64Value", "FloatValue", "DoubleValue", "StringValue",
                                 "BytesValue")]
             + ["A:" + n for n in ("ArrayBool", "ArrayBytes", "ArrayString", "ArrayFloat",
                                   "ArrayDouble", "ArrayInt32", "ArrayInt64", "ArraySInt32",
                                   "ArraySInt64", "ArrayUInt32", "ArrayUInt64")]
             + ["Image", "DumpString", "DumpFloats", "Payload", "big_image", "big_bytes",
                "big_array"])
    decorators = "".join("@EngineDataPack(keyword='%s', id=DataPackIdentifier('%s', 'src'))\n"
                         % (n.split(":")[-1], n.split(":")[-1]) for n in names)
    args = ", ".join(n.split(":")[-1] for n in names)
    return textwrap.dedent('''\
        from nrp_core import *
        from nrp_core._datapacks import RawData
        from nrp_core.data.nrp_protobuf import *
        from spec import *

        ''') + decorators + '@TransceiverFunction("dst")\n' + "def relay(%s):\n" % args + \
        textwrap.indent(textwrap.dedent('''\
            got = dict(locals())
            out = []
            for name, (fwd, back) in WRAPPERS.items():
                dp = got[name]
                assert type(dp).__name__ == "Wrappers%sDataPack" % name, type(dp).__name__
                assert isinstance(dp.data, getattr(wrappers_pb2, name)), type(dp.data)
                check_scalar(name, dp.data.value, fwd)
                o = globals()["Wrappers%sDataPack" % name](name, "dst")
                o.data.value = back
                out.append(o)
            for name, (fwd, back) in ARRAYS.items():
                dp = got[name]
                assert type(dp).__name__ == "NrpGenericProto%sDataPack" % name, type(dp).__name__
                check_array(name, dp.data, fwd)
                o = globals()["NrpGenericProto%sDataPack" % name](name, "dst")
                o.data.array[:] = back[0]
                o.data.shape[:] = back[1]
                out.append(o)
            img = Image.data
            assert (img.height, img.width, img.step, img.type, img.isBigEndian, img.data) == IMAGE[0]
            o = NrpGenericProtoImageDataPack("Image", "dst")
            (o.data.height, o.data.width, o.data.step, o.data.type, o.data.isBigEndian,
             o.data.data) = IMAGE[1]
            out.append(o)
            assert type(DumpString).__name__ == "DumpStringDataPack"
            assert DumpString.data.string_stream == DUMP_STRING[0]
            o = DumpStringDataPack("DumpString", "dst")
            o.data.string_stream = DumpString.data.string_stream + "!"
            out.append(o)
            assert list(DumpFloats.data.float_stream) == DUMP_FLOATS[0][0]
            assert list(DumpFloats.data.dims) == DUMP_FLOATS[0][1]
            o = DumpArrayFloatDataPack("DumpFloats", "dst")
            o.data.float_stream.extend(DUMP_FLOATS[1][0])
            o.data.dims.extend(DUMP_FLOATS[1][1])
            out.append(o)
            assert Payload.data.integer == TEST_PAYLOAD[0]
            o = EngineTestTestPayloadDataPack("Payload", "dst")
            o.data.integer = Payload.data.integer + 1
            out.append(o)
            # Large bytes: intact, relayed as they are (the message itself).
            for name, dp in (("big_image", big_image), ("big_bytes", big_bytes)):
                field = dp.data.data if name == "big_image" else dp.data.value
                check_big(name, field)
                o = type(dp)(name, "dst")
                o.data = dp.data
                out.append(o)
            check_big("big_array", big_array.data.array[1])
            o = NrpGenericProtoArrayBytesDataPack("big_array", "dst")
            o.data.array.extend(big_array.data.array)
            out.append(o)
            # RawData classes (what status functions return): .data is the message.
            r = EngineTestTestPayloadRawData()
            r.data.integer = 3
            assert isinstance(r, RawData) and isinstance(r.data, enginetest_pb2.TestPayload)
            s = DumpStringRawData(dump_pb2.String(string_stream="x"))
            assert s.data.string_stream == "x"
            assert type(WrappersBoolValueRawData().data) is wrappers_pb2.BoolValue
            return out
            '''), "    ")


def grpc_engine(name, script_file, timestep=0.01, packages=("Wrappers", "NrpGenericProto", "Dump",
                                                              "EngineTest"), **extra):
    cfg = {"EngineType": "python_grpc", "EngineName": name, "PythonFileName": script_file,
           "EngineTimestep": timestep, "ProtobufPackages": list(packages)}
    cfg.update(extra)
    return cfg


class Messages(E2ETestCase):
    STEPS = 10

    def experiment(self):
        self.write("spec.py", SPEC)
        self.write("src.py", SRC)
        self.write("dst.py", DST)
        self.write("tf_relay.py", relay_tf())
        self.write_config({
            "SimulationName": "grpc_messages", "SimulationTimeout": self.STEPS * 0.01,
            "EngineConfigs": [grpc_engine("src", "src.py"), grpc_engine("dst", "dst.py")],
            "DataPackProcessingFunctions": [{"Name": "tf_relay", "FileName": "tf_relay.py"}]})

    def run_tagged(self, tag, shm_mb=None):
        env = {"TAG": tag}
        if shm_mb is not None:
            env["CONVOY_SHM_MB"] = shm_mb
        old = dict(os.environ)
        os.environ.update(env)
        try:
            self.run_dir = os.path.join(self.dir, "run_" + tag)
            r = self.run_convoy()
        finally:
            os.environ.clear()
            os.environ.update(old)
        self.assertExit(r, 0)
        with open(os.path.join(self.dir, "dst_%s.jsonl" % tag)) as f:
            return [json.loads(line) for line in f], self.summary()

    def test_every_type_both_ways_and_large_bytes_in_shared_memory(self):
        self.experiment()
        entries, summary = self.run_tagged("shm")
        self.assertNoEngineLeft(expect_pids=("src", "dst"))
        # Every step of dst checked every datapack (an assert would have ended the run).
        self.assertEqual(len(entries), self.STEPS)
        # The TF of cycle k relays what src had after step k (k = 0: after initialize).
        self.assertEqual([e["seqs"] for e in entries], [[k] * 3 for k in range(self.STEPS)])
        # One copy of each large value per process and cycle: src into its arena, the
        # coordinator into the TF's message and into dst's arena, dst into its message.
        cycles = summary["cycles"]
        copies = summary["frame_copies"]
        self.assertEqual(copies["src"], 3 * cycles)
        self.assertEqual(copies["coordinator"], 2 * 3 * cycles)
        self.assertEqual(copies["dst"], 3 * self.STEPS)
        # Without shared memory the same bytes arrive inline.
        inline, _ = self.run_tagged("inline", shm_mb="0")
        self.assertEqual(inline, entries)


# A python_grpc camera: gazebo_pb2.Camera in the engines, GazeboCameraDataPack in the TF.
CAM_SRC = textwrap.dedent('''\
    import numpy as np
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from nrp_protobuf import gazebo_pb2

    class Script(GrpcEngineScript):
        def initialize(self):
            self._registerDataPack("camera", gazebo_pb2.Camera)
            self._registerDataPack("small", gazebo_pb2.Camera)
            self._registerDataPack("joint", gazebo_pb2.Joint)
            self._registerDataPack("link", gazebo_pb2.Link)
            self.seq = 0
            self.runLoop(0)

        def runLoop(self, timestep_ns):
            frame = np.random.default_rng(self.seq).integers(0, 256, (480, 736, 3), dtype=np.uint8)
            self._setDataPack("camera", gazebo_pb2.Camera(imageWidth=736, imageHeight=480,
                                                          imageDepth=3, imageData=frame.tobytes()))
            self._setDataPack("small", gazebo_pb2.Camera(imageWidth=2, imageHeight=1,
                                                         imageDepth=3, imageData=bytes(range(6))))
            j = self._getDataPack("joint")
            j.position, j.velocity, j.effort = 0.5, -1.0, float(self.seq)
            l = self._getDataPack("link")
            del l.position[:]
            l.position.extend([1, 2, self.seq])
            del l.linearVelocity[:]
            l.linearVelocity.extend([4, 5, 6])
            self.seq += 1
    ''')

CAM_DST = textwrap.dedent('''\
    import hashlib, json, os
    import numpy as np
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from nrp_protobuf import gazebo_pb2

    class Script(GrpcEngineScript):
        def initialize(self):
            self._registerDataPack("camera_in", gazebo_pb2.Camera)
            self._registerDataPack("joint_in", gazebo_pb2.Joint)
            self._registerDataPack("link_in", gazebo_pb2.Link)
            self.log = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "cam.jsonl"), "w")

        def runLoop(self, timestep_ns):
            m = self._getDataPack("camera_in")
            j = self._getDataPack("joint_in")
            l = self._getDataPack("link_in")
            self.log.write(json.dumps({
                "type": type(m).__name__, "dims": [m.imageHeight, m.imageWidth, m.imageDepth],
                "sha": hashlib.sha1(m.imageData).hexdigest(),
                "joint": [j.position, j.velocity, j.effort],
                "link": [list(l.position), list(l.linearVelocity)]}) + "\\n")

        def shutdown(self):
            self.log.close()
    ''')

CAM_TF = textwrap.dedent('''\
    import hashlib, json, os
    import numpy as np
    from nrp_core import *
    from nrp_core.data.nrp_protobuf import *

    LOG = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "tf.jsonl"), "w")

    @EngineDataPack(keyword='camera', id=DataPackIdentifier('camera', 'cam'))
    @EngineDataPack(keyword='small', id=DataPackIdentifier('small', 'cam'))
    @EngineDataPack(keyword='joint', id=DataPackIdentifier('joint', 'cam'))
    @EngineDataPack(keyword='link', id=DataPackIdentifier('link', 'cam'))
    @TransceiverFunction("view")
    def relay(camera, small, joint, link):
        img = camera.data.imageData
        LOG.write(json.dumps({
            "class": type(camera).__name__, "small_class": type(small).__name__,
            "view": (not img.flags["OWNDATA"]) and (not img.flags["WRITEABLE"]),
            "dims": [camera.data.imageHeight, camera.data.imageWidth, camera.data.imageDepth],
            "sha": hashlib.sha1(img.tobytes()).hexdigest(),
            "small": [int(v) for v in small.data.imageData],
            "joint_class": type(joint).__name__, "link_class": type(link).__name__}) + "\\n")
        LOG.flush()
        out = GazeboCameraDataPack("camera_in", "view")
        out.data.imageWidth = camera.data.imageWidth
        out.data.imageHeight = camera.data.imageHeight
        out.data.imageDepth = camera.data.imageDepth
        out.data.imageData = camera.data.imageData
        j = GazeboJointDataPack("joint_in", "view")
        j.data.position, j.data.velocity, j.data.effort = (joint.data.position, joint.data.velocity,
                                                          joint.data.effort)
        l = GazeboLinkDataPack("link_in", "view")
        l.data.pos = link.data.pos
        l.data.lin_vel = link.data.lin_vel
        return [out, j, l]
    ''')


class Camera(E2ETestCase):
    def test_gazebo_camera_between_grpc_engines_through_a_numpy_tf(self):
        self.write("cam.py", CAM_SRC)
        self.write("view.py", CAM_DST)
        self.write("tf_cam.py", CAM_TF)
        self.write_config({
            "SimulationName": "grpc_camera", "SimulationTimeout": 0.05,
            "EngineConfigs": [grpc_engine("cam", "cam.py", packages=["Gazebo"]),
                              grpc_engine("view", "view.py", packages=["Gazebo"])],
            "DataPackProcessingFunctions": [{"Name": "tf_cam", "FileName": "tf_cam.py"}]})
        r = self.run_convoy()
        self.assertExit(r, 0)
        with open(os.path.join(self.dir, "tf.jsonl")) as f:
            tf = [json.loads(line) for line in f]
        with open(os.path.join(self.dir, "cam.jsonl")) as f:
            view = [json.loads(line) for line in f]
        self.assertEqual(len(view), 5)
        self.assertEqual({t["class"] for t in tf}, {"GazeboCameraDataPack"})
        self.assertEqual({t["small_class"] for t in tf}, {"GazeboCameraDataPack"})
        self.assertEqual({t["joint_class"] for t in tf}, {"GazeboJointDataPack"})
        self.assertEqual({t["link_class"] for t in tf}, {"GazeboLinkDataPack"})
        self.assertTrue(all(t["view"] for t in tf), "the TF's image should be a read-only view")
        self.assertEqual(tf[0]["small"], [0, 1, 2, 3, 4, 5])
        # dst's step k gets what the TF of cycle k saw (frames differ from step to step)
        self.assertEqual([v["sha"] for v in view], [t["sha"] for t in tf[:5]])
        self.assertEqual(len({v["sha"] for v in view}), 5)
        self.assertEqual({v["type"] for v in view}, {"Camera"})
        self.assertEqual(view[0]["dims"], [480, 736, 3])
        self.assertEqual(view[2]["joint"], [0.5, -1.0, 2.0])
        self.assertEqual(view[2]["link"], [[1, 2, 2], [4, 5, 6]])
        # One copy of a frame per process and cycle (cam: into its arena; coordinator: into
        # view's arena; view: into its message).
        copies = self.summary()["frame_copies"]
        cycles = self.summary()["cycles"]
        self.assertEqual(copies["cam"], cycles)
        self.assertEqual(copies["coordinator"], cycles)
        self.assertEqual(copies["view"], 5)


BAD_SRC = textwrap.dedent('''\
    import os
    from nrp_core.engines.python_grpc import GrpcEngineScript
    from nrp_protobuf import dump_pb2, wrappers_pb2

    _HERE = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(os.path.join(_HERE, "pids"), exist_ok=True)
    open(os.path.join(_HERE, "pids", "%(name)s.pid"), "w").write(str(os.getpid()))

    class Script(GrpcEngineScript):
        def initialize(self):
            self._registerDataPack("text", dump_pb2.String)
    %(initialize)s

        def runLoop(self, timestep_ns):
            self._getDataPack("text").string_stream = str(self._time_ns)
    %(run_loop)s
    ''')


def bad_engine(name, initialize="", run_loop=""):
    ind = lambda code: textwrap.indent(textwrap.dedent(code).strip("\n"), " " * 8) if code else ""
    return BAD_SRC % {"name": name, "initialize": ind(initialize), "run_loop": ind(run_loop)}


TEXT_TF = textwrap.dedent('''\
    from nrp_core import *
    from nrp_core.data.nrp_protobuf import *

    @EngineDataPack(keyword='text', id=DataPackIdentifier('text', 'python_1'))
    @TransceiverFunction("python_2")
    def relay(text):
        %s
    ''')  # the body's lines are indented by experiment()


class BadInput(E2ETestCase):
    def experiment(self, src1="", src2="", tf_body="return []", packages=("Dump",)):
        self.write("python_1.py", src1 or bad_engine("python_1"))
        self.write("python_2.py", src2 or bad_engine("python_2"))
        self.write("tf.py", TEXT_TF % "\n    ".join(tf_body.split("\n")))
        self.write_config({
            "SimulationName": "grpc_bad", "SimulationTimeout": 0.05,
            "EngineConfigs": [grpc_engine("python_1", "python_1.py", packages=packages),
                              grpc_engine("python_2", "python_2.py", packages=packages)],
            "DataPackProcessingFunctions": [{"Name": "tf", "FileName": "tf.py"}]})

    def check_engine_error(self, r, *needles):
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, *needles)
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")

    def test_unknown_protobuf_package_is_a_config_error(self):
        self.experiment(packages=("Dump", "NoSuchPackage"))
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "/EngineConfigs/0/ProtobufPackages/1", "NoSuchPackage",
                             "NrpGenericProto")
        self.assertOneError(r)
        self.assertEqual(self.engine_pids(), {}, "no engine should have started")

    def test_unknown_message_type(self):
        self.experiment(src1=bad_engine("python_1", initialize='''
            from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
            fdp = descriptor_pb2.FileDescriptorProto(name="mine.proto", package="mine")
            fdp.message_type.add(name="Thing").field.add(name="x", number=1, type=5, label=1)
            pool = descriptor_pool.DescriptorPool()
            pool.Add(fdp)
            Thing = message_factory.MessageFactory(pool).GetPrototype(pool.FindMessageTypeByName("mine.Thing"))
            self._registerDataPack("thing", Thing)
            '''))
        r = self.run_convoy()
        self.check_engine_error(r, "python_1", "mine.Thing", "is not compiled into Convoy",
                                "Initialize")

    def test_register_with_a_non_message_type(self):
        self.experiment(src1=bad_engine("python_1", initialize='self._registerDataPack("d", dict)'))
        r = self.run_convoy()
        self.check_engine_error(r, "python_1", "must be a protobuf message class")

    def test_set_datapack_with_a_wrong_type(self):
        self.experiment(src1=bad_engine("python_1", run_loop='''
            self._setDataPack("text", wrappers_pb2.BoolValue(value=True))'''))
        r = self.run_convoy()
        self.check_engine_error(r, "python_1", "runLoop", "registered with type Dump.String",
                                "Wrappers.BoolValue")

    def test_tf_sends_a_wrong_type(self):
        self.experiment(tf_body='o = WrappersBoolValueDataPack("text", "python_2")\nreturn [o]')
        r = self.run_convoy()
        self.check_engine_error(r, "python_2", "text", "Wrappers.BoolValue", "Dump.String")

    def test_exception_in_run_loop(self):
        self.experiment(src2=bad_engine("python_2", run_loop='''
            if self._time_ns >= 20000000:
                raise RuntimeError("boom in grpc runLoop")'''))
        r = self.run_convoy()
        self.check_engine_error(r, "python_2", "boom in grpc runLoop", "runLoop", "python_2.py")

    def test_unlisted_package_warns(self):
        self.experiment(src1=bad_engine("python_1", initialize='''
            self._registerDataPack("flag", wrappers_pb2.BoolValue)'''))
        r = self.run_convoy()
        self.assertExit(r, 0)
        log = self.read_log("python_1")
        self.assertIn("ProtobufPackages does not list package 'Wrappers'", log)
        self.assertEqual(log.count("ProtobufPackages does not list"), 1)


if __name__ == "__main__":
    unittest.main()
