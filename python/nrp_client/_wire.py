"""The client's requests as protobuf bytes without building their messages (nrp_server.proto):
the datapacks a step sends are a few fixed identifiers and type URLs around each payload's
bytes, so they are joined from cached pieces. The bytes parse as the messages that
RunLoopMessage(...) with the same datapacks serializes to (the same fields in the same order;
tested in tests/unit/test_nrp_client_wire.py), at a fraction of their cost per step."""
from nrp_client import nrp_server_pb2 as _pb

TYPE_URL_PREFIX = "type.googleapis.com/"
# (field number << 3) | wire type 2 (length-delimited), and 0 (varint)
_ID, _DATA = b"\x0a", b"\x12"                # DataPackMessage.dataPackId, .data
_URL, _VALUE = b"\x0a", b"\x12"              # Any.type_url, Any.value
_JSON_DATAPACKS, _PROTO_DATAPACKS = b"\x12", b"\x1a"  # DataPacks.jsonDataPacks, .protoDataPacks
_ITERATIONS, _RUN_DATAPACKS = b"\x08", b"\x12"  # RunLoopMessage.numIterations, .dataPacks

_heads = {}  # (datapack name, engine name, type URL) -> the DataPackMessage's fixed part


def varint(n):
    """A protobuf varint (an int32's negative values as 10 bytes, as protobuf writes them)."""
    if n < 0:
        n += 1 << 64
    if n < 0x80:
        return bytes((n,))
    out = bytearray()
    while n >= 0x80:
        out.append((n & 0x7F) | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


_ONE_BYTE = tuple(bytes((n,)) for n in range(0x80))  # the varints of 0 to 127


def field(tag, data):
    """A length-delimited field: its tag, the length, the bytes."""
    n = len(data)
    return tag + (_ONE_BYTE[n] if n < 0x80 else varint(n)) + data


def datapack(name, engine, type_name, value):
    """A DataPackMessage's bytes: identifier (name, engine), data = Any(type, value)."""
    key = (name, engine, type_name)
    head = _heads.get(key)
    if head is None:
        ident = _pb.DataPackIdentifier(dataPackName=name, engineName=engine)
        head = _heads[key] = (field(_ID, ident.SerializeToString()),
                              field(_URL, (TYPE_URL_PREFIX + type_name).encode()))
    ident, url = head
    return ident + field(_DATA, url + field(_VALUE, value) if value else url)


def datapacks(json_datapacks, proto_datapacks):
    """A DataPacks message's bytes from DataPackMessages' bytes."""
    return (b"".join(field(_JSON_DATAPACKS, d) for d in json_datapacks) +
            b"".join(field(_PROTO_DATAPACKS, d) for d in proto_datapacks))


def run_loop_message(num_iterations, datapacks_bytes):
    """A RunLoopMessage's bytes."""
    out = _ITERATIONS + varint(num_iterations) if num_iterations else b""
    return out + field(_RUN_DATAPACKS, datapacks_bytes) if datapacks_bytes else out
