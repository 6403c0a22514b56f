"""Input and output nodes of the computational graph (NRP-Core 1.4's InputNode, OutputNode and
their engine, MQTT, ROS, time and dummy kinds). The functional node is in _functional.py.

Values travel by reference, as NRP-Core's pointers do: a node downstream sees the very object
its upstream node published. A node `receive`s on one of its ports; input nodes publish to
their ports' subscribers.
"""
import copy
import logging
import threading

from nrp_core._datapacks import DataPack

from ._policies import ALL, CLEAR, KEEP, LAST, ComputationalGraphError

_log = logging.getLogger("nrp_core.event_loop")

QUEUE_SIZE = 10  # messages kept per input port between two cycles (NRP-Core's default)


class Node:
    """A node of the graph: its id, its kind ("input", "output", "functional") and the flags
    the graph uses to order and run it."""

    kind = ""
    type_str = ""

    def __init__(self, node_id):
        self.id = node_id
        self.visited = False
        self._do_compute = False

    def do_compute(self):
        return self._do_compute

    def set_do_compute(self, value):
        self._do_compute = value

    def configure(self, transports):
        pass

    def compute(self):
        pass

    def cycle_start(self):
        pass

    def graph_loaded(self, graph):
        pass

    def __repr__(self):
        return "<%s node %r>" % (self.type_str or self.kind, self.id)


# ------------------------------------------------------------------------------ input nodes

class _Port:
    __slots__ = ("single", "list", "data")

    def __init__(self):
        self.single = []  # (node, keyword) subscribed to the last message
        self.list = []    # (node, keyword) subscribed to every message (msg_publish.all)
        self.data = []


class InputNode(Node):
    """Publishes, at the start of each cycle, what arrived since the last one: the last
    message (msg_publish.last) or all of them as a list (msg_publish.all). With nothing new,
    msg_cache.keep publishes nothing (the functional node keeps its previous input) and
    msg_cache.clear publishes None."""

    kind = "input"

    def __init__(self, node_id, queue_size=QUEUE_SIZE):
        Node.__init__(self, node_id)
        self.publish_policy = LAST
        self.cache_policy = KEEP
        self.queue_size = queue_size
        self.ports = {}

    def register_port(self, port):
        self.ports.setdefault(port, _Port())

    def subscribe(self, port, node, keyword):
        """Connects `port` to input `keyword` of functional node `node`, through the single
        or the list port as the node's publish policy is now (as in NRP-Core)."""
        handle = self.ports[port]
        (handle.list if self.publish_policy is ALL else handle.single).append((node, keyword))

    def compute(self):
        for port, handle in self.ports.items():
            new = self.take(port)
            if new:
                handle.data = list(new[:self.queue_size])
                if len(new) > self.queue_size:
                    _log.info("Port handle '%s' reached max size. Added msg will be dropped.", port)
                if self.publish_policy is LAST:
                    _publish(handle.single, handle.data[-1])
                else:
                    _publish(handle.list, list(handle.data))
            elif self.cache_policy is CLEAR:
                _publish(handle.single, None)
                _publish(handle.list, None)
                handle.data = []

    def take(self, port):
        """The messages of `port` that arrived since the last cycle (a list, maybe empty)."""
        raise NotImplementedError


def _publish(subscribers, value):
    for node, keyword in subscribers:
        node.receive(keyword, value)


class InputEngineNode(InputNode):
    """@FromEngine: datapacks of one engine ("<engine>_input", one port per datapack name).
    The loop pushes them with set_datapacks(); an empty datapack never replaces a stored
    non-empty one."""

    type_str = "FromEngine"

    def __init__(self, node_id, engine_name):
        InputNode.__init__(self, node_id)
        self.engine_name = engine_name
        self._lock = threading.Lock()
        self._temp = {}
        self._stored = set()

    def requested_datapacks(self):
        """The names of the datapacks this node reads, in port order."""
        return list(self.ports)

    def set_datapacks(self, datapacks):
        """Called by the loop (any thread) with datapacks read from the engine."""
        with self._lock:
            for dp in datapacks:
                name = dp.name
                if name in self.ports and (name not in self._temp or not _is_empty(dp)):
                    self._temp[name] = dp

    def take(self, port):
        with self._lock:
            dp = self._temp.get(port)
            if dp is None or (port in self._stored and _is_empty(dp)):
                return []
            del self._temp[port]
            self._stored.add(port)
            return [dp]


def _is_empty(dp):
    is_empty = getattr(dp, "isEmpty", None)
    return bool(is_empty()) if is_empty is not None else False


