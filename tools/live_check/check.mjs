// Connects to Convoy's live server with Foxglove's own protocol client
// (@foxglove/ws-protocol's FoxgloveClient over the `ws` package), and writes what it got as
// JSON: the server's info, the channels, per topic the number of messages and the first one
// decoded, the time messages, the status messages. A test instrument (tests/e2e/test_live.py,
// benchmarks/live_bench.py).
//
//   node check.mjs --url ws://127.0.0.1:8765 [--mode all|garbage|disconnect] [--out FILE]
//                  [--wait SECONDS] [--timeout SECONDS]
//
// all:        subscribe to every channel as it is advertised; read until the server closes.
// garbage:    the same, after sending a message that is not JSON and subscribing to a channel
//             that does not exist (the server answers with status errors).
// disconnect: subscribe to everything, then after 20 messages send half a WebSocket frame and
//             drop the connection.
// Retries connecting for --wait seconds (the server starts with the run). Exit 0 when the
// server closed the connection (or, for disconnect, once it has disconnected), 1 otherwise.
import wsProtocol from "@foxglove/ws-protocol";
import { WebSocket } from "ws";
import { writeFileSync } from "node:fs";

const { FoxgloveClient } = wsProtocol;

function args() {
  const out = { mode: "all", wait: 30, timeout: 120 };
  const a = process.argv.slice(2);
  for (let i = 0; i < a.length; i += 2) out[a[i].replace(/^--/, "")] = a[i + 1];
  out.wait = Number(out.wait);
  out.timeout = Number(out.timeout);
  if (!out.url) throw new Error("--url ws://HOST:PORT is needed");
  return out;
}

const opts = args();
const result = {
  mode: opts.mode, connected: false, closed: false, serverInfo: null, channels: [],
  messages: {}, time: { count: 0, last: null }, status: [], errors: [],
};
const channels = new Map(); // id -> channel
const topics = new Map();   // subscription id -> channel
let total = 0;
let gone = false; // disconnect: the connection was dropped

function finish(code) {
  const text = JSON.stringify(result, (k, v) => (typeof v === "bigint" ? v.toString() : v), 1);
  if (opts.out) writeFileSync(opts.out, text);
  else process.stdout.write(text + "\n");
  process.exit(code);
}

// The first message of a channel, decoded enough for a test to check it.
function describe(channel, bytes) {
  if (channel.encoding !== "json") return { bytes: bytes.length };
  const value = JSON.parse(Buffer.from(bytes).toString("utf8"));
  if (channel.schemaName === "foxglove.CompressedImage") {
    const jpeg = Buffer.from(value.data, "base64");
    return { format: value.format, frame_id: value.frame_id, timestamp: value.timestamp,
             jpeg_bytes: jpeg.length, head: jpeg.subarray(0, 3).toString("hex"),
             tail: jpeg.subarray(jpeg.length - 2).toString("hex") };
  }
  return { json: value, bytes: bytes.length };
}

function connect(deadline) {
  const ws = new WebSocket(opts.url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  let opened = false;
  ws.on("error", (err) => {
    if (!opened && Date.now() < deadline) {
      setTimeout(() => connect(deadline), 100);
      return;
    }
    result.errors.push(String(err));
  });
  client.on("open", () => {
    opened = true;
    result.connected = true;
  });
  client.on("serverInfo", (info) => {
    result.serverInfo = info;
    if (opts.mode === "garbage") {
      ws.send("{this is not json");
      client.subscribe(987654);
    }
  });
  client.on("status", (s) => result.status.push(s));
  client.on("time", (t) => {
    result.time.count++;
    result.time.last = t.timestamp;
  });
  client.on("advertise", (list) => {
    for (const c of list) {
      channels.set(c.id, c);
      result.channels.push({ id: c.id, topic: c.topic, encoding: c.encoding,
                             schemaName: c.schemaName, schemaEncoding: c.schemaEncoding,
                             schemaBytes: c.schema.length });
      topics.set(client.subscribe(c.id), c);
    }
  });
  client.on("message", (m) => {
    const c = topics.get(m.subscriptionId);
    if (!c || gone) return;
    const bytes = new Uint8Array(m.data.buffer, m.data.byteOffset, m.data.byteLength);
    const entry = (result.messages[c.topic] ??= { count: 0, first: null, last_time: null });
    if (entry.count === 0) {
      try {
        entry.first = describe(c, bytes);
      } catch (e) {
        entry.first = { error: String(e) };
      }
    }
    entry.count++;
    entry.last_time = m.timestamp;
    if (++total === 20 && opts.mode === "disconnect") {
      // Half a frame (a masked text frame announcing a 16-bit length, and one byte of it),
      // then the connection is gone.
      ws._socket.write(Buffer.from([0x81, 0xfe, 0x01]));
      ws._socket.destroy();
      gone = true;
      result.closed = true;
      setTimeout(() => finish(0), 50);
    }
  });
  client.on("close", () => {
    if (!opened) return;
    result.closed = true;
    finish(0);
  });
}

setTimeout(() => finish(1), opts.timeout * 1000);
connect(Date.now() + opts.wait * 1000);
