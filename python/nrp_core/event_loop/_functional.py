"""@FunctionalNode: a Python function as a node of the computational graph (NRP-Core 1.4's
PythonFunctionalNode).

    @FunctionalNode(name="transfer_fn", outputs=["out"], exec_policy=...on_new_message)
    def f(a, b): return [value]          # or None: nothing is published this cycle

The node's inputs are the function's arguments (inspect.getfullargspec(f).args), passed by
keyword; an input with no connection or no data yet is None. With exec_policy.on_new_message
(the default) the node runs in a cycle where one of its inputs received a value other than
None; with exec_policy.always, in every cycle. It returns None or a list with one item per
declared output.
"""
import inspect
import os
import traceback

from . import _graph
from ._nodes import Node
from ._policies import ALWAYS, ON_NEW_MESSAGE, ComputationalGraphError, check_policy, \
    node_policies

MAX_PORTS = 10  # inputs and outputs of one node (NRP-Core's PythonFunctionalNode)
PY_OBJECT_TYPE = "N5boost6python3api6objectE"  # typeid(boost::python::object).name()


def _check_types(source, output, target, keyword):
    """An edge between functional nodes joins ports of the same C++ type (NRP-Core's
    createEdge): what matters only when a C++ node (createFNFromFactoryModule) is on it."""
    out_id, out_type = source.port_type(output, False)
    in_id, in_type = target.port_type(keyword, True)
    if out_id != in_id:
        raise ComputationalGraphError(
            "In Functional node '%s'. Error While creating edge to port '%s'. Attempt to connect "
            "to port '%s' of node '%s', but they are of different types (%s and %s)."
            % (target.id, keyword, output, source.id, out_type, in_type))


