"""The graph's connections from the simulation config: the MQTTNode client (with the mosquitto
started for the run when no broker answers at a local MQTTBroker) and the ROSNode node. Used by
the EventLoop (EventLoopRun) and by the FTILoop's "cg" graph, which NRP-Core also lets use MQTT
and ROS nodes.

    clients = GraphClients(config, log_dir)   # config: a dict with "MQTTNode" / "ROSNode"
    clients.connect()                          # ComputationalGraphError naming the key
    clients.transports()                       # -> Transports(mqtt, ros)
    clients.close()

One GraphClients may be made the process's (activate()): the FTILoop's graph, loaded by the
coordinator's GraphRuntime, takes its transports with active_transports().
"""
import logging
import os

from ._policies import ComputationalGraphError
from ._transport import Transports

_log = logging.getLogger("nrp_core.event_loop")

_active = None


class GraphClients:
    def __init__(self, config, log_dir):
        self.config = config
        self.log_dir = log_dir
        self.mqtt = self.ros = self.broker = None

    def connect(self):
        from ._mqtt import DEFAULT_BROKER, LocalBroker, MqttConnection, MqttError
        node = self.config.get("MQTTNode")
        if node is not None:
            address = node.get("MQTTBroker", DEFAULT_BROKER)
            try:
                self.broker = LocalBroker.ensure(address, os.path.join(self.log_dir,
                                                                       "mosquitto.log"))
                if self.broker is not None:
                    _log.info("started mosquitto on %s for the run", address)
                self.mqtt = MqttConnection(address, node.get("ClientName", "NRP-core-client"))
            except (MqttError, ValueError) as e:
                self.close()
                raise ComputationalGraphError("MQTTNode.MQTTBroker: %s" % e) from None
        if self.config.get("ROSNode") is not None:
            from ._rospy_transport import RospyInterface
            try:
                self.ros = RospyInterface(self.config["ROSNode"].get("NodeName", "nrp_core"),
                                          master_log=os.path.join(self.log_dir, "rosmaster.log"))
            except ComputationalGraphError as e:
                self.close()
                raise ComputationalGraphError("ROSNode: %s" % e) from None

    def transports(self):
        return Transports(self.mqtt, self.ros)

    def activate(self):
        """Makes these the connections of the graphs loaded from now on (active_transports)."""
        global _active
        _active = self

    def close(self):
        global _active
        if _active is self:
            _active = None
        if self.mqtt is not None:
            self.mqtt.close()
            self.mqtt = None
        if self.ros is not None:
            self.ros.shutdown()
            self.ros = None
        if self.broker is not None:
            self.broker.stop()
            self.broker = None


def active_transports():
    """The active GraphClients' Transports, or Transports(None, None)."""
    return _active.transports() if _active is not None else Transports()
