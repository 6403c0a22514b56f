"""Protobuf datapacks of the world engine, as in NRP-Core's nrp_core.data.nrp_protobuf.

The data objects answer to the report's attribute names and to NRP-Core 1.4's:
  GazeboCameraDataPack.data: image_height/imageHeight, image_width/imageWidth,
      image_depth/imageDepth, image_data/imageData (numpy uint8, 1-D)
  GazeboJointDataPack.data:  position, velocity, effort
  GazeboLinkDataPack.data:   pos/position, rot/rotation (x y z w), lin_vel/linear_velocity,
      ang_vel/angular_velocity (numpy float32)
A camera image received in a transceiver function is a read-only view on the engine's
frame (no copy): copy it (image_data.copy()) to change it or keep it beyond the call.

Every other protobuf message registered in Convoy's datapack registry (src/datapack) has a
datapack class here too, made on first use: `<Package><Message>DataPack` by NRP-Core's rule
(or the name given at registration), whose .data is a message of Debian's Python protobuf,
and a `<Package><Message>RawData` class (what status functions return), whose .data is the
message alone. NRP-Core's message set (Dump, EngineTest, Gazebo, NrpGenericProto, Wrappers)
is always registered: DumpStringDataPack, NrpGenericProtoImageDataPack,
WrappersBoolValueDataPack, EngineTestTestPayloadRawData... Their .data is an instance of the
class that `from nrp_protobuf import dump_pb2` gives engines (dump_pb2.String).
"""
import importlib

import numpy as np

from nrp_core._datapacks import (DataPack, DataPackIdentifier, RawData,  # noqa: F401
                                 SerializedMessage, _received)


def _alias(name):
    return property(lambda self: getattr(self, name),
                    lambda self, value: setattr(self, name, value))


class CameraData:
    __slots__ = ("image_height", "image_width", "image_depth", "image_data")

    def __init__(self, image_height=0, image_width=0, image_depth=0, image_data=None):
        self.image_height = image_height
        self.image_width = image_width
        self.image_depth = image_depth
        self.image_data = np.zeros(0, np.uint8) if image_data is None else image_data

    imageHeight = _alias("image_height")
    imageWidth = _alias("image_width")
    imageDepth = _alias("image_depth")
    imageData = _alias("image_data")

    def __repr__(self):
        return "CameraData(%dx%dx%d)" % (self.image_height, self.image_width, self.image_depth)


class JointData:
    __slots__ = ("position", "velocity", "effort")

    def __init__(self, position=0.0, velocity=0.0, effort=0.0):
        self.position = position
        self.velocity = velocity
        self.effort = effort

    def __repr__(self):
        return "JointData(position=%g, velocity=%g, effort=%g)" % (
            self.position, self.velocity, self.effort)


def _vec(n, value=None):
    return np.zeros(n, np.float32) if value is None else np.asarray(value, np.float32)


class LinkData:
    __slots__ = ("pos", "rot", "lin_vel", "ang_vel")

    def __init__(self, pos=None, rot=None, lin_vel=None, ang_vel=None):
        self.pos = _vec(3, pos)
        self.rot = _vec(4, rot) if rot is not None else np.array([0, 0, 0, 1], np.float32)
        self.lin_vel = _vec(3, lin_vel)
        self.ang_vel = _vec(3, ang_vel)

    position = _alias("pos")
    rotation = _alias("rot")
    linear_velocity = _alias("lin_vel")
    angular_velocity = _alias("ang_vel")

    def __repr__(self):
        return "LinkData(pos=%s, rot=%s)" % (list(self.pos), list(self.rot))


class GazeboCameraDataPack(DataPack):
    __slots__ = ()
    _type = "convoy.data.Camera"

    def __init__(self, name, engine_name):
        DataPack.__init__(self, name, engine_name)
        self._data = CameraData()


class GazeboJointDataPack(DataPack):
    __slots__ = ()
    _type = "convoy.data.Joint"

    def __init__(self, name, engine_name):
        DataPack.__init__(self, name, engine_name)
        self._data = JointData()


class GazeboLinkDataPack(DataPack):
    __slots__ = ()
    _type = "convoy.data.Link"

    def __init__(self, name, engine_name):
        DataPack.__init__(self, name, engine_name)
        self._data = LinkData()


class ProtobufDataPack(DataPack):
    """A datapack of a registered protobuf message: .data is the message (mutable in place)."""

    __slots__ = ()
    _message = None  # the message class, set on each subclass

    def __init__(self, name, engine_name):
        DataPack.__init__(self, name, engine_name)
        self._data = self._message()

    @classmethod
    def from_bytes(cls, name, engine_name, payload):
        """A datapack of the message serialized as `payload` (bytes), sent as they are: a
        function that assembles a message from serialized parts (a road user's neighbours from
        each road user's bytes) skips parsing and serializing it again. Not checked here (the
        engine reading it names the datapack if the bytes do not parse); .data parses them on
        first use."""
        if not isinstance(payload, bytes):
            raise TypeError("%s.from_bytes: payload must be bytes, not %s"
                            % (cls.__name__, type(payload).__name__))
        return _received(cls, name, engine_name, SerializedMessage(cls._message, payload))


