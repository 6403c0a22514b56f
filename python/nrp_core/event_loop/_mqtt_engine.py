"""NRP-Core 1.4's asynchronous Python engines (async_python_json_engine.py,
async_python_grpc_engine.py): an EngineScript run in real time by its own event loop, its
datapacks exchanged over MQTT.

    async_python_json_engine.py --config=engine.json [--loglevel=info]

engine.json (NRP-Core's event_loop.json#/event_loop_engine):
    Timestep (0.01 s), Timeout (0: until SIGINT/SIGTERM), TimestepWarnThreshold (0.001 s),
    EngineConfig {EngineName, PythonFileName, ...: the script's _config},
    MQTTConfig {MQTTBroker, ClientName (default: EngineName)}, ProcessLastMsg (true),
    DataQueueSize (1); the grpc variant also ProtobufPackages.

Each cycle: the datapacks received on "<EngineName>/set/<datapack>" since the last cycle are
set (the last one of each with ProcessLastMsg, else all in order; at most DataQueueSize kept
per cycle), the script's time advances by Timestep and runLoop(timestep_ns) runs, then every
registered datapack is published on "<EngineName>/get/<datapack>" (QoS 1):
    json: {"name", "engine_name", "type", "data"}   grpc: an EngineGrpc.DataPackMessage.
The broker is MQTTConfig.MQTTBroker, else $CONVOY_MQTT_BROKER (set by the coordinator to its
MQTTNode.MQTTBroker), else localhost:1883. A bad config: one message naming the file and the
field, exit 2; no broker: exit 2.
"""
import argparse
import importlib.util
import json
import logging
import os
import signal
import sys
import threading

from ._codec import JSON_DATAPACK_TYPE
from ._loop import EventLoopInterface
from ._mqtt import DEFAULT_BROKER, MqttConnection, MqttError, parse_broker

LOG_LEVELS = {"critical": logging.CRITICAL, "fatal": logging.FATAL, "error": logging.ERROR,
              "warning": logging.WARNING, "warn": logging.WARN, "info": logging.INFO,
              "debug": logging.DEBUG, "notset": logging.NOTSET}
PROTOBUF_PACKAGES = ("Dump", "EngineTest", "Gazebo", "NrpGenericProto", "Wrappers")
_KNOWN_KEYS = ("Timestep", "Timeout", "TimestepWarnThreshold", "EngineConfig", "MQTTConfig",
               "ProcessLastMsg", "DataQueueSize", "$schema")

_log = logging.getLogger("nrp_core.async_engine")


class ConfigError(ValueError):
    pass


def _number(config, key, default, minimum, strict):
    value = config.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            (value <= minimum if strict else value < minimum):
        raise ConfigError("/%s: must be a number %s %g, got %s"
                          % (key, ">" if strict else ">=", minimum, json.dumps(value)))
    return float(value)


def _string(obj, key, pointer, default=None):
    value = obj.get(key, default)
    if not isinstance(value, str) or not value.strip():
        raise ConfigError("%s/%s: %s" % (pointer, key, "is required" if key not in obj else
                                         "must be a non-empty string, got " + json.dumps(value)))
    return value


