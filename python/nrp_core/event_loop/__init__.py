"""Convoy's implementation of NRP-Core 1.4's nrp_core.event_loop: the computational graph
(CG) of functional nodes and input/output nodes, written in pure Python.

A CG file, as in NRP-Core:

    from nrp_core.event_loop import *

    @FromEngine(keyword="joints", address="/gazebo/joints")
    @ToEngine(keyword="cmd", address="/gazebo")
    @FunctionalNode(name="controller", outputs=["cmd"])
    def controller(joints):
        ...
        return [cmd_datapack]

The coordinator loads the config's ComputationalGraph files with load_computational_graph()
and runs the graph with an EventLoop (SimulationLoop "EventLoop") or an FTIStep (FTILoop with
DataPackProcessor "cg"); engine datapacks move through an EngineLink, MQTT and ROS through
the Transports it provides (see _transport.py; RospyInterface is the ROS one, on rospy).
C++ functional nodes: createFNFromFactoryModule (see _factory_module.py).
"""
from ._codec import JSON_DATAPACK_TYPE  # noqa: F401
from ._decorators import (Clock, FromEngine, FromFunctionalNode, FromSpinnaker,  # noqa: F401
                          InputDummy, Iteration, MQTTPublisher, MQTTSubscriber, OutputDummy,
                          RosPublisher, RosSubscriber, ToEngine, ToSpinnaker)
from ._functional import FunctionalNode, createFNFromFactoryModule  # noqa: F401
from ._graph import ComputationalGraph  # noqa: F401
from ._loader import load_computational_graph  # noqa: F401
from ._loop import EventLoop, EventLoopInterface, FTIStep  # noqa: F401
from ._policies import ComputationalGraphError, ExecutionMode, node_policies  # noqa: F401
from ._rospy_transport import RospyInterface  # noqa: F401  (imports rospy when constructed)
from ._transport import (DataPackSink, DataPackSource, EngineLink, MQTTClient,  # noqa: F401
                         ROSInterface, Transports)

# What `from nrp_core.event_loop import *` gives a CG file: NRP-Core's names.
__all__ = ["node_policies", "FunctionalNode", "FromFunctionalNode", "FromEngine", "ToEngine",
           "MQTTSubscriber", "MQTTPublisher", "RosSubscriber", "RosPublisher", "Clock",
           "Iteration", "InputDummy", "OutputDummy", "FromSpinnaker", "ToSpinnaker",
           "createFNFromFactoryModule", "EventLoopInterface"]