_classes = {}  # type name -> datapack class


def _registry():
    try:
        import _convoy_datapack  # provided by the Convoy program running this Python
    except ImportError:
        return None
    return _convoy_datapack


def _module_class(type_name):
    """The class of the generated module (nrp_protobuf.dump_pb2.String) of a type compiled
    from proto/nrp_protobuf, so that TFs, engines and user code share one class."""
    file_name = _registry().proto_file(type_name)
    if not (file_name.startswith("nrp_protobuf/") and file_name.endswith(".proto")):
        return None
    module = importlib.import_module(file_name[:-len(".proto")].replace("/", ".") + "_pb2")
    from google.protobuf import descriptor_pool
    names = []
    d = descriptor_pool.Default().FindMessageTypeByName(type_name)
    while d is not None:
        names.insert(0, d.name)
        d = d.containing_type
    cls = module
    for n in names:
        cls = getattr(cls, n)
    return cls


def _message_class(type_name):
    """The Python protobuf class of a registered message, built from Convoy's descriptors."""
    cls = _module_class(type_name)
    if cls is not None:
        return cls
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    pool = descriptor_pool.Default()
    try:
        descriptor = pool.FindMessageTypeByName(type_name)
    except KeyError:
        files = descriptor_pb2.FileDescriptorSet.FromString(
            _registry().file_descriptor_set(type_name))
        for f in files.file:  # dependencies first
            try:
                pool.FindFileByName(f.name)
            except KeyError:
                pool.Add(f)
        descriptor = pool.FindMessageTypeByName(type_name)
    get_class = getattr(message_factory, "GetMessageClass", None)
    if get_class is not None:
        return get_class(descriptor)
    return message_factory.MessageFactory(pool).GetPrototype(descriptor)


def datapack_class(type_name):
    """The datapack class of a protobuf message type, by its full name ("my_pkg.RoadUser"):
    any type registered in Convoy, compiled into it, or read from a .proto file."""
    return _datapack_class(type_name)


def _datapack_class(type_name):
    cls = _classes.get(type_name)
    if cls is None:
        registry = _registry()
        if registry is None:
            raise RuntimeError("protobuf datapack type %r: no Convoy datapack registry in this "
                               "Python" % type_name)
        cls = type(registry.python_class(type_name), (ProtobufDataPack,),
                   {"__slots__": (), "_type": type_name, "_message": _message_class(type_name)})
        _classes[type_name] = cls
    return cls


class ProtobufRawData(RawData):
    """A protobuf message without an identifier (what a status function returns): .data is
    the message (mutable in place)."""

    __slots__ = ()
    _message = None  # the message class, set on each subclass

    def __init__(self, data=None):
        RawData.__init__(self, self._message() if data is None else data)


_raw_classes = {}  # type name -> RawData class


def _raw_data_class(type_name, name):
    cls = _raw_classes.get(type_name)
    if cls is None:
        cls = type(name, (ProtobufRawData,),
                   {"__slots__": (), "_type": type_name, "_message": _message_class(type_name)})
        _raw_classes[type_name] = cls
    return cls


def _nrp_message_class(name):
    """NRP-Core's <Package><Message> class (GazeboJoint is nrp_protobuf.gazebo_pb2.Joint)."""
    for package in ("Gazebo", "Dump", "EngineTest", "NrpGenericProto", "Wrappers"):
        if name.startswith(package) and len(name) > len(package):
            try:
                module = importlib.import_module("nrp_protobuf.%s_pb2" % package.lower())
            except ImportError:
                return None
            return getattr(module, name[len(package):], None)
    return None


def __getattr__(name):
    # `from nrp_core.data.nrp_protobuf import RoadUserDataPack`: any registered type's class;
    # `...RawData`: its RawData class.
    registry = _registry()
    if registry is not None:
        if name.endswith("RawData"):
            type_name = registry.raw_types().get(name[:-len("RawData")] + "DataPack")
            if type_name is not None:
                return _raw_data_class(type_name, name)
        else:
            type_name = registry.types().get(name)
            if type_name is not None:
                return _datapack_class(type_name)
    # NRP-Core's message classes: GazeboJoint, DumpString... (<Package><Message>).
    cls = None if name.endswith(("DataPack", "RawData")) else _nrp_message_class(name)
    if cls is not None:
        return cls
    raise AttributeError("module %r has no attribute %r" % (__name__, name))


def _all_names():
    names = ["GazeboCameraDataPack", "GazeboJointDataPack", "GazeboLinkDataPack", "CameraData",
             "JointData", "LinkData", "DataPackIdentifier", "ProtobufDataPack", "ProtobufRawData",
             "datapack_class"]
    registry = _registry()
    if registry is not None:  # `from nrp_core.data.nrp_protobuf import *` gives every class
        names += sorted(n for n in registry.types() if n not in names)
        names += sorted(n[:-len("DataPack")] + "RawData" for n in registry.raw_types()
                        if n.endswith("DataPack"))
    return names


__all__ = _all_names()
