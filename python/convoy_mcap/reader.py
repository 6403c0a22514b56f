"""MCAP reading and checking (see __init__.py)."""
import base64
import json
import math
import struct
import warnings
import zlib
from collections import namedtuple

MAGIC = b"\x89MCAP0\r\n"
OP = {0x01: "Header", 0x02: "Footer", 0x03: "Schema", 0x04: "Channel", 0x05: "Message",
      0x06: "Chunk", 0x07: "MessageIndex", 0x08: "ChunkIndex", 0x09: "Attachment",
      0x0A: "AttachmentIndex", 0x0B: "Statistics", 0x0C: "Metadata", 0x0D: "MetadataIndex",
      0x0E: "SummaryOffset", 0x0F: "DataEnd"}

Schema = namedtuple("Schema", "id name encoding data")
Channel = namedtuple("Channel", "id schema_id topic message_encoding metadata")
Message = namedtuple("Message", "topic channel sequence log_time publish_time encoding "
                                "schema_name data value")


class McapError(Exception):
    """A malformed file; the message names the file and the byte offset."""


class McapIncompleteWarning(UserWarning):
    """A file cut short (a killed writer, a full disk): read up to its last whole record."""


class _Fields:
    def __init__(self, buf, where):
        self.buf, self.p, self.where = buf, 0, where

    def _take(self, n):
        if self.p + n > len(self.buf):
            raise McapError("%s: record cut short" % self.where)
        out = self.buf[self.p:self.p + n]
        self.p += n
        return out

    def u8(self):
        return self._take(1)[0]

    def u16(self):
        return struct.unpack("<H", self._take(2))[0]

    def u32(self):
        return struct.unpack("<I", self._take(4))[0]

    def u64(self):
        return struct.unpack("<Q", self._take(8))[0]

    def string(self):
        return bytes(self._take(self.u32())).decode("utf-8")

    def bytes32(self):
        return bytes(self._take(self.u32()))

    def bytes64(self):
        return self._take(self.u64())

    def map(self, key, value):
        inner = _Fields(self._take(self.u32()), self.where)
        out = {}
        while inner.p < len(inner.buf):
            k = key(inner)
            out[k] = value(inner)
        return out

    def rest(self):
        return bytes(self.buf[self.p:])


def _zstd_decompress(data, size, fail):
    """A zstd chunk's records (Convoy writes them so; Debian's python3-zstandard reads them)."""
    try:
        import zstandard
    except ImportError:
        fail("zstd chunk: install python3-zstandard to read it")
    try:
        return zstandard.ZstdDecompressor().decompress(bytes(data), max_output_size=size)
    except zstandard.ZstdError as e:
        fail("zstd chunk does not decompress: %s" % e)


class _CutShort(Exception):
    """The file ends inside a record of the data section (at byte `at`)."""

    def __init__(self, what, at):
        super().__init__(what)
        self.what, self.at = what, at


def _records(buf, start, end, where, file_end=False):
    """(opcode, offset, content) of the records in buf[start:end]. A record running past the
    end is malformed, or, with `file_end` (the end of the file), the file is cut short."""
    p = start
    while p < end:
        if p + 9 > end:
            what = "%s: record header cut short at byte %d" % (where, p)
            raise _CutShort(what, p) if file_end else McapError(what)
        op = buf[p]
        (n,) = struct.unpack_from("<Q", buf, p + 1)
        if p + 9 + n > end:
            what = "%s: record %s of %d bytes at byte %d runs past the end" % (
                where, OP.get(op, hex(op)), n, p)
            raise _CutShort(what, p) if file_end else McapError(what)
        yield op, p, buf[p + 9:p + 9 + n]
        p += 9 + n


