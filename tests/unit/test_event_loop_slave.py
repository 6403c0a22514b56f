"""Unit tests of the pieces behind "SimulationLoop": "EventLoop" with EngineConfigs and MQTT /
ROS nodes in the FTILoop's graph (python/nrp_core/event_loop/_loop.py, _clients.py).

Slave: while an EventLoopRun is loaded, event_loop_graph() is its graph (what the coordinator's
GraphRuntime takes instead of loading the files again); an EngineLink on it moves datapacks in
and out without computing (NRP-Core's ComputationalGraphHandle in slave mode); the EventLoop
computes on its own clock; close() forgets the graph.
Clients: GraphClients without MQTTNode/ROSNode gives empty Transports; activate() makes its
transports the ones the FTILoop's graph gets (active_transports()); close() deactivates; an
unreachable broker is an error naming MQTTNode.MQTTBroker.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_event_loop_slave
"""
import os
import socket
import tempfile
import textwrap
import unittest

from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.event_loop import ComputationalGraphError, EngineLink
from nrp_core.event_loop._clients import GraphClients, active_transports
from nrp_core.event_loop._loop import EventLoopRun, event_loop_graph

GRAPH = textwrap.dedent("""\
    from nrp_core.event_loop import *
    from nrp_core.data.nrp_json import JsonDataPack

    @FromEngine(keyword="src", address="/src/out")
    @Iteration(keyword="it")
    @ToEngine(keyword="dp", address="/dst")
    @FunctionalNode(name="relay", outputs=["dp"])
    def relay(src, it):
        dp = JsonDataPack("in", "dst")
        dp.data["x"] = None if src is None else src.data["x"]
        dp.data["it"] = it
        return [dp]
    """)


class Source:
    def __init__(self):
        self.x = 0

    def get_datapacks(self, engine, names):
        dp = JsonDataPack("out", engine)
        dp.data["x"] = self.x
        return [dp]


class Sink:
    def __init__(self):
        self.sent = []

    def send_datapacks(self, engine, datapacks):
        self.sent += [(engine, dict(dp.data)) for dp in datapacks]


class Slave(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        with open(os.path.join(self.tmp.name, "graph.py"), "w") as f:
            f.write(GRAPH)
        self.run_ = EventLoopRun({"EventLoop": {"Timestep": 0.01}}, self.tmp.name)

    def tearDown(self):
        self.run_.close()
        self.tmp.cleanup()

    def test_engine_datapacks_move_without_computing(self):
        self.assertIsNone(event_loop_graph())
        self.run_.connect()
        self.run_.load(["graph.py"], self.tmp.name)
        graph = event_loop_graph()
        self.assertIs(graph, self.run_.graph)
        link, source, sink = EngineLink(graph), Source(), Sink()
        self.assertEqual(link.requested("src"), ["out"])
        # FTILoop cycles before the EventLoop's first: datapacks in, nothing out.
        for x in (1, 2):
            source.x = x
            link.update_from_engines(source, ["src", "dst"])
            link.send_to_engines(sink, ["src", "dst"])
        self.assertEqual(sink.sent, [])
        self.run_.loop.run_once(0)  # the EventLoop computes: the latest datapack
        link.send_to_engines(sink, ["src"])  # not dst's turn: nothing
        self.assertEqual(sink.sent, [])
        link.send_to_engines(sink, ["dst"])
        link.send_to_engines(sink, ["dst"])  # drained once
        self.assertEqual(sink.sent, [("dst", {"x": 2, "it": 0})])
        self.run_.close()
        self.assertIsNone(event_loop_graph())


class Clients(unittest.TestCase):
    def test_no_clients(self):
        c = GraphClients({}, tempfile.gettempdir())
        c.connect()
        t = c.transports()
        self.assertIsNone(t.mqtt)
        self.assertIsNone(t.ros)
        c.close()

    def test_active_transports(self):
        marker = object()
        c = GraphClients({}, tempfile.gettempdir())
        c.mqtt = marker  # as connect() would set it
        self.assertIsNone(active_transports().mqtt)
        c.activate()
        self.assertIs(active_transports().mqtt, marker)
        c.mqtt = None
        c.close()
        self.assertIsNone(active_transports().mqtt)

    def test_unreachable_broker(self):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        # A non-local address nothing answers on: no mosquitto is started for it.
        c = GraphClients({"MQTTNode": {"MQTTBroker": "192.0.2.1:%d" % port}},
                         tempfile.gettempdir())
        with self.assertRaisesRegex(ComputationalGraphError,
                                    "MQTTNode.MQTTBroker: no MQTT broker answers at 192.0.2.1"):
            c.connect()
        self.assertIsNone(c.broker)


if __name__ == "__main__":
    unittest.main()
