"""Base class of Python protobuf engines (EngineType python_grpc), as in NRP-Core.

A script subclasses GrpcEngineScript (NRP-Core expects the class to be named Script) and
registers each datapack with a protobuf message class, e.g. `nrp_protobuf.dump_pb2.String`.
_getDataPack returns the message itself: changing it in place changes the datapack. A
datapack registered and never set holds a default message. A datapack a transceiver function
sends replaces the engine's message (a new object; earlier references keep the old one).

The server sets `_name` and `_config`, advances `_time_ns` to the end of the step being run,
then calls runLoop(timestep_ns)."""

from google.protobuf.message import Message


class GrpcEngineScript:

    def __init__(self):
        self._time_ns = 0
        self._name = ""
        self._config = {}
        self._datapacks = {}  # name -> message
        self._datapack_types = {}  # name -> message class

    # --- to override -------------------------------------------------------------------
    def initialize(self):
        pass

    def runLoop(self, timestep_ns):
        pass

    def shutdown(self):
        pass

    def reset(self):
        pass

    # --- datapacks ---------------------------------------------------------------------
    def _getEngineName(self):
        return self._name

    def _registerDataPack(self, datapack_name, protobuf_type):
        if datapack_name in self._datapacks:
            raise ValueError("engine '%s': datapack '%s' is already registered"
                             % (self._name, datapack_name))
        if not (isinstance(protobuf_type, type) and issubclass(protobuf_type, Message)):
            raise TypeError("engine '%s': _registerDataPack('%s', %r): the type must be a "
                            "protobuf message class (e.g. nrp_protobuf.dump_pb2.String)"
                            % (self._name, datapack_name, protobuf_type))
        self._check_type(datapack_name, protobuf_type)
        self._datapack_types[datapack_name] = protobuf_type
        self._datapacks[datapack_name] = protobuf_type()

    def _getRegisteredDataPackNames(self):
        return list(self._datapacks)

    def _getDataPack(self, datapack_name):
        try:
            return self._datapacks[datapack_name]
        except KeyError:
            raise ValueError("engine '%s': datapack '%s' is not registered"
                             % (self._name, datapack_name)) from None

    def _setDataPack(self, datapack_name, data):
        try:
            cls = self._datapack_types[datapack_name]
        except KeyError:
            raise ValueError("engine '%s': datapack '%s' is not registered"
                             % (self._name, datapack_name)) from None
        if not isinstance(data, cls):
            raise TypeError("engine '%s': datapack '%s' was registered with type %s, set with %s"
                            % (self._name, datapack_name, cls.DESCRIPTOR.full_name,
                               _type_name(data)))
        self._datapacks[datapack_name] = data

    def _advanceTime(self, timestep_ns):
        self._time_ns += timestep_ns

    def _check_type(self, datapack_name, protobuf_type):
        """Set by the engine server: refuses a type Convoy cannot carry."""


def _type_name(data):
    descriptor = getattr(type(data), "DESCRIPTOR", None)
    full_name = getattr(descriptor, "full_name", None)
    return full_name if isinstance(full_name, str) else type(data).__name__


__all__ = ["GrpcEngineScript"]