class Recording:
    """An MCAP file read whole and checked: magic, every record's framing, the chunks', data
    section's and summary's CRCs, the chunk indexes and message indexes (when present).

    A file cut short (a killed writer, a full disk) is read up to its last whole record of the
    data section, so every whole chunk's messages: `complete` is False, `incomplete` says why
    and where, and a McapIncompleteWarning is issued. A file without its whole Header is not
    read (McapError)."""

    def __init__(self, path):
        self.path = str(path)
        with open(path, "rb") as f:
            self.buf = memoryview(f.read())
        self.schemas, self.channels, self.metadata = {}, {}, {}
        self.records = {}  # opcode name -> count (data section, chunk contents included)
        self.chunk_indexes, self.statistics, self.summary_offsets = [], None, []
        self.complete = False
        self.incomplete = ""
        self.profile = self.library = ""
        self._messages = []  # (offset in buf of the record content)
        try:
            self._check()
        except _CutShort as e:
            if self.library is None:
                self._fail("Header record cut short", 8)
            self.incomplete = "it is cut short at byte %d (a record starting at byte %d)" % (
                len(self.buf), e.at)
        if not self.complete:
            warnings.warn("%s: incomplete recording: %s; read its %d messages up to there"
                          % (self.path, self.incomplete, len(self._messages)),
                          McapIncompleteWarning, stacklevel=2)

    def _fail(self, what, offset):
        raise McapError("%s: %s (at byte %d)" % (self.path, what, offset))

    def _count(self, op):
        name = OP.get(op, hex(op))
        self.records[name] = self.records.get(name, 0) + 1

    def _parse(self, op, body, offset):
        f = _Fields(body, "%s at byte %d" % (self.path, offset))
        if op == 0x03:
            s = Schema(f.u16(), f.string(), f.string(), f.bytes32())
            if s.id:
                self.schemas[s.id] = s
        elif op == 0x04:
            c = Channel(f.u16(), f.u16(), f.string(), f.string(),
                        f.map(_Fields.string, _Fields.string))
            if c.schema_id and c.schema_id not in self.schemas:
                self._fail("channel %r names an undefined schema %d" % (c.topic, c.schema_id), offset)
            self.channels[c.id] = c
        elif op == 0x05:
            cid = f.u16()
            if cid not in self.channels:
                self._fail("message on undefined channel %d" % cid, offset)
            self._messages.append(body)
        elif op == 0x0C:
            name = f.string()
            self.metadata[name] = f.map(_Fields.string, _Fields.string)

    def _check(self):
        buf = self.buf
        if bytes(buf[:8]) != MAGIC:
            self._fail("not an MCAP file (no magic)", 0)
        p = 8
        data_end = None
        self.library = None  # until the Header is read
        chunks = {}  # offset -> (length, {channel: [(time, offset)]})
        for op, off, body in _records(buf, 8, len(buf), self.path, file_end=True):
            if off == 8:
                if op != 0x01:
                    self._fail("no Header after the magic", 8)
                f = _Fields(body, self.path)
                self.profile, self.library = f.string(), f.string()
                self._count(op)
                p = off + 9 + len(body)
                continue
            p = off + 9 + len(body)
            self._count(op)
            if op == 0x0F:
                data_end = (off, body)
                break
            if op in (0x01, 0x02):
                self._fail("unexpected %s record in the data section" % OP[op], off)
            if op == 0x06:
                f = _Fields(body, self.path)
                start, end, usize, crc = f.u64(), f.u64(), f.u64(), f.u32()
                comp = f.string()
                recs = f.bytes64()
                if comp == "zstd":
                    recs = _zstd_decompress(recs, usize, lambda what: self._fail(what, off))
                elif comp:
                    self._fail("compressed chunk (%s) not supported" % comp, off)
                if len(recs) != usize:
                    self._fail("chunk sizes disagree", off)
                if crc and zlib.crc32(recs) != crc:
                    self._fail("chunk CRC does not match", off)
                for cop, coff, cbody in _records(recs, 0, len(recs), "%s chunk at %d" % (self.path, off)):
                    self._count(cop)
                    self._parse(cop, cbody, off)
                chunks[off] = (9 + len(body), recs)
            else:
                self._parse(op, body, off)
        if self.library is None:
            self._fail("no Header record after the magic", 8)
        if data_end is None:
            self.incomplete = "no Data End record (the writer stopped)"
            return
        off, body = data_end
        (crc,) = struct.unpack_from("<I", body, 0)
        if crc and zlib.crc32(buf[:off]) != crc:
            self._fail("data section CRC does not match", off)
        summary_start = p
        if len(buf) < p + 29 + 8 or bytes(buf[-8:]) != MAGIC:
            self.incomplete = "no footer after the Data End record"
            return
        foot = len(buf) - 8 - 29
        f = _Fields(buf[foot:len(buf) - 8], self.path)
        if f.u8() != 0x02 or f.u64() != 20:
            self._fail("no Footer before the closing magic", foot)
        s_start, so_start, s_crc = f.u64(), f.u64(), f.u32()
        if s_crc and zlib.crc32(buf[s_start or foot:foot + 1 + 8 + 16]) != s_crc:
            self._fail("summary CRC does not match", s_start)
        for op, off, body in _records(buf, summary_start, foot, self.path):
            fb = _Fields(body, self.path)
            if op == 0x08:
                ci = dict(start=fb.u64(), end=fb.u64(), offset=fb.u64(), length=fb.u64(),
                          index_offsets=fb.map(_Fields.u16, _Fields.u64), index_length=fb.u64(),
                          compression=fb.string(), compressed=fb.u64(), uncompressed=fb.u64())
                self.chunk_indexes.append(ci)
            elif op == 0x0B:
                self.statistics = dict(
                    message_count=fb.u64(), schema_count=fb.u16(), channel_count=fb.u32(),
                    attachment_count=fb.u32(), metadata_count=fb.u32(), chunk_count=fb.u32(),
                    message_start_time=fb.u64(), message_end_time=fb.u64(),
                    channel_message_counts=fb.map(_Fields.u16, _Fields.u64))
            elif op == 0x0E:
                self.summary_offsets.append((fb.u8(), fb.u64(), fb.u64()))
        # The indexes point where they say.
        for ci in self.chunk_indexes:
            if ci["offset"] not in chunks or chunks[ci["offset"]][0] != ci["length"]:
                self._fail("chunk index points at no chunk", ci["offset"])
            recs = chunks[ci["offset"]][1]
            for cid, moff in ci["index_offsets"].items():
                fb = _Fields(buf[moff + 9:], self.path)
                if buf[moff] != 0x07 or fb.u16() != cid:
                    self._fail("message index offset does not point at its record", moff)
                n = fb.u32() // 16
                for _ in range(n):
                    t, roff = fb.u64(), fb.u64()
                    if recs[roff] != 0x05 or struct.unpack_from("<HIQ", recs, roff + 9)[0] != cid \
                            or struct.unpack_from("<Q", recs, roff + 15)[0] != t:
                        self._fail("message index entry does not point at its message", moff)
        for op, start, length in self.summary_offsets:
            if buf[start] != op:
                self._fail("summary offset group does not start with its opcode", start)
        self.incomplete = ""
        self.complete = True

    def messages(self, topics=None):
        """The messages in file order (Message tuples), decoded."""
        for body in self._messages:
            cid, seq, log_time, pub_time = struct.unpack_from("<HIQQ", body, 0)
            ch = self.channels[cid]
            if topics is not None and ch.topic not in topics:
                continue
            data = bytes(body[22:])
            schema = self.schemas.get(ch.schema_id)
            value = json.loads(data) if ch.message_encoding == "json" else data
            yield Message(ch.topic, ch, seq, log_time, pub_time, ch.message_encoding,
                          schema.name if schema else "", data, value)


def untag(value):
    """A recorded JSON value with the tags of docs/recording.md turned into Python values
    (numpy arrays when numpy is there, else dicts with dtype/shape/bytes)."""
    if isinstance(value, list):
        return [untag(v) for v in value]
    if not isinstance(value, dict):
        return value
    if len(value) == 1:
        (k, v), = value.items()
        if k == "__value__":
            return untag(v)
        if k == "__float__":
            return {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}[v]
        if k == "__bytes__":
            return base64.b64decode(v)
        if k == "__ndarray__":
            raw = base64.b64decode(v["data"]) if "data" in v else None
            try:
                import numpy
                if raw is None:
                    return numpy.zeros(v["shape"], dtype=numpy.dtype(v["dtype"]))
                return numpy.frombuffer(raw, dtype=numpy.dtype(v["dtype"])).reshape(v["shape"])
            except ImportError:
                return {"dtype": v["dtype"], "shape": v["shape"], "data": raw}
    return {k: untag(v) for k, v in value.items()}