class _QueuedInputNode(InputNode):
    """An input node fed from another thread (MQTT, ROS callbacks) into a bounded queue."""

    def __init__(self, node_id, address):
        InputNode.__init__(self, node_id)
        self.address = address
        self._lock = threading.Lock()
        self._temp = []
        self._error = None

    def _push(self, value):
        with self._lock:
            if len(self._temp) < self.queue_size:
                self._temp.append(value)
            else:
                _log.debug("'%s' node capacity is full. Dropping message...", self.id)

    def take(self, port):
        with self._lock:
            error, self._error = self._error, None
            new, self._temp = self._temp, []
        if error is not None:
            raise ComputationalGraphError('In %s node "%s": %s' % (self.type_str, self.id, error))
        return new


class InputMQTTNode(_QueuedInputNode):
    """@MQTTSubscriber: messages of one topic ("<topic>_input")."""

    type_str = "MQTTSubscriber"

    def __init__(self, node_id, topic, codec):
        _QueuedInputNode.__init__(self, node_id, topic)
        self.codec = codec

    def configure(self, transports):
        client = getattr(transports, "mqtt", None)
        if client is None:
            _log.warning('From InputMQTTNode "%s". NRPCoreSim is not connected to MQTT and this '
                         "node can't subscribe to topics. Check your experiment configuration",
                         self.id)
            return
        client.subscribe(self.address, self.on_message)

    def on_message(self, payload):
        """The MQTT client's callback (any thread)."""
        try:
            value = self.codec.decode(payload)
        except Exception as e:  # reported at the next cycle, on the loop's thread
            with self._lock:
                self._error = e
            return
        self._push(value)


class InputROSNode(_QueuedInputNode):
    """@RosSubscriber: messages of one ROS topic (node id and port: the topic)."""

    type_str = "RosSubscriber"

    def __init__(self, node_id, topic, msg_type):
        _QueuedInputNode.__init__(self, node_id, topic)
        self.msg_type = msg_type

    def configure(self, transports):
        ros = getattr(transports, "ros", None)
        if ros is None:
            raise ComputationalGraphError('RosSubscriber "%s": the experiment has no ROS node; '
                                          'add "ROSNode": {} to its configuration' % self.address)
        ros.subscribe(self.address, self.msg_type, self._push)


class InputTimeNode(InputNode):
    """@Clock ("clock_node", port "clock", ms) and @Iteration ("iteration_node", port
    "iteration"): publish once per update."""

    def __init__(self, node_id, type_str):
        InputNode.__init__(self, node_id)
        self.type_str = type_str
        self._value = 0
        self._new = False

    def update(self, value):
        self._value = int(value)
        self._new = True

    def take(self, port):
        if not self._new:
            return []
        self._new = False
        return [self._value]


class InputDummy(InputNode):
    """@InputDummy (NRP-Core's test node): publishes `value` every cycle."""

    type_str = "InputDummy"

    def __init__(self, node_id, value):
        InputNode.__init__(self, node_id)
        self.value = value

    def take(self, port):
        return [self.value]


# ----------------------------------------------------------------------------- output nodes

class OutputNode(Node):
    """Sends what its ports received: when due (every compute_period cycles, or marked by
    the loop), each stored message in turn; then forgets them unless publish_from_cache."""

    kind = "output"

    def __init__(self, node_id, publish_from_cache=False, max_port_connections=0,
                 compute_period=1):
        Node.__init__(self, node_id)
        if (publish_from_cache or compute_period != 1) and max_port_connections != 1:
            max_port_connections = 1
        self.publish_from_cache = publish_from_cache
        self.max_port_connections = max_port_connections
        self.compute_period = compute_period
        self._n_loop = 0
        self.ports = {}  # port -> [number of connections, stored messages]

    def connect(self, port):
        """Adds a connection to `port` (registering it); raises if the port is full."""
        entry = self.ports.setdefault(port, [0, []])
        if self.max_port_connections and entry[0] >= self.max_port_connections:
            info = "the maximum limit of connections for this port has been reached"
            if self.compute_period != 1:
                info = ("the node has been configured with a compute period different than one "
                        "and can only have one connection per port")
            elif self.publish_from_cache:
                info = ("the node has been configured to publish from cache and can only have "
                        "one connection per port")
            raise ComputationalGraphError('Error when creating graph edge to output node "%s", '
                                          'port "%s": %s. Check your graph definition.'
                                          % (self.id, port, info))
        entry[0] += 1

    def set_compute_period(self, period):
        if self.max_port_connections != 1 and period != 1:
            _log.info('In node "%s". Request to set compute period to %d rejected because the '
                      "node ports can receive more than one connection", self.id, period)
            return
        self.compute_period = period

    def do_compute(self):
        return self._do_compute or (self.compute_period != 0 and
                                    (self._n_loop - 1) % self.compute_period == 0)

    def cycle_start(self):
        self._n_loop += 1

    def receive(self, port, value):
        if value is None:
            return
        stored = self.ports[port][1]
        if self.max_port_connections == 1 and stored:
            stored[-1] = value
        else:
            stored.append(value)

    def compute(self):
        if not self.do_compute():
            return
        for port, (_, stored) in self.ports.items():
            for value in stored:
                self.send(port, value)
            if not self.publish_from_cache:
                stored.clear()

    def send(self, port, value):
        raise NotImplementedError


