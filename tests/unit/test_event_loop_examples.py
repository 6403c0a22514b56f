"""NRP-Core 1.4's event-loop examples' node files (experiments/nrp_event_loop, NRP-Core's own,
unchanged) loaded by nrp_core.event_loop and run a few cycles against a fake MQTT broker."""
import json
import os
import shutil
import unittest
from unittest import mock

import nrp_core.data.nrp_json as nrp_json
import nrp_core.data.nrp_protobuf as nrp_protobuf
import nrp_core.event_loop as el
from nrp_core.event_loop import Transports, load_computational_graph
from test_event_loop import FakeBroker, GraphTest, _proto_class

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "experiments",
                        "nrp_event_loop")
UPSTREAM = "/tmp/nrpsrc/examples/event_loop_examples"


class NlohmannJson(dict):
    """Stands for NRP-Core's nrp_core.data.nrp_json.NlohmannJson (not in Convoy yet)."""


NlohmannJson.__module__ = "nrp_core.data.nrp_json"


class ExamplesTest(GraphTest):
    def load_example(self, rel, transports):
        """An example's node file, as it is in NRP-Core, run from a copy in a fresh folder."""
        name = os.path.basename(rel)
        shutil.copy(os.path.join(EXAMPLES, rel), os.path.join(self.dir.name, name))
        return load_computational_graph([name], "AllNodes", transports, self.dir.name)

    @unittest.skipUnless(os.path.isdir(UPSTREAM), "NRP-Core's sources are not at " + UPSTREAM)
    def test_copies_are_upstream(self):
        for rel in ("tf_exchange_async/tf_1.py", "tf_exchange_async/tf_grpc.py",
                    "mqtt_simple/cg_mqtt.py"):
            with open(os.path.join(UPSTREAM, rel)) as a, open(os.path.join(EXAMPLES, rel)) as b:
                self.assertEqual(a.read().strip(), b.read().strip(), rel)

    def test_tf_exchange_async_json(self):
        broker = FakeBroker()
        graph = self.load_example("tf_exchange_async/tf_1.py", Transports(mqtt=broker))
        for step in range(3):
            broker.publish("python_1/get/datapack1", json.dumps({
                "name": "datapack1", "engine_name": "python_1", "type": "x",
                "data": {"time": step * 100, "timestep": 100}}).encode())
            graph.compute()
        graph.compute()  # nothing new: on_new_message does not run
        out = [json.loads(p) for t, p in broker.published if t == "python_2/set/rec_datapack2"]
        self.assertEqual([o["data"]["time"] for o in out], [0, 100, 200])
        self.assertEqual(out[0]["name"], "rec_datapack2")
        self.assertEqual(out[0]["engine_name"], "python_2")
        self.assertEqual(out[0]["type"], el.JSON_DATAPACK_TYPE)

    def test_tf_exchange_async_proto(self):
        dump_string = _proto_class("Dump", "String", [(5, "string_stream", 9)])
        dp_class = type("DumpStringDataPack", (nrp_protobuf.ProtobufDataPack,),
                        {"__slots__": (), "_type": "Dump.String", "_message": dump_string})
        broker = FakeBroker()
        with mock.patch.object(nrp_protobuf, "DumpStringDataPack", dp_class, create=True), \
                mock.patch.object(nrp_protobuf, "__all__", ["DumpStringDataPack"]):
            graph = self.load_example("tf_exchange_async/tf_grpc.py", Transports(mqtt=broker))
        from nrp_core.event_loop._codec import _datapack_message_class
        envelope = _datapack_message_class()
        for step in range(2):
            m = envelope()
            m.dataPackId.dataPackName, m.dataPackId.engineName = "datapack1", "python_1"
            m.data.Pack(dump_string(string_stream=str(step * 1000)))
            broker.publish("python_1/get/datapack1", m.SerializeToString())
            graph.compute()
        out = []
        for topic, payload in broker.published:
            if topic == "python_2/set/rec_datapack2":
                m = envelope.FromString(payload)
                msg = dump_string()
                self.assertTrue(m.data.Unpack(msg))
                out.append((m.dataPackId.dataPackName, m.dataPackId.engineName, msg.string_stream))
        self.assertEqual(out, [("rec_datapack2", "python_2", "0"),
                               ("rec_datapack2", "python_2", "1000")])

    def test_mqtt_simple(self):
        joint = _proto_class("Gazebo", "Joint", [(1, "position", 2), (2, "velocity", 2),
                                                 (3, "effort", 2)])
        broker = FakeBroker()
        with mock.patch.object(nrp_json, "NlohmannJson", NlohmannJson, create=True), \
                mock.patch.object(nrp_protobuf, "GazeboJoint", joint, create=True), \
                mock.patch("builtins.print") as printed:
            graph = self.load_example("mqtt_simple/cg_mqtt.py", Transports(mqtt=broker))
            for _ in range(3):
                graph.compute()
        self.assertEqual(len(graph.layers()[1]), 5)
        lines = [c.args[0] for c in printed.call_args_list]
        self.assertEqual(len(lines), 10)  # cycles 2 and 3: each node prints its loop-back
        self.assertIn("Message from mqtt str: Hi there!", lines)
        self.assertIn("Message from mqtt json: {'hi': 'there'}", lines)
        self.assertTrue(any(s.startswith("Message from mqtt proto: position: 10") for s in lines))
        self.assertTrue(any(s.startswith("Message from mqtt proto datapack: GazeboJointDataPack("
                                         "'a', 'b')") for s in lines))
        by_topic = {}
        for topic, payload in broker.published:
            by_topic.setdefault(topic, []).append(payload)
        self.assertEqual(set(by_topic), {"test_topic", "test_topic_proto", "test_topic_proto_dp",
                                         "test_topic_json", "test_topic_json_dp"})
        self.assertTrue(all(len(v) == 3 for v in by_topic.values()))
        self.assertEqual(json.loads(by_topic["test_topic_json_dp"][0])["data"], {"hi": "there"})
        self.assertEqual(joint.FromString(by_topic["test_topic_proto"][0]).position, 10)


if __name__ == "__main__":
    unittest.main()
