"""The computational graph: its nodes, its edges, its layers and one cycle of it (NRP-Core
1.4's ComputationalGraphManager and ComputationalGraph).

Layers, as NRP-Core builds them: every input node first, then functional layers (the first
holds the functional nodes fed only by input nodes, or by nothing; each next one the nodes fed
by the previous layers), every output node last. A functional node left out is on a cycle (or
after one): an error. A node without any edge is not in the graph and never runs.

One cycle (compute()):
  1. each output node counts the cycle; in OutputDriven mode each output node due this cycle
     marks every node upstream of it;
  2. every input node publishes what arrived since the last cycle;
  3. the functional layers in order, then the output nodes: in AllNodes mode every node
     (subject to its own policy), in OutputDriven mode only the marked ones.
"""
import logging
import threading

from ._policies import ComputationalGraphError, ExecutionMode

_log = logging.getLogger("nrp_core.event_loop")

CLOCK_NODE = "clock_node"
ITERATION_NODE = "iteration_node"


def parse_address(address, has_port=True):
    """'/node/port' -> (node, port); with has_port False, '/node' -> (node, node)."""
    if not isinstance(address, str) or not address.startswith("/"):
        raise ComputationalGraphError('Error while parsing node address "%s". Computational '
                                      "Graph addresses must start with '/'" % (address,))
    node, sep, port = address[1:].partition("/")
    if not has_port:
        return address[1:], address[1:]
    if not sep:
        raise ComputationalGraphError('Error while parsing node address "%s". Expected format '
                                      "is '/node_id/port_id'" % address)
    return node, port


