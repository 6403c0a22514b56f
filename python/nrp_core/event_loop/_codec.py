"""Message types of MQTT and ROS nodes: which `type=` a decorator accepts, and how an MQTT
payload becomes the value a functional node sees, and back (NRP-Core 1.4's MqttEdgeFactory,
InputMQTTNode, OutputMQTTNode, DPInputMQTTNode and DPOutputMQTTNode).

MQTT `type` can be:
  str                                   payload as text
  nrp_core.data.nrp_json.NlohmannJson   payload parsed as JSON (the node sees a dict/list...)
  a protobuf message class              payload is the serialized message
  a datapack class (JsonDataPack, DumpStringDataPack, GazeboJointDataPack...), found by
  instantiating type("dpname", "enginename") as NRP-Core does:
    JSON data     -> {"name", "engine_name", "type", "data"} (name, engine_name, data required)
    protobuf data -> EngineGrpc.DataPackMessage {dataPackId, data: Any}
"""
import importlib
import json
import logging

from nrp_core._datapacks import DataPack, JsonDataPack

from ._policies import ComputationalGraphError

# What NRP-Core 1.4 puts in a JSON datapack's "type": typeid(nlohmann::json).name() as GCC
# mangles nlohmann-json 3.11 (Debian bookworm's). Receivers check name/engine_name/data only;
# NRP-Core's async python_json engine compares "type" with JsonDataPack.getType(), so Convoy's
# engines must use this constant.
JSON_DATAPACK_TYPE = ("N8nlohmann16json_abi_v3_11_210basic_jsonISt3mapSt6vectorNSt7__cxx1112"
                      "basic_stringIcSt11char_traitsIcESaIcEEEblmdSaNS0_14adl_serializerES3_"
                      "IhSaIhEEvEE")

_log = logging.getLogger("nrp_core.event_loop")


def _is_proto_class(t):
    try:
        from google.protobuf.message import Message
    except ImportError:
        return False
    return isinstance(t, type) and issubclass(t, Message)


def _is_json_class(t):
    return t is dict or (getattr(t, "__name__", "") == "NlohmannJson" and
                         getattr(t, "__module__", "").startswith("nrp_core.data.nrp_json"))


class Codec:
    """Turns payloads (bytes) into values and back for one node's type."""

    def __init__(self, kind, msg_type, message_class=None, adapter=None):
        self.kind = kind  # "str", "json", "proto", "json_datapack", "proto_datapack"
        self.msg_type = msg_type
        self.message_class = message_class
        self.adapter = adapter  # (to_message, from_message) for Convoy's Gazebo data classes

    def decode(self, payload):
        if isinstance(payload, str):
            payload = payload.encode("utf-8")
        return getattr(self, "_decode_" + self.kind)(payload)

    def encode(self, value):
        """The payload of `value`, or None if nothing is to be sent (an empty datapack)."""
        return getattr(self, "_encode_" + self.kind)(value)

    def _decode_str(self, payload):
        return payload.decode("utf-8", "replace")

    def _encode_str(self, value):
        if isinstance(value, bytes):
            return value
        if not isinstance(value, str):
            raise TypeError("expected a str, got %s" % type(value).__name__)
        return value.encode("utf-8")

    def _decode_json(self, payload):
        try:
            return json.loads(payload)
        except ValueError as e:
            raise ComputationalGraphError("Error in InputMQTTNode while converting incoming msg "
                                          "into json format: %s" % e) from None

    def _encode_json(self, value):
        if isinstance(value, (bytes, str)):
            return value if isinstance(value, bytes) else value.encode("utf-8")
        return json.dumps(value).encode("utf-8")

    def _decode_proto(self, payload):
        try:
            return self.msg_type.FromString(payload)
        except Exception:
            raise ComputationalGraphError("Error in InputMQTTNode while converting incoming msg "
                                          "into protobuf format") from None

    def _encode_proto(self, value):
        return value.SerializeToString()

    def _decode_json_datapack(self, payload):
        try:
            dp = json.loads(payload)
        except ValueError as e:
            raise ComputationalGraphError("Error in InputMQTTNode while converting incoming msg "
                                          "into json datapack format: %s" % e) from None
        if not isinstance(dp, dict) or "name" not in dp or "engine_name" not in dp:
            raise ComputationalGraphError('malformed json datapack received: "%s". It must '
                                          "contain keys name and engine_name"
                                          % payload.decode("utf-8", "replace"))
        if "data" not in dp:
            raise ComputationalGraphError("empty datapack received. This is not allowed")
        out = self.msg_type(dp["name"], dp["engine_name"])
        out.data = dp["data"]
        return out

    def _encode_json_datapack(self, value):
        if _empty(value):
            return None
        return json.dumps({"name": value.name, "engine_name": value.engine_name,
                           "type": JSON_DATAPACK_TYPE, "data": value.data}).encode("utf-8")

    def _decode_proto_datapack(self, payload):
        envelope = _datapack_message_class()
        try:
            m = envelope.FromString(payload)
        except Exception:
            raise ComputationalGraphError("Error in DPInputMQTTNode while converting incoming msg "
                                          "into EngineGrpc::DataPackMessage protobuf message") \
                from None
        if not m.HasField("data"):
            raise ComputationalGraphError("Error in DPInputMQTTNode. Received empty DataPack")
        if not m.HasField("dataPackId"):
            raise ComputationalGraphError("Error in DPInputMQTTNode. Received DataPack without id")
        message_class = self.message_class()
        if not m.data.Is(message_class.DESCRIPTOR):
            raise ComputationalGraphError("Error in DPInputMQTTNode while converting incoming msg "
                                          "into DataPack. Wrong msg type")
        msg = message_class()
        m.data.Unpack(msg)
        out = self.msg_type(m.dataPackId.dataPackName, m.dataPackId.engineName)
        out.data = self.adapter[1](msg) if self.adapter else msg
        return out

    def _encode_proto_datapack(self, value):
        if _empty(value):
            return None
        msg = self.adapter[0](value.data, self.message_class()()) if self.adapter else value.data
        m = _datapack_message_class()()
        m.dataPackId.dataPackName = value.name
        m.dataPackId.engineName = value.engine_name
        m.dataPackId.dataPackType = msg.DESCRIPTOR.full_name
        m.data.Pack(msg)
        return m.SerializeToString()


