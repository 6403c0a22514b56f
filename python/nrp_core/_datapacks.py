"""Datapack value classes seen by transceiver functions and engine scripts."""


class DataPackIdentifier:
    """Identifies a datapack: its name, the engine it belongs to, and its type."""

    __slots__ = ("dataPackName", "engineName", "dataPackType")

    def __init__(self, name, engine_name, type=""):
        self.dataPackName = name
        self.engineName = engine_name
        self.dataPackType = type

    # Convenience aliases.
    name = property(lambda self: self.dataPackName)
    engine_name = property(lambda self: self.engineName)

    def __eq__(self, other):
        return (isinstance(other, DataPackIdentifier) and self.dataPackName == other.dataPackName
                and self.engineName == other.engineName)

    def __hash__(self):
        return hash((self.dataPackName, self.engineName))

    def __repr__(self):
        return "DataPackIdentifier(%r, %r)" % (self.dataPackName, self.engineName)


class EmptyDataPackError(RuntimeError):
    pass


class DataPack:
    """Base of all datapacks: an identifier and, unless empty, data."""

    __slots__ = ("_id", "_data", "_updated")
    _type = ""

    def __init__(self, name, engine_name):
        self._id = DataPackIdentifier(name, engine_name, self._type)
        self._data = None

    @property
    def id(self):
        return self._id

    @property
    def name(self):
        return self._id.dataPackName

    @property
    def engine_name(self):
        return self._id.engineName

    def isEmpty(self):
        return self._data is None

    def isUpdated(self):
        # False for a datapack kept from an earlier cycle: its engine did not send it again
        # (a camera between two frames), as NRP-Core's DataPack.isUpdated().
        return self._data is not None and getattr(self, "_updated", True)

    @property
    def data(self):
        if self._data is None:
            raise EmptyDataPackError("datapack '%s' of engine '%s' is empty: check isEmpty() first"
                                     % (self._id.dataPackName, self._id.engineName))
        if type(self._data) is SerializedMessage:
            self._data = self._data.parse()
        return self._data

    @data.setter
    def data(self, value):
        self._data = value

    def __repr__(self):
        return "%s(%r, %r%s)" % (type(self).__name__, self.name, self.engine_name,
                                 ", empty" if self._data is None else "")


class SerializedMessage:
    """A protobuf message still in its serialized form (ProtobufDataPack.from_bytes): sent as
    the bytes it is, parsed only when a function reads the datapack's .data."""

    __slots__ = ("message_class", "payload")

    def __init__(self, message_class, payload):
        self.message_class = message_class
        self.payload = payload

    def parse(self):
        return self.message_class.FromString(self.payload)


def _received(cls, name, engine_name, data):
    """A datapack of class `cls` holding an engine's `data`, as Convoy hands it to a function:
    DataPack.__init__'s fields without the class's default data, which `data` replaces."""
    dp = object.__new__(cls)
    dp._id = DataPackIdentifier(name, engine_name, cls._type)
    dp._data = data
    return dp


class JsonDataPack(DataPack):
    """A datapack whose data is a JSON value (a dict, usually). numpy arrays are allowed
    inside and travel as binary blobs."""

    __slots__ = ()
    _type = "json"

    def __init__(self, name, engine_name, data=None):
        DataPack.__init__(self, name, engine_name)
        self._data = {} if data is None else data


class EmptyDataPack(DataPack):
    """A datapack that carries no data (not produced yet, or unknown to its engine)."""

    __slots__ = ()

    def __init__(self, name, engine_name, type=""):
        DataPack.__init__(self, name, engine_name)
        self._id.dataPackType = type


class RawData:
    """Data without an identifier, as NRP-Core's *RawData classes: what a status function
    returns to the client. `.data` is a JSON value (JsonRawData) or a protobuf message
    (the <Package><Message>RawData classes of nrp_core.data.nrp_protobuf)."""

    __slots__ = ("_data",)
    _type = ""

    def __init__(self, data=None):
        self._data = data

    @property
    def data(self):
        return self._data

    @data.setter
    def data(self, value):
        self._data = value

    def __repr__(self):
        return "%s(%r)" % (type(self).__name__, self._data)


class JsonRawData(RawData):
    """JSON data without an identifier (a dict by default)."""

    __slots__ = ()
    _type = "json"

    def __init__(self, data=None):
        RawData.__init__(self, {} if data is None else data)
