"""Unit tests of nrp_client._wire (no simulation): the request bytes it joins parse as the
messages protobuf builds from the same datapacks, and are the same bytes.

Run: cd tests/unit && /usr/bin/python3 -m unittest -v test_nrp_client_wire"""
import json
import os
import random
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from nrp_client import _wire  # noqa: E402
from nrp_client import nrp_server_pb2 as _pb  # noqa: E402


def by_protobuf(num_iterations, json_items, proto_items):
    """The RunLoopMessage as nrp_client built it before _wire (DataPackMessage, Any.Pack)."""
    message = _pb.RunLoopMessage(numIterations=num_iterations)
    for out, items in ((message.dataPacks.jsonDataPacks, json_items),
                       (message.dataPacks.protoDataPacks, proto_items)):
        for name, engine, payload in items:
            dp = out.add()
            dp.dataPackId.dataPackName = name
            dp.dataPackId.engineName = engine
            dp.data.Pack(payload)
    return message


def by_wire(num_iterations, json_items, proto_items):
    def packed(items):
        return [_wire.datapack(name, engine, p.DESCRIPTOR.full_name, p.SerializeToString())
                for name, engine, p in items]
    return _wire.run_loop_message(num_iterations,
                                  _wire.datapacks(packed(json_items), packed(proto_items)))


class WireTest(unittest.TestCase):
    def test_varint(self):
        for n in (0, 1, 127, 128, 300, 2 ** 31 - 1, -1, -2 ** 31):
            m = _pb.RunLoopMessage(numIterations=n)
            self.assertEqual(_wire.run_loop_message(n, b""), m.SerializeToString(), n)

    def test_same_bytes_as_protobuf(self):
        rng = random.Random(4)
        for _ in range(300):
            n = rng.choice([0, 1, 2, 1000])
            json_items = [("action%d" % i, "agent" * rng.randint(0, 40),
                           _pb.JsonMessage(data=json.dumps({"steer": rng.uniform(-1, 1)})))
                          for i in range(rng.randint(0, 2))]
            proto_items = [("joint::" + "x" * rng.randint(0, 200), "gazebo",
                            _pb.JsonMessage(data="" if rng.random() < 0.3 else
                                            "y" * rng.randint(1, 300)))
                           for _ in range(rng.randint(0, 4))]
            wire = by_wire(n, json_items, proto_items)
            message = by_protobuf(n, json_items, proto_items)
            self.assertEqual(_pb.RunLoopMessage.FromString(wire), message)
            self.assertEqual(wire, message.SerializeToString())


if __name__ == "__main__":
    unittest.main()