def _empty(value):
    if value is None or not isinstance(value, DataPack):
        raise TypeError("expected a datapack, got %s" % type(value).__name__)
    if value.isEmpty():
        _log.warning('Received null or empty datapack "%s"; it is not published', value.name)
        return True
    return False


def mqtt_codec(msg_type, address, is_input):
    """The codec of an MQTTSubscriber/MQTTPublisher `type`; raises ComputationalGraphError with
    NRP-Core's message for a type it does not support."""
    decorator = ('MQTTSubscriber decorator "' if is_input else 'MQTTPublisher decorator "') + \
        address
    if msg_type is str:
        return Codec("str", msg_type)
    if _is_json_class(msg_type):
        return Codec("json", msg_type)
    if _is_proto_class(msg_type):
        return Codec("proto", msg_type)
    if isinstance(msg_type, type) and issubclass(msg_type, DataPack):
        return _datapack_codec(msg_type, decorator)
    raise ComputationalGraphError(
        'Error occurred while processing %s". MQTT node type must be either "str", '
        '"nrp_core.data.nrp_json.NlohmannJson" or an "nrp_core.data.nrp_protobuf" class.'
        % decorator)


def _datapack_codec(msg_type, decorator):
    sample = msg_type("dpname", "enginename")
    data = sample._data
    if isinstance(sample, JsonDataPack) or isinstance(data, (dict, list)):
        return Codec("json_datapack", msg_type)
    if _is_proto_class(type(data)):
        cls = type(data)
        return Codec("proto_datapack", msg_type, lambda: cls)
    adapter = _GAZEBO_ADAPTERS.get(type(data).__name__)
    if adapter is not None:
        name, to_message, from_message = adapter
        return Codec("proto_datapack", msg_type, lambda: _gazebo_class(name, decorator),
                     (to_message, lambda m: from_message(m, type(data))))
    raise ComputationalGraphError('Error occurred while processing %s". Protobuf message type: '
                                  '"%s.%s" is not supported.'
                                  % (decorator, msg_type.__module__, msg_type.__name__))


def _datapack_message_class():
    """EngineGrpc.DataPackMessage: Convoy's generated module, else built from its layout."""
    global _envelope
    if _envelope is None:
        try:
            _envelope = importlib.import_module("nrp_protobuf.engine_grpc_pb2").DataPackMessage
        except ImportError:
            _envelope = _build_envelope()
    return _envelope