def read_config(path, kind):
    """The validated config (defaults filled); ConfigError("FILE: /pointer: what")."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ConfigError("%s: cannot read: %s" % (path, e.strerror or e)) from None
    try:
        config = json.loads(text)
    except ValueError as e:
        raise ConfigError("%s: not valid JSON: %s" % (path, e)) from None
    try:
        return _validate(config, kind, os.path.dirname(os.path.abspath(path)))
    except ConfigError as e:
        raise ConfigError("%s: %s" % (path, e)) from None


def _validate(config, kind, config_dir):
    if not isinstance(config, dict):
        raise ConfigError("the config must be a JSON object")
    for key in config:
        if key not in _KNOWN_KEYS:
            _log.warning("/%s: unknown key (ignored)", key)
    out = {"Timestep": _number(config, "Timestep", 0.01, 0, True),
           "Timeout": _number(config, "Timeout", 0, 0, False),
           "TimestepWarnThreshold": _number(config, "TimestepWarnThreshold", 0.001, 0, False)}
    queue = config.get("DataQueueSize", 1)
    if isinstance(queue, bool) or not isinstance(queue, int) or queue < 1:
        raise ConfigError("/DataQueueSize: must be an integer >= 1, got %s" % json.dumps(queue))
    out["DataQueueSize"] = queue
    last = config.get("ProcessLastMsg", True)
    if not isinstance(last, bool):
        raise ConfigError("/ProcessLastMsg: must be true or false, got %s" % json.dumps(last))
    out["ProcessLastMsg"] = last
    engine = config.get("EngineConfig")
    if not isinstance(engine, dict):
        raise ConfigError("/EngineConfig: " + ("is required" if engine is None else
                                               "must be an object"))
    engine = dict(engine)
    _string(engine, "EngineName", "/EngineConfig")
    script = _string(engine, "PythonFileName", "/EngineConfig")
    found = [p for p in (script, os.path.join(config_dir, script)) if os.path.isfile(p)]
    if not found:
        raise ConfigError("/EngineConfig/PythonFileName: no file \"%s\"" % script)
    engine["PythonFileName"] = os.path.abspath(found[0])
    if kind == "grpc":
        packages = engine.setdefault("ProtobufPackages", ["EngineTest"])
        if not isinstance(packages, list) or not all(p in PROTOBUF_PACKAGES for p in packages):
            raise ConfigError("/EngineConfig/ProtobufPackages: must be a list of %s, got %s"
                              % (", ".join(PROTOBUF_PACKAGES), json.dumps(packages)))
    out["EngineConfig"] = engine
    mqtt = config.get("MQTTConfig", {})
    if not isinstance(mqtt, dict):
        raise ConfigError("/MQTTConfig: must be an object")
    broker = mqtt.get("MQTTBroker") or os.environ.get("CONVOY_MQTT_BROKER") or DEFAULT_BROKER
    if "MQTTBroker" in mqtt:
        _string(mqtt, "MQTTBroker", "/MQTTConfig")
    try:
        parse_broker(broker)
    except ValueError as e:
        raise ConfigError("/MQTTConfig/MQTTBroker: %s" % e) from None
    out["MQTTConfig"] = {"MQTTBroker": broker,
                         "ClientName": _string(mqtt, "ClientName", "/MQTTConfig",
                                               engine["EngineName"])}
    return out


def _load_script(path, base):
    """The script's Script class (a subclass of `base`; the grpc engine also takes the only
    subclass when none is named Script)."""
    name = "_nrp_engine_script_" + os.path.splitext(os.path.basename(path))[0]
    sys.path.insert(0, os.path.dirname(path))
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cls = getattr(module, "Script", None)
    if cls is None:
        found = [v for v in vars(module).values()
                 if isinstance(v, type) and issubclass(v, base) and v is not base]
        cls = found[0] if len(found) == 1 else None
    if not (isinstance(cls, type) and issubclass(cls, base)):
        raise ConfigError("%s: class Script must inherit from %s" % (path, base.__name__))
    return cls


class AsyncEngine(EventLoopInterface):
    """The engine's event loop: script + MQTT client."""

    def __init__(self, config, codec):
        EventLoopInterface.__init__(self, config["Timestep"], config["TimestepWarnThreshold"])
        self.config = config
        self.codec = codec
        self.engine = config["EngineConfig"]
        self.name = self.engine["EngineName"]
        self.timestep_ns = int(round(config["Timestep"] * 1e9))
        self.script = None
        self.client = None
        self._store = {}
        self._store_lock = threading.Lock()

    def _initialize_cb(self):
        cls = _load_script(self.engine["PythonFileName"], self.codec.base)
        mqtt = self.config["MQTTConfig"]
        self.client = MqttConnection(mqtt["MQTTBroker"], mqtt["ClientName"])
        self.script = cls()
        self.script._name = self.name
        self.script._config = self.engine
        self.script.initialize()
        for dp in self.script._datapacks:
            self._store[dp] = []
            topic = "%s/set/%s" % (self.name, dp)
            _log.info("Subscribing to topic: %s", topic)
            self.client.subscribe(topic, lambda payload, dp=dp: self._on_message(dp, payload))

    def _on_message(self, dp, payload):
        with self._store_lock:
            queue = self._store[dp]
            if len(queue) >= self.config["DataQueueSize"]:
                _log.debug("Received datapack %s but queue is full, it will be discarded", dp)
                return
        value = self.codec.decode(self.name, dp, payload)
        if value is not None:
            with self._store_lock:
                queue.append(value)

    def _run_loop_cb(self):
        with self._store_lock:
            received = {dp: q[:] for dp, q in self._store.items() if q}
            for q in self._store.values():
                q.clear()
        for dp, values in received.items():
            for value in values[-1:] if self.config["ProcessLastMsg"] else values:
                self.codec.apply(self.script, dp, value)
        self.script._advanceTime(self.timestep_ns)
        self.script.runLoop(self.timestep_ns)
        if self.client.connected:
            for dp in list(self.script._datapacks):
                self.client.publish("%s/get/%s" % (self.name, dp),
                                    self.codec.encode(self.script, dp))

    def _shutdown_cb(self):
        try:
            if self.script is not None:
                self.script.shutdown()
        finally:
            if self.client is not None:
                self.client.close()