class OutputEngineNode(OutputNode):
    """@ToEngine: datapacks for one engine ("<engine>_output"); the loop drains them with
    get_datapacks() (the last datapack of each name wins)."""

    type_str = "ToEngine"

    def __init__(self, node_id, engine_name):
        OutputNode.__init__(self, node_id, False, 1, 1)
        self.engine_name = engine_name
        self._lock = threading.Lock()
        self._store = {}

    def send(self, port, value):
        if not isinstance(value, DataPack):
            raise ComputationalGraphError('ToEngine node "%s": a functional node sent it a %s; '
                                          "it takes datapacks" % (self.id, type(value).__name__))
        if value.engine_name != self.engine_name:
            _log.info("In OutputEngineNode '%s'. Received datapack with Id '%s' linked to Engine "
                      "'%s'. This node only accept datapacks linked to Engine '%s'. Please check "
                      "your graph configuration", self.engine_name, value.name,
                      value.engine_name, self.engine_name)
            return
        try:  # copied, so that the node may change its datapack in later cycles
            value = copy.deepcopy(value)
        except Exception:
            pass
        with self._lock:
            self._store[value.name] = value

    def get_datapacks(self):
        """The datapacks sent since the last call (any thread)."""
        with self._lock:
            out, self._store = list(self._store.values()), {}
        return out


class OutputMQTTNode(OutputNode):
    """@MQTTPublisher: publishes on one topic ("<topic>_output")."""

    type_str = "MQTTPublisher"

    def __init__(self, node_id, topic, codec, publish_from_cache=False, compute_period=1):
        OutputNode.__init__(self, node_id, publish_from_cache, 0, compute_period)
        self.address = topic
        self.codec = codec
        self._client = None
        self._warned = False

    def configure(self, transports):
        self._client = getattr(transports, "mqtt", None)

    def send(self, port, value):
        try:
            payload = self.codec.encode(value)
        except (TypeError, ValueError, AttributeError) as e:
            raise ComputationalGraphError('MQTTPublisher "%s": cannot send a %s as %s: %s'
                                          % (self.address, type(value).__name__,
                                             getattr(self.codec.msg_type, "__name__", "?"), e)) \
                from None
        if payload is None:
            return
        if self._client is None:
            if not self._warned:
                _log.warning('From OutputMQTTNode "%s". NRPCoreSim is not connected to MQTT and '
                             "this node can't publish. Check your experiment configuration",
                             self.id)
                self._warned = True
            return
        self._client.publish(self.address, payload)


class OutputROSNode(OutputNode):
    """@RosPublisher: publishes on one ROS topic (node id and port: the topic)."""

    type_str = "RosPublisher"

    def __init__(self, node_id, topic, msg_type, publish_from_cache=False, compute_period=1):
        OutputNode.__init__(self, node_id, publish_from_cache, 0, compute_period)
        self.address = topic
        self.msg_type = msg_type
        self._ros = None

    def configure(self, transports):
        self._ros = getattr(transports, "ros", None)
        if self._ros is None:
            raise ComputationalGraphError('RosPublisher "%s": the experiment has no ROS node; '
                                          'add "ROSNode": {} to its configuration' % self.address)
        advertise = getattr(self._ros, "advertise", None)
        if advertise is not None:  # publishers up before the first message (RospyInterface)
            advertise(self.address, self.msg_type)

    def send(self, port, value):
        if not isinstance(value, self.msg_type):
            raise ComputationalGraphError('RosPublisher "%s": a functional node sent it a %s, not '
                                          "a %s" % (self.address, type(value).__name__,
                                                    self.msg_type.__name__))
        self._ros.publish(self.address, self.msg_type, value)


class OutputDummy(OutputNode):
    """@OutputDummy (NRP-Core's test node): keeps what it sends in `sent`."""

    type_str = "OutputDummy"

    def __init__(self, node_id, publish_from_cache=False, compute_period=1):
        OutputNode.__init__(self, node_id, publish_from_cache, 0, compute_period)
        self.sent = []

    def send(self, port, value):
        self.sent.append(value)