_envelope = None


def _build_envelope():
    from google.protobuf import any_pb2, descriptor_pb2, descriptor_pool, message_factory
    pool = descriptor_pool.DescriptorPool()
    any_file = descriptor_pb2.FileDescriptorProto()
    any_pb2.DESCRIPTOR.CopyToProto(any_file)
    pool.Add(any_file)
    f = descriptor_pb2.FileDescriptorProto(name="convoy_event_loop/engine_grpc.proto",
                                           package="EngineGrpc", syntax="proto3",
                                           dependency=["google/protobuf/any.proto"])
    ident = f.message_type.add(name="DataPackIdentifier")
    for number, field in enumerate(("dataPackName", "dataPackType", "engineName"), 1):
        ident.field.add(name=field, number=number, type=9, label=1)  # string, optional
    msg = f.message_type.add(name="DataPackMessage")
    msg.field.add(name="dataPackId", number=1, type=11, label=1,
                  type_name=".EngineGrpc.DataPackIdentifier")
    msg.field.add(name="data", number=2, type=11, label=1, type_name=".google.protobuf.Any")
    pool.Add(f)
    descriptor = pool.FindMessageTypeByName("EngineGrpc.DataPackMessage")
    get_class = getattr(message_factory, "GetMessageClass", None)
    if get_class is not None:
        return get_class(descriptor)
    return message_factory.MessageFactory(pool).GetPrototype(descriptor)


def _gazebo_class(name, decorator):
    """Gazebo.<name>: nrp_core.data.nrp_protobuf's Gazebo<name> (NRP-Core's name), else
    Convoy's generated nrp_protobuf.gazebo_pb2."""
    try:
        return getattr(importlib.import_module("nrp_core.data.nrp_protobuf"), "Gazebo" + name)
    except (AttributeError, ImportError, RuntimeError):
        pass
    try:
        return getattr(importlib.import_module("nrp_protobuf.gazebo_pb2"), name)
    except (AttributeError, ImportError):
        raise ComputationalGraphError('%s": the Gazebo.%s protobuf message is not available '
                                      "(nrp_protobuf.gazebo_pb2 is built with Convoy)"
                                      % (decorator, name)) from None


def _joint_to(d, m):
    m.position, m.velocity, m.effort = float(d.position), float(d.velocity), float(d.effort)
    return m


def _joint_from(m, cls):
    return cls(m.position, m.velocity, m.effort)


def _link_to(d, m):
    for field, attr in (("position", "pos"), ("rotation", "rot"), ("linearVelocity", "lin_vel"),
                        ("angularVelocity", "ang_vel")):
        getattr(m, field).extend(float(x) for x in getattr(d, attr))
    return m


def _link_from(m, cls):
    return cls(list(m.position), list(m.rotation), list(m.linearVelocity),
               list(m.angularVelocity))


def _camera_to(d, m):
    m.imageWidth, m.imageHeight, m.imageDepth = d.image_width, d.image_height, d.image_depth
    m.imageData = bytes(memoryview(d.image_data))
    return m


def _camera_from(m, cls):
    import numpy as np
    return cls(m.imageHeight, m.imageWidth, m.imageDepth, np.frombuffer(m.imageData, np.uint8))


# Convoy's Gazebo datapack data classes (nrp_core.data.nrp_protobuf) and their messages.
_GAZEBO_ADAPTERS = {"JointData": ("Joint", _joint_to, _joint_from),
                    "LinkData": ("Link", _link_to, _link_from),
                    "CameraData": ("Camera", _camera_to, _camera_from)}


def check_ros_type(msg_type, address, is_input):
    """RosSubscriber/RosPublisher `type`: an nrp_core.data.nrp_ros class (NRP-Core), or a
    rospy message class (Convoy)."""
    module = getattr(msg_type, "__module__", "") or ""
    rospy_class = isinstance(msg_type, type) and hasattr(msg_type, "_md5sum") and \
        hasattr(msg_type, "_type")
    if not (module.startswith("nrp_core.data.nrp_ros") or rospy_class):
        raise ComputationalGraphError(
            'Error occurred while processing %s decorator "%s". ROS message type must be an '
            '"nrp_core.data.nrp_ros" class.' % ("RosSubscriber" if is_input else "RosPublisher",
                                                address))
    return msg_type
