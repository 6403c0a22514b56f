"""What the graph's input and output nodes talk to. The coordinator provides real ones (an
MQTT client, a rospy node, the loop's datapack pool); tests provide fakes. Nothing here
imports paho, rospy or Convoy's C++.

  Transports(mqtt=..., ros=...)  handed to load_computational_graph() / graph.configure()

Engine datapacks do not go through an interface of the nodes: the loop pushes them into the
graph and drains them out (EngineLink below), as NRP-Core's ComputationalGraphHandle does.
"""


class MQTTClient:
    """An MQTT connection (NRP-Core's NRPMQTTProxy): QoS 1, not retained."""

    def subscribe(self, topic, callback):
        """Calls callback(payload: bytes) for each message on `topic`, from any thread."""
        raise NotImplementedError

    def publish(self, topic, payload):
        """Publishes `payload` (bytes) on `topic`."""
        raise NotImplementedError


class ROSInterface:
    """A ROS node (NRP-Core's NRPROSProxy); callbacks only buffer, spin_once() is called by
    the loop before each cycle."""

    def subscribe(self, topic, msg_type, callback):
        """Calls callback(msg) for each `msg_type` message on `topic`."""
        raise NotImplementedError

    def publish(self, topic, msg_type, msg):
        """Publishes `msg` on `topic` (advertised on first use)."""
        raise NotImplementedError

    def spin_once(self):
        pass


class DataPackSource:
    """Where FromEngine datapacks come from: the loop's datapacks of one engine."""

    def get_datapacks(self, engine_name, datapack_names):
        """The latest datapacks of `engine_name` among `datapack_names` (a list of datapack
        objects; an empty datapack for one the engine has not sent)."""
        raise NotImplementedError


class DataPackSink:
    """Where ToEngine datapacks go."""

    def send_datapacks(self, engine_name, datapacks):
        raise NotImplementedError


class Transports:
    """The connections a graph's nodes use; None for one the experiment does not have (MQTT
    nodes then warn and stay silent, as in NRP-Core; ROS nodes fail)."""

    def __init__(self, mqtt=None, ros=None):
        self.mqtt = mqtt
        self.ros = ros


class EngineLink:
    """Moves datapacks between engines and the graph's FromEngine/ToEngine nodes (NRP-Core's
    ComputationalGraphHandle::updateDataPacksFromEngines / sendDataPacksToEngines)."""

    def __init__(self, graph):
        self.graph = graph
        self.inputs = {n.engine_name: n for n in graph.nodes_of("FromEngine")}
        self.outputs = {n.engine_name: n for n in graph.nodes_of("ToEngine")}

    def requested(self, engine_name):
        """The datapack names the graph reads from `engine_name`."""
        node = self.inputs.get(engine_name)
        return node.requested_datapacks() if node else []

    def update_from_engines(self, source, engines):
        for engine in engines:
            node = self.inputs.get(engine)
            if node is not None:
                node.set_datapacks(source.get_datapacks(engine, node.requested_datapacks()))

    def send_to_engines(self, sink, engines):
        for engine in engines:
            node = self.outputs.get(engine)
            if node is not None:
                datapacks = node.get_datapacks()
                if datapacks:
                    sink.send_datapacks(engine, datapacks)