class ComputationalGraph:
    """The nodes registered by decorators, the edges between them, and how to run a cycle."""

    def __init__(self, exec_mode=ExecutionMode.ALL_NODES):
        self.exec_mode = ExecutionMode.check(exec_mode)
        self.nodes = {}        # id -> node, in registration order
        self._succ = {}        # node id -> [successor ids] (edges, in insertion order)
        self._pred = {}        # node id -> [predecessor ids]
        self.input_layer = []
        self.functional_layers = []
        self.output_layer = []
        self.configured = False
        self.anonymous_ports = 0  # @ToEngine's "anonymous_port<N>"
        self.lock = threading.RLock()  # held by compute() (the GIL's role in NRP-Core)

    # ------------------------------------------------------------------------ registration
    def register_node(self, node):
        """Registers `node`; returns the node registered under its id (an input or output
        node of the same kind is shared by several decorators)."""
        existing = self.nodes.get(node.id)
        if existing is None:
            self.nodes[node.id] = node
            return node
        if existing.kind != node.kind or type(existing) is not type(node):
            raise ComputationalGraphError('Duplicated node name: "%s" in nodes with type "%s" and '
                                          '"%s". This is not allowed.'
                                          % (node.id, node.type_str, existing.type_str))
        if node.kind == "functional":
            raise ComputationalGraphError('Duplicated Node Name: Attempt to register Functional '
                                          'Node with name "%s". But a node with that name already '
                                          "exists." % node.id)
        return existing

    def add_edge(self, source, target):
        if self.configured:
            raise ComputationalGraphError("Inserting edges while the graph is being configured or "
                                          "is configured is not allowed")
        if source is target:
            raise ComputationalGraphError('Attempt to insert edge from node "%s" to itself. This '
                                          "is not allowed" % source.id)
        if source.kind == "output" or target.kind == "input":
            raise ComputationalGraphError('Attempt to insert edge from "%s" to "%s": an output '
                                          "node can't be a source, an input node can't be a "
                                          "target"
                                          % (source.id, target.id))
        succ = self._succ.setdefault(source.id, [])
        if target.id not in succ:
            succ.append(target.id)
            self._pred.setdefault(target.id, []).append(source.id)
        self._pred.setdefault(source.id, [])
        self._succ.setdefault(target.id, [])

    def in_graph(self, node_id):
        return node_id in self._succ

    # ------------------------------------------------------------------------- configuring
    def load_complete(self):
        """Makes the edges asked for by @FromFunctionalNode (NRP-Core's graphLoadComplete)."""
        for node in list(self.nodes.values()):
            node.graph_loaded(self)

    def configure(self, transports=None):
        """Builds the layers, checks for cycles and configures every node in the graph
        (MQTT and ROS subscriptions). Raises ComputationalGraphError."""
        if self.configured:
            raise ComputationalGraphError("Graph is already configured")
        members = [n for n in self.nodes.values() if self.in_graph(n.id)]
        for node in self.nodes.values():
            node.visited = False
        self.input_layer = [n for n in members if n.kind == "input"]
        self.output_layer = [n for n in members if n.kind == "output"]
        self.functional_layers = self._functional_layers(members)
        left = [n for n in members if n.kind == "functional" and not n.visited]
        if left:
            raise ComputationalGraphError(self._cycle_message(left))
        self._check_time_nodes()
        for node in members:
            node.configure(transports)
        self._warn(members)
        self.configured = True

    def _functional_layers(self, members):
        for node in self.input_layer + self.output_layer:
            node.visited = True
        layer = [n for n in members if n.kind == "functional" and
                 all(self.nodes[p].kind == "input" for p in self._pred[n.id])]
        layers = []
        while layer:
            for node in layer:
                node.visited = True
            layers.append(layer)
            candidates = []
            for node in layer:
                for s in self._succ[node.id]:
                    nxt = self.nodes[s]
                    if nxt.kind == "functional" and not nxt.visited and nxt not in candidates:
                        candidates.append(nxt)
            layer = [n for n in candidates
                     if all(self.nodes[p].visited for p in self._pred[n.id])]
        return layers

    def _cycle_message(self, left):
        """Names a cycle among the functional nodes left out of the layers."""
        left_ids = {n.id for n in left}
        cycle = None
        for start in left:
            cycle = self._find_cycle(start.id, left_ids)
            if cycle:
                break
        text = " -> ".join('"%s"' % c for c in cycle) if cycle else ""
        others = sorted(left_ids - set(cycle or []))
        msg = "Cycle(s) found in the graph. Cycles are not supported: " + text
        if others:
            msg += " (nodes after the cycle: %s)" % ", ".join('"%s"' % o for o in others)
        return msg

    def _find_cycle(self, start, allowed):
        path, on_path, done = [], set(), set()

        def visit(node_id):
            path.append(node_id)
            on_path.add(node_id)
            for s in self._succ[node_id]:
                if s in on_path:
                    return path[path.index(s):] + [s]
                if s in allowed and s not in done:
                    found = visit(s)
                    if found:
                        return found
            on_path.discard(path.pop())
            done.add(node_id)
            return None

        return visit(start)

    def _check_time_nodes(self):
        for node_id, what in ((CLOCK_NODE, "Clock"), (ITERATION_NODE, "Iteration")):
            node = self.nodes.get(node_id)
            if node is not None and node.type_str != what:
                raise ComputationalGraphError(
                    "Exception in the ComputationalGraph: found Node with id '%s', which is "
                    "reserved for the input %s node" % (node_id, what))

    def _warn(self, members):
        for node in self.nodes.values():
            if not self.in_graph(node.id):
                _log.warning('Graph node "%s" is disconnected. It will not be executed.', node.id)
        for node in members:
            if node.kind == "functional":
                inputs, outputs = node.unconnected()
                for k in inputs:
                    _log.warning('In python functional node "%s". Input argument "%s" is not '
                                 "connected", node.id, k)
                for o in outputs:
                    _log.warning('In python functional node "%s". Output "%s" is not connected',
                                 node.id, o)

    # ------------------------------------------------------------------------------ running
    def compute(self):
        """Runs one cycle of the graph."""
        if not self.configured:
            raise ComputationalGraphError("Graph is not configured. Please (re-)build the graph "
                                          "by calling 'configure()'")
        with self.lock:
            output_driven = self.exec_mode == ExecutionMode.OUTPUT_DRIVEN
            for node in self.output_layer:
                node.cycle_start()
                if output_driven and node.do_compute():
                    self._mark_upstream(node)
            for node in self.input_layer:
                node.compute()
            for layer in self.functional_layers + [self.output_layer]:
                for node in layer:
                    if not output_driven or node.do_compute():
                        node.compute()
                        node.set_do_compute(False)

    def _mark_upstream(self, node):
        stack = [node.id]
        while stack:
            for p in self._pred[stack.pop()]:
                pred = self.nodes[p]
                if not pred.do_compute():
                    pred.set_do_compute(True)
                    stack.append(p)

    # ---------------------------------------------------------------- queries for the loop
    def layers(self):
        """[[input ids], [functional ids]..., [output ids]]: the order nodes run in."""
        return [[n.id for n in layer] for layer in
                [self.input_layer] + self.functional_layers + [self.output_layer]]

    def nodes_of(self, type_str):
        return [n for n in self.nodes.values() if n.type_str == type_str and self.in_graph(n.id)]

    def time_node(self, node_id):
        node = self.nodes.get(node_id)
        return node if node is not None and self.in_graph(node_id) else None


_current = ComputationalGraph()


def current():
    """The graph decorators register into (NRP-Core's ComputationalGraphManager instance)."""
    return _current


def reset(exec_mode=ExecutionMode.ALL_NODES):
    """Starts a new, empty graph for decorators to register into; returns it."""
    global _current
    _current = ComputationalGraph(exec_mode)
    return _current
