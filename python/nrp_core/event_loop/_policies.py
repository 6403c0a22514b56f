"""Node policies with NRP-Core's spellings, and the error the graph raises.

    node_policies.input_node.msg_cache.{keep, clear}
    node_policies.input_node.msg_publish.{last, all}
    node_policies.functional_node.exec_policy.{on_new_message, always}
    node_policies.output_node.publish_format.{series, batch}

As in NRP-Core (boost.python enums with export_values()), each value is also reachable one
level up: node_policies.input_node.keep, node_policies.functional_node.always...
"""


class ComputationalGraphError(RuntimeError):
    """A computational-graph file or a graph cycle failed; the message names the node."""


class _Policy:
    """One value of a policy enum; compared by identity."""

    __slots__ = ("enum", "name")

    def __init__(self, enum, name):
        self.enum = enum
        self.name = name

    def __repr__(self):
        return "nrp_core.event_loop.node_policies.%s.%s" % (self.enum, self.name)

    __str__ = __repr__


def _enum(path, *names):
    values = {n: _Policy(path, n) for n in names}
    cls = type(path.rsplit(".", 1)[-1], (), dict(values, names=values, path=path,
                                                 __doc__="Values: " + ", ".join(names)))
    return cls, values


_msg_cache, _cache_values = _enum("input_node.msg_cache", "clear", "keep")
_msg_publish, _publish_values = _enum("input_node.msg_publish", "last", "all")
_exec_policy, _exec_values = _enum("functional_node.exec_policy", "on_new_message", "always")
_publish_format, _format_values = _enum("output_node.publish_format", "series", "batch")


class node_policies:  # noqa: N801 (NRP-Core's name)
    """NRP-Core's node_policies namespace."""

    class input_node:  # noqa: N801
        msg_cache = _msg_cache
        msg_publish = _msg_publish
        locals().update(_cache_values)
        locals().update(_publish_values)

    class functional_node:  # noqa: N801
        exec_policy = _exec_policy
        locals().update(_exec_values)

    class output_node:  # noqa: N801
        publish_format = _publish_format
        locals().update(_format_values)


KEEP = _cache_values["keep"]
CLEAR = _cache_values["clear"]
LAST = _publish_values["last"]
ALL = _publish_values["all"]
ON_NEW_MESSAGE = _exec_values["on_new_message"]
ALWAYS = _exec_values["always"]


def check_policy(value, enum, what):
    """Raises TypeError unless `value` is a value of `enum` (as boost.python does)."""
    if not isinstance(value, _Policy) or value.enum != enum.path:
        raise TypeError("%s must be one of node_policies.%s.{%s}, got %r"
                        % (what, enum.path, ", ".join(enum.names), value))
    return value


class ExecutionMode:
    """The config's EventLoop.ExecutionMode: AllNodes runs every node each cycle (subject to
    its own policy); OutputDriven runs only the nodes upstream of the output nodes due this
    cycle."""

    ALL_NODES = "AllNodes"
    OUTPUT_DRIVEN = "OutputDriven"

    @staticmethod
    def check(mode):
        if mode not in (ExecutionMode.ALL_NODES, ExecutionMode.OUTPUT_DRIVEN):
            raise ValueError('ExecutionMode must be "AllNodes" or "OutputDriven", got %r' % (mode,))
        return mode
