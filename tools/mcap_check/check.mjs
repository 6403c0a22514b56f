// Reads an MCAP file with the official MCAP library (@mcap/core), both ways: the streaming
// reader (every record, CRCs checked) and the indexed reader (summary, chunk indexes, message
// indexes, metadata). Prints what it found as JSON; exits 1 when either reader refuses the
// file. A test instrument for Convoy's own writer (tests/e2e/test_recording.py). Chunks
// compressed with zstd are decompressed by fzstd (pure JavaScript, from npm).
//
//   node tools/mcap_check/check.mjs FILE.mcap
//
// With --partial, each file may be cut short (a killed run, a full disk): only the streaming
// reader reads it, fed the bytes in pieces as from a pipe, every CRC checked; it stops where
// the file ends (inside the open chunk). Prints a line {file, done, messages, topics: {topic:
// count}, records} per file; exits 0 when every byte up to there was read, 1 when the reader
// refused a record (a CRC, a malformed record).
//
//   node tools/mcap_check/check.mjs --partial FILE.mcap...  (tests/e2e/test_recording_faults.py)
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { readFileSync } from "node:fs";
import zlib from "node:zlib";
import { decompress as zstdDecompress } from "fzstd";

const partial = process.argv[2] === "--partial";
const file = process.argv[partial ? 3 : 2];
const decompressHandlers = {
  zstd: (data, size) => {
    const raw = zstdDecompress(data, new Uint8Array(Number(size)));
    if (raw.length !== Number(size)) throw new Error(`zstd chunk: ${raw.length} bytes, not ${size}`);
    return raw;
  },
};

// One file cut short, read by the streaming reader: {file, done, messages, topics, records}
// (and `error` when the reader refused a record).
function readPartial(file) {
  let bytes;
  try {
    bytes = new Uint8Array(readFileSync(file));
  } catch (e) {
    return { file, done: false, messages: 0, topics: {}, records: {}, error: String(e) };
  }
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers });
  const channels = new Map();
  const topics = {};
  const records = {};
  let messages = 0;
  try {
    for (let at = 0; at === 0 || at < bytes.length; at += 65536) {
      reader.append(bytes.subarray(at, at + 65536));
      for (let rec; (rec = reader.nextRecord()); ) {
        records[rec.type] = (records[rec.type] ?? 0) + 1;
        if (rec.type === "Channel") channels.set(rec.id, rec.topic);
        if (rec.type === "Message") {
          const topic = channels.get(rec.channelId);
          if (topic === undefined) throw new Error(`message on unknown channel ${rec.channelId}`);
          topics[topic] = (topics[topic] ?? 0) + 1;
          messages++;
        }
      }
    }
  } catch (e) {
    return { file, done: false, messages, topics, records, error: String(e) };
  }
  return { file, done: reader.done(), messages, topics, records };
}

if (partial) {
  // Several files: one line of JSON each.
  let refused = false;
  for (const f of process.argv.slice(3)) {
    const got = readPartial(f);
    console.log(JSON.stringify(got));
    if (got.error) {
      console.error(`${f}: @mcap/core refused it after ${got.messages} messages: ${got.error}`);
      refused = true;
    }
  }
  process.exit(refused ? 1 : 0);
}

const bytes = new Uint8Array(readFileSync(file));
const out = { file, stream: {}, indexed: {} };

// Streaming: every record, chunk and data-section CRCs validated.
const stream = new McapStreamReader({ validateCrcs: true, decompressHandlers });
stream.append(bytes);
const ops = {};
let streamMessages = 0;
for (let rec; (rec = stream.nextRecord()); ) {
  ops[rec.type] = (ops[rec.type] ?? 0) + 1;
  if (rec.type === "Message") streamMessages++;
}
out.stream = { done: stream.done(), records: ops, messages: streamMessages };
if (!stream.done()) {
  console.log(JSON.stringify(out));
  console.error(`${file}: the streaming reader did not reach the end of the file`);
  process.exit(1);
}

// Indexed: summary, chunk and message indexes, metadata.
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const topics = {};
let indexedMessages = 0;
let lastTime = -1n;
let ordered = true;
let jsonOk = 0;
for await (const m of reader.readMessages({ validateCrcs: true })) {
  indexedMessages++;
  const ch = reader.channelsById.get(m.channelId);
  topics[ch.topic] = (topics[ch.topic] ?? 0) + 1;
  if (m.logTime < lastTime) ordered = false;
  lastTime = m.logTime;
  if (ch.messageEncoding === "json") {
    JSON.parse(new TextDecoder().decode(m.data));
    jsonOk++;
  }
}
const metadata = {};
for await (const md of reader.readMetadata()) metadata[md.name] = Object.fromEntries(md.metadata);
const schemas = {};
for (const s of reader.schemasById.values()) schemas[s.name] = s.encoding;
let dataCrcOk = null;
if (reader.dataSectionCrc !== undefined && zlib.crc32) {
  const own = zlib.crc32(bytes.subarray(0, Number(reader.dataEndOffset))) >>> 0;
  dataCrcOk = own === reader.dataSectionCrc;
}
out.indexed = {
  messages: indexedMessages,
  statistics_messages: Number(reader.statistics?.messageCount ?? -1),
  chunks: reader.chunkIndexes.length,
  chunk_compressions: [...new Set(reader.chunkIndexes.map((c) => c.compression))],
  compressed_bytes: Number(reader.chunkIndexes.reduce((a, c) => a + c.compressedSize, 0n)),
  uncompressed_bytes: Number(reader.chunkIndexes.reduce((a, c) => a + c.uncompressedSize, 0n)),
  channels: reader.channelsById.size,
  topics,
  schemas,
  metadata_names: Object.keys(metadata),
  convoy_version: metadata.convoy?.convoy_version,
  json_messages_parsed: jsonOk,
  log_time_ordered: ordered,
  data_section_crc_ok: dataCrcOk,
  profile: reader.header.profile,
  library: reader.header.library,
};
console.log(JSON.stringify(out));
