"""The edge decorators of NRP-Core 1.4's nrp_core.event_loop, with its names, signatures and
defaults. Each is a class whose instance, called with a FunctionalNode, connects it and
returns it, so they stack above @FunctionalNode or are called directly: FromEngine(...)(fn).

  FromFunctionalNode(keyword, address="/node/output")
  FromEngine(keyword, address="/engine/datapack", cache_policy=msg_cache.keep)
  ToEngine(keyword, address="/engine")
  MQTTSubscriber(keyword, address=topic, type, publish_policy=msg_publish.last,
                 cache_policy=msg_cache.keep)
  MQTTPublisher(keyword, address=topic, type, publish_from_cache=False, compute_period=1)
  RosSubscriber(keyword, address=topic, type, publish_policy=last, cache_policy=keep)
  RosPublisher(keyword, address=topic, type, publish_from_cache=False, compute_period=1)
  Clock(keyword)            ms since the loop started (EventLoop) or simulated ms (FTILoop)
  Iteration(keyword)        the loop's cycle, from 0
  InputDummy(keyword, address, value), OutputDummy(keyword, address, publish_from_cache=False,
             compute_period=1)    NRP-Core's test nodes
"""
from . import _graph
from ._codec import check_ros_type, mqtt_codec
from ._functional import FunctionalNode
from ._nodes import (InputDummy as _InputDummyNode, InputEngineNode, InputMQTTNode, InputROSNode,
                     InputTimeNode, OutputDummy as _OutputDummyNode, OutputEngineNode,
                     OutputMQTTNode, OutputROSNode)
from ._policies import KEEP, LAST, ComputationalGraphError, check_policy, node_policies

_cache_enum = node_policies.input_node.msg_cache
_publish_enum = node_policies.input_node.msg_publish


def _functional(obj, node_id, what):
    if not isinstance(obj, FunctionalNode) or obj.function is None:
        raise ComputationalGraphError(
            '%s "%s" was called with the wrong argument type (%s). Argument must be a '
            "FunctionalNode object: put @FunctionalNode(...) last, right above the function"
            % (what, node_id, type(obj).__name__))
    return obj


def _check_str(value, what):
    if not isinstance(value, str):
        raise TypeError("%s must be a string, got %r" % (what, value))
    return value


def _check_period(value):
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise TypeError("compute_period must be a non-negative int, got %r" % (value,))
    return value


class _InputEdge:
    """Connects an input node's port to an input of the functional node."""

    def __init__(self, keyword, node_id, port, publish_policy=LAST, cache_policy=KEEP):
        self._keyword = _check_str(keyword, "keyword")
        self._id = node_id
        self._port = port
        self._publish_policy = check_policy(publish_policy, _publish_enum, "publish_policy")
        self._cache_policy = check_policy(cache_policy, _cache_enum, "cache_policy")

    def _make_node(self):
        raise NotImplementedError

    def __call__(self, fn):
        fn = _functional(fn, self._id, "InputEdge")
        graph = _graph.current()
        node = graph.register_node(self._make_node())
        node.publish_policy = self._publish_policy
        node.cache_policy = self._cache_policy
        node.register_port(self._port)
        fn.connect_input(self._keyword, 'port "%s" of node "%s"' % (self._port, node.id))
        node.subscribe(self._port, fn, self._keyword)
        graph.add_edge(node, fn)
        return fn


class _OutputEdge:
    """Connects an output of the functional node to an output node's port."""

    def __init__(self, keyword, node_id, port, publish_from_cache=False, compute_period=1):
        self._keyword = _check_str(keyword, "keyword")
        self._id = node_id
        self._port = port
        if not isinstance(publish_from_cache, bool):
            raise TypeError("publish_from_cache must be a bool, got %r" % (publish_from_cache,))
        self._from_cache = publish_from_cache
        self._period = _check_period(compute_period)

    def _make_node(self):
        raise NotImplementedError

    def __call__(self, fn):
        fn = _functional(fn, self._id, "OutputEdge")
        graph = _graph.current()
        node = graph.register_node(self._make_node())
        if self._keyword not in fn.outputs:
            fn.add_subscriber(self._keyword, node, self._port)  # raises, naming the outputs
        node.connect(self._port)
        fn.add_subscriber(self._keyword, node, self._port)
        graph.add_edge(fn, node)
        return fn


class FromFunctionalNode:
    """Feeds input `keyword` from output `address` ("/node/output") of another functional
    node, which may be declared later (the edge is made when the graph has loaded)."""

    def __init__(self, keyword, address):
        self._keyword = _check_str(keyword, "keyword")
        self._address = _check_str(address, "address")
        _graph.parse_address(address)

    def __call__(self, fn):
        fn = _functional(fn, self._address, "FromFunctionalNode")
        fn.check_input(self._keyword)
        fn.request_f2f_edge(self._keyword, self._address)
        return fn