class FunctionalNode(Node):
    """NRP-Core's FunctionalNode decorator; the object it returns is the node itself."""

    kind = "functional"
    type_str = "FunctionalNode"

    def __init__(self, name, outputs, exec_policy=ON_NEW_MESSAGE):
        if not isinstance(name, str):
            raise TypeError("FunctionalNode name must be a string, got %r" % (name,))
        if isinstance(outputs, str) or not all(isinstance(o, str) for o in outputs):
            raise TypeError('FunctionalNode "%s": outputs must be a list of strings, got %r'
                            % (name, outputs))
        Node.__init__(self, name)
        self.outputs = list(outputs)
        self.exec_policy = check_policy(exec_policy, node_policies.functional_node.exec_policy,
                                        "exec_policy")
        self.function = None
        self.inputs = []
        self._values = {}
        self._sources = {}    # input keyword -> description of what is connected to it
        self._has_new = False
        self._subscribers = {o: [] for o in self.outputs}  # output -> [(node, port)]
        self._f2f = {}         # input keyword -> "/node/output" (made when the graph loads)

    # -------------------------------------------------------------------- set-up (decoration)
    def __call__(self, function):
        if self.function is not None:
            raise ComputationalGraphError('Duplicated Node Name: Attempt to register Functional '
                                          'Node with name "%s". But a node with that name '
                                          "already exists." % self.id)
        if not callable(function):
            raise TypeError('FunctionalNode "%s" decorates a %s, not a function'
                            % (self.id, type(function).__name__))
        self.inputs = list(inspect.getfullargspec(function).args)
        if len(self.inputs) > MAX_PORTS or len(self.outputs) > MAX_PORTS:
            raise ComputationalGraphError('FunctionalNode "%s": at most %d inputs and %d outputs'
                                          % (self.id, MAX_PORTS, MAX_PORTS))
        self.function = function
        self.__name__ = getattr(function, "__name__", self.id)
        self.__doc__ = getattr(function, "__doc__", None)
        _graph.current().register_node(self)
        return self

    def check_input(self, keyword):
        if keyword not in self.inputs:
            raise ComputationalGraphError('"%s" does not match any of the declared input '
                                          'arguments in node "%s"' % (keyword, self.id))

    def connect_input(self, keyword, source):
        """Records that `source` (a description) feeds input `keyword`: one source per input."""
        self.check_input(keyword)
        if keyword in self._sources:
            raise ComputationalGraphError('Port "%s" of node "%s" can only have 1 subscriber(s): '
                                          "it is connected to %s and %s"
                                          % (keyword, self.id, self._sources[keyword], source))
        self._sources[keyword] = source

    def add_subscriber(self, output, node, port):
        if output not in self._subscribers:
            raise ComputationalGraphError('"%s" does not match any of the declared outputs of '
                                          'node "%s" (outputs: %s)'
                                          % (output, self.id, ", ".join(self.outputs) or "none"))
        self._subscribers[output].append((node, port))

    def request_f2f_edge(self, keyword, address):
        self._f2f[keyword] = address

    def graph_loaded(self, graph):
        """Makes the @FromFunctionalNode edges, now that every node is registered."""
        requests, self._f2f = self._f2f, {}
        for keyword, address in requests.items():
            node_id, port = _graph.parse_address(address)
            full = "/%s/%s" % (node_id, port)
            other = graph.nodes.get(node_id)
            if not isinstance(other, FunctionalNode):
                raise ComputationalGraphError(
                    "While creating the F2F edge '%s' (input \"%s\" of node \"%s\"). A Functional "
                    "node with name '%s' could not be found in the computational graph. Be sure "
                    "that the edge address is correctly formatted and the connected node exists."
                    % (full, keyword, self.id, node_id))
            if port not in other.outputs:
                raise ComputationalGraphError(
                    "While creating the F2F edge '%s' (input \"%s\" of node \"%s\"). Functional "
                    "node '%s' doesn't have a declared output '%s'. Be sure that the edge address "
                    "is correctly formatted and the specified output exists."
                    % (full, keyword, self.id, node_id, port))
            _check_types(other, port, self, keyword)
            self.connect_input(keyword, "'%s'" % full)
            other.add_subscriber(port, self, keyword)
            graph.add_edge(other, self)

    def unconnected(self):
        """(inputs, outputs) with no connection, for the graph's warnings."""
        return ([k for k in self.inputs if k not in self._sources],
                [o for o in self.outputs if not self._subscribers[o]])

    def port_type(self, port, is_input):
        """(C++ type id, type as written) of a port: a Python node's are boost::python
        objects, as in NRP-Core."""
        return PY_OBJECT_TYPE, "boost::python::object"

    # ------------------------------------------------------------------------------ running
    def receive(self, keyword, value):
        self._values[keyword] = value
        self._has_new = self._has_new or value is not None

    def compute(self):
        if self.exec_policy is ALWAYS or self._has_new:
            result = self._run()
            if result is not None:
                for output, value in zip(self.outputs, result):
                    for node, port in self._subscribers[output]:
                        node.receive(port, value)
        self._has_new = False

    def _run(self):
        kwargs = {k: self._values.get(k) for k in self.inputs}
        try:
            result = self.function(**kwargs)
        except Exception as e:
            # The user's frames only: this method's own is left out.
            trace = traceback.format_exception(type(e), e, e.__traceback__.tb_next)
            raise ComputationalGraphError('An error occurred while executing Functional Node with '
                                          'id "%s":\n%s' % (self.id, "".join(trace))) from e
        if result is None:
            return None
        if not isinstance(result, list):
            raise ComputationalGraphError('An error occurred while executing Functional Node with '
                                          'id "%s". It is expected to return an object of type '
                                          "list or None, it returned a %s"
                                          % (self.id, type(result).__name__))
        if len(result) != len(self.outputs):
            raise ComputationalGraphError('Functional Node with id "%s" has %d declared outputs, '
                                          "but returns %d elements."
                                          % (self.id, len(self.outputs), len(result)))
        return result


def createFNFromFactoryModule(module_name, function_name, node_name, exec_policy):  # noqa: N802
    """NRP-Core's C++ functional node: a node named `node_name` running C++ function
    `function_name` of FN factory module `module_name` (a libFNFactoryModule.so built with
    build_fn_factory_module.sh, looked for in the calling graph file's folder, the current
    folder, then LD_LIBRARY_PATH). Returns the node, for FromFunctionalNode(...)(fn) etc."""
    import sys
    from ._factory_module import create_node
    exec_policy = check_policy(exec_policy, node_policies.functional_node.exec_policy,
                               "exec_policy")
    caller = sys._getframe(1).f_code.co_filename
    caller_dir = os.path.dirname(os.path.abspath(caller)) if os.path.isfile(caller) else None
    return create_node(module_name, function_name, node_name, exec_policy, caller_dir)