class JsonCodec:
    @property
    def base(self):
        from nrp_core.engines.python_json import EngineScript
        return EngineScript

    def encode(self, script, dp):
        return json.dumps({"name": dp, "engine_name": script._name, "type": JSON_DATAPACK_TYPE,
                           "data": script._getDataPack(dp)}).encode("utf-8")

    def decode(self, engine, dp, payload):
        try:
            m = json.loads(payload)
        except ValueError as e:
            _log.warning("Received datapack %s couldn't be unpacked: %s", dp, e)
            return None
        if not isinstance(m, dict) or "data" not in m:
            _log.warning("Received datapack %s is not a datapack object with \"data\"", dp)
            return None
        return m["data"]

    def apply(self, script, dp, data):
        script._setDataPack(dp, data)


class GrpcCodec:
    def __init__(self):
        from nrp_protobuf.engine_grpc_pb2 import DataPackMessage
        self.envelope = DataPackMessage

    @property
    def base(self):
        from nrp_core.engines.python_grpc import GrpcEngineScript
        return GrpcEngineScript

    def encode(self, script, dp):
        msg = script._getDataPack(dp)
        m = self.envelope()
        m.dataPackId.dataPackName = dp
        m.dataPackId.engineName = script._name
        m.dataPackId.dataPackType = msg.DESCRIPTOR.full_name
        m.data.Pack(msg)
        return m.SerializeToString()

    def decode(self, engine, dp, payload):
        m = self.envelope()
        try:
            m.ParseFromString(payload)
        except Exception:
            _log.warning("Received datapack %s couldn't be unpacked", dp)
            return None
        if m.dataPackId.dataPackName != dp:
            _log.warning("Received datapack %s in the wrong topic %s",
                         m.dataPackId.dataPackName, dp)
            return None
        return m

    def apply(self, script, dp, m):
        cls = script._datapack_types[dp]
        msg = cls()
        if not m.data.Unpack(msg):
            _log.warning("Received datapack %s of type %s, registered as %s", dp,
                         m.data.TypeName(), cls.DESCRIPTOR.full_name)
            return
        script._setDataPack(dp, msg)


def main(kind, argv=None):
    """The command (kind "json" or "grpc"); returns the exit code."""
    prog = "async_python_%s_engine.py" % kind
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("--config", required=True)
    parser.add_argument("--loglevel", default="info", type=str.lower, choices=LOG_LEVELS)
    args = parser.parse_args(argv)
    logging.basicConfig(level=LOG_LEVELS[args.loglevel], stream=sys.stderr,
                        format="[%(asctime)s] [" + prog + "] [%(levelname)s] %(message)s")
    try:
        config = read_config(args.config, kind)
    except ConfigError as e:
        print("error: %s: %s" % (prog, e), file=sys.stderr)
        return 2
    name = config["EngineConfig"]["EngineName"]
    for handler in logging.getLogger().handlers:
        handler.setFormatter(logging.Formatter("[%(asctime)s] [" + name +
                                               "] [%(levelname)s] %(message)s"))
    engine = AsyncEngine(config, GrpcCodec() if kind == "grpc" else JsonCodec())

    def on_signal(signum, frame):
        _log.info("Received stop signal")
        engine.stop_loop()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        engine.initialize()
    except MqttError as e:
        print("error: %s: %s: /MQTTConfig/MQTTBroker: %s" % (prog, args.config, e),
              file=sys.stderr)
        return 2
    except ConfigError as e:
        print("error: %s: %s" % (prog, e), file=sys.stderr)
        return 2
    except Exception:
        _log.exception("engine %s failed to initialize", name)
        try:
            engine._shutdown_cb()
        except Exception:
            pass
        return 1
    code = 0
    try:
        engine.run_loop(config["Timeout"])
    except Exception:
        _log.exception("engine %s failed", name)
        code = 1
    finally:
        engine.shutdown()
    return code
