"""Loading a computational graph from the config's ComputationalGraph files (NRP-Core 1.4's
createPythonGraphFromConfig).

Every file is executed in order in one shared globals dict (a later file sees the names an
earlier one defined); then the @FromFunctionalNode edges are made (so they may point to a node
of a later file) and the graph is configured. A missing file, or a file that raises, fails
with "Loading of computation graph file "<file>" failed: ..." as in NRP-Core.
"""
import builtins
import os
import sys
import traceback

from . import _graph
from ._policies import ComputationalGraphError, ExecutionMode


def load_computational_graph(files, exec_mode=ExecutionMode.ALL_NODES, transports=None,
                             base_dir=None, fti_loop=False):
    """Executes the graph files and returns the configured ComputationalGraph.

    files: the config's ComputationalGraph list; relative names are taken from base_dir
    (the experiment's directory; default: the current directory), which is also put on
    sys.path so that a file can import modules next to it.
    exec_mode: the config's EventLoop.ExecutionMode ("AllNodes" or "OutputDriven").
    transports: a Transports (MQTT client, ROS node) for the input and output nodes.
    fti_loop: the graph is the FTILoop's DataPackProcessor ("cg"): OutputDriven mode, and
    ToEngine nodes run only when the loop marks them (their engine has synced).
    """
    if isinstance(files, str):
        files = [files]
    if fti_loop:
        exec_mode = ExecutionMode.OUTPUT_DRIVEN
    graph = _graph.reset(exec_mode)
    shared = {"__builtins__": builtins}
    if base_dir and base_dir not in sys.path:
        sys.path.insert(0, base_dir)
    try:
        for name in files:
            _exec_file(name, base_dir, shared)
        graph.load_complete()
        if fti_loop:
            for node in graph.nodes_of("ToEngine"):
                node.set_compute_period(0)
        graph.configure(transports)
    finally:
        _graph.reset()  # later decorators do not touch the loaded graph
    return graph


def _exec_file(name, base_dir, shared):
    path = name if os.path.isabs(name) or not base_dir else os.path.join(base_dir, name)
    if not os.path.isfile(path):
        raise ComputationalGraphError('Loading of computation graph file "%s" failed: the file '
                                      "doesn't exist." % name)
    try:
        with open(path, "rb") as f:
            code = compile(f.read(), path, "exec")
        exec(code, shared)
    except ComputationalGraphError as e:
        raise ComputationalGraphError('Loading of computation graph file "%s" failed: %s'
                                      % (name, e)) from e
    except (Exception, SystemExit) as e:
        detail = "".join(traceback.format_exception(type(e), e, e.__traceback__.tb_next
                                                    if e.__traceback__ else None))
        raise ComputationalGraphError('Loading of computation graph file "%s" failed: %s'
                                      % (name, detail.rstrip())) from e