class FromEngine(_InputEdge):
    """Feeds input `keyword` with datapack `address` ("/engine/datapack")."""

    def __init__(self, keyword, address, cache_policy=KEEP):
        engine, datapack = _graph.parse_address(_check_str(address, "address"))
        _InputEdge.__init__(self, keyword, engine + "_input", datapack, LAST, cache_policy)
        self._engine = engine

    def _make_node(self):
        return InputEngineNode(self._id, self._engine)


class ToEngine(_OutputEdge):
    """Sends output `keyword` (a datapack) to engine `address` ("/engine")."""

    def __init__(self, keyword, address):
        engine, _ = _graph.parse_address(_check_str(address, "address"), has_port=False)
        graph = _graph.current()
        port = "anonymous_port%d" % graph.anonymous_ports
        graph.anonymous_ports += 1
        _OutputEdge.__init__(self, keyword, engine + "_output", port)
        self._engine = engine

    def _make_node(self):
        return OutputEngineNode(self._id, self._engine)


class MQTTSubscriber(_InputEdge):
    """Feeds input `keyword` with the messages of MQTT topic `address`, as `type`."""

    def __init__(self, keyword, address, type, publish_policy=LAST, cache_policy=KEEP):
        _check_str(address, "address")
        _InputEdge.__init__(self, keyword, address + "_input", address, publish_policy,
                            cache_policy)
        self._codec = mqtt_codec(type, address, True)

    def _make_node(self):
        return InputMQTTNode(self._id, self._port, self._codec)


class MQTTPublisher(_OutputEdge):
    """Publishes output `keyword` on MQTT topic `address`, as `type`."""

    def __init__(self, keyword, address, type, publish_from_cache=False, compute_period=1):
        _check_str(address, "address")
        _OutputEdge.__init__(self, keyword, address + "_output", address, publish_from_cache,
                             compute_period)
        self._codec = mqtt_codec(type, address, False)

    def _make_node(self):
        return OutputMQTTNode(self._id, self._port, self._codec, self._from_cache, self._period)


class RosSubscriber(_InputEdge):
    """Feeds input `keyword` with the messages of ROS topic `address` (node id: the topic)."""

    def __init__(self, keyword, address, type, publish_policy=LAST, cache_policy=KEEP):
        _check_str(address, "address")
        _InputEdge.__init__(self, keyword, address, address, publish_policy, cache_policy)
        self._type = check_ros_type(type, address, True)

    def _make_node(self):
        return InputROSNode(self._id, self._port, self._type)


class RosPublisher(_OutputEdge):
    """Publishes output `keyword` on ROS topic `address` (node id: the topic)."""

    def __init__(self, keyword, address, type, publish_from_cache=False, compute_period=1):
        _check_str(address, "address")
        _OutputEdge.__init__(self, keyword, address, address, publish_from_cache, compute_period)
        self._type = check_ros_type(type, address, False)

    def _make_node(self):
        return OutputROSNode(self._id, self._port, self._type, self._from_cache, self._period)


class Clock(_InputEdge):
    """Feeds input `keyword` with the loop's clock, in ms (node "clock_node", port "clock")."""

    def __init__(self, keyword):
        _InputEdge.__init__(self, keyword, _graph.CLOCK_NODE, "clock")

    def _make_node(self):
        return InputTimeNode(self._id, "Clock")


class Iteration(_InputEdge):
    """Feeds input `keyword` with the loop's cycle number (node "iteration_node")."""

    def __init__(self, keyword):
        _InputEdge.__init__(self, keyword, _graph.ITERATION_NODE, "iteration")

    def _make_node(self):
        return InputTimeNode(self._id, "Iteration")


class InputDummy(_InputEdge):
    """NRP-Core's test input: publishes `value` every cycle (node and port: `address`)."""

    def __init__(self, keyword, address, value):
        _InputEdge.__init__(self, keyword, _check_str(address, "address"), address)
        self._value = value

    def _make_node(self):
        return _InputDummyNode(self._id, self._value)


class OutputDummy(_OutputEdge):
    """NRP-Core's test output: keeps what it is sent in node.sent (node and port: address)."""

    def __init__(self, keyword, address, publish_from_cache=False, compute_period=1):
        _OutputEdge.__init__(self, keyword, _check_str(address, "address"), address,
                             publish_from_cache, compute_period)

    def _make_node(self):
        return _OutputDummyNode(self._id, self._from_cache, self._period)


class _Unsupported:
    what = ""

    def __init__(self, *args, **kwargs):
        raise ComputationalGraphError("%s: SpiNNaker nodes are not supported by Convoy"
                                      % self.what)


class FromSpinnaker(_Unsupported):
    what = "FromSpinnaker"


class ToSpinnaker(_Unsupported):
    what = "ToSpinnaker"
