// Replay mode: a recording.mcap (fetched from ?mcap=URL, or a file picked or dropped) read with
// the official MCAP library (@mcap/core; zstd chunks by fzstd), kept in memory per topic, and
// played into the model on a local clock: play/pause, 1x/2x/4x, seek anywhere.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import type { McapTypes } from "@mcap/core";
import { decompress } from "fzstd";
import { Model, SourceMessage, isImageTopic, wanted } from "./model";

interface Recorded { topic: string; schemaName: string; timeNs: number; data: Uint8Array }

export interface Recording {
  simulation: string;
  startNs: number;
  endNs: number;
  messages: Recorded[]; // log-time order
  byTopic: Map<string, Recorded[]>;
}

const decompressHandlers = {
  zstd: (data: Uint8Array, size: bigint) => decompress(data, new Uint8Array(Number(size))),
};

export async function fetchRecording(url: string, progress: (text: string) => void): Promise<Recording> {
  progress("fetching " + url);
  const res = await fetch(url);
  if (!res.ok) throw new Error(`${url}: HTTP ${res.status} ${res.statusText}`);
  const buf = new Uint8Array(await res.arrayBuffer());
  progress(`reading ${(buf.length / 1e6).toFixed(1)} MB`);
  return readRecording(buf);
}

export async function readRecording(bytes: Uint8Array): Promise<Recording> {
  const messages: Recorded[] = [];
  let simulation = "";
  try {
    const readable = {
      size: async () => BigInt(bytes.length),
      read: async (offset: bigint, length: bigint) => bytes.subarray(Number(offset), Number(offset + length)),
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    const topics: number[] = [];
    for (const ch of reader.channelsById.values()) if (wanted(ch.topic)) topics.push(ch.id);
    const names = [...reader.channelsById.values()].filter((c) => topics.includes(c.id)).map((c) => c.topic);
    for await (const m of reader.readMessages({ topics: names })) {
      const ch = reader.channelsById.get(m.channelId)!;
      if (ch.messageEncoding !== "json") continue;
      messages.push({ topic: ch.topic, schemaName: reader.schemasById.get(ch.schemaId)?.name ?? "",
                      timeNs: Number(m.logTime), data: m.data });
    }
    for await (const md of reader.readMetadata({ name: "convoy" })) simulation = md.metadata.get("simulation") ?? "";
  } catch (indexedError) {
    // A recording without its summary (a killed run): read it front to back.
    messages.length = 0;
    simulation = readStreamed(bytes, messages) || simulation;
    if (messages.length === 0) throw indexedError;
  }
  messages.sort((a, b) => a.timeNs - b.timeNs);
  const byTopic = new Map<string, Recorded[]>();
  for (const m of messages) {
    let list = byTopic.get(m.topic);
    if (!list) byTopic.set(m.topic, (list = []));
    list.push(m);
  }
  return {
    simulation,
    startNs: messages.length ? Math.min(0, messages[0].timeNs) : 0,
    endNs: messages.length ? messages[messages.length - 1].timeNs : 0,
    messages, byTopic,
  };
}

function readStreamed(bytes: Uint8Array, out: Recorded[]): string {
  const stream = new McapStreamReader({ decompressHandlers });
  stream.append(bytes);
  const channels = new Map<number, McapTypes.Channel>();
  const schemas = new Map<number, string>();
  let simulation = "";
  for (let rec; (rec = stream.nextRecord()); ) {
    if (rec.type === "Schema") schemas.set(rec.id, rec.name);
    else if (rec.type === "Channel") channels.set(rec.id, rec);
    else if (rec.type === "Metadata" && rec.name === "convoy") simulation = rec.metadata.get("simulation") ?? "";
    else if (rec.type === "Message") {
      const ch = channels.get(rec.channelId);
      if (!ch || !wanted(ch.topic) || ch.messageEncoding !== "json") continue;
      out.push({ topic: ch.topic, schemaName: schemas.get(ch.schemaId) ?? "", timeNs: Number(rec.logTime), data: rec.data });
    }
  }
  return simulation;
}

// What a seek replays of each topic, up to the new time.
function seekTail(topic: string, list: Recorded[], upto: number): Recorded[] {
  if (topic === "/convoy/map" || topic === "/convoy/infractions") return list.slice(0, upto);
  if (topic === "/convoy/log") return list.slice(Math.max(0, upto - 200), upto);
  if (topic === "/convoy/scene") {
    // Entities persist until deleted: replay the last 2 s so that every present one is there.
    const t = upto > 0 ? list[upto - 1].timeNs - 2e9 : 0;
    let from = upto;
    while (from > 0 && list[from - 1].timeNs >= t) from--;
    return list.slice(from, upto);
  }
  return upto > 0 ? [list[upto - 1]] : [];
}

/** Index of the first message after time t (binary search). */
function after(list: Recorded[], t: number): number {
  let lo = 0, hi = list.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (list[mid].timeNs <= t) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

export class ReplaySource {
  timeNs: number;
  rate = 1;
  playing = true;
  private next = 0; // index into recording.messages of the next message to play
  private lastWall = 0;

  constructor(readonly recording: Recording, private readonly model: Model) {
    this.timeNs = recording.startNs;
  }

  /** Move to time t: the model is rebuilt from what was recorded up to t. */
  seek(t: number): void {
    const rec = this.recording;
    t = Math.max(rec.startNs, Math.min(rec.endNs, t));
    this.model.resetDynamic();
    const batch: Recorded[] = [];
    for (const [topic, list] of rec.byTopic) {
      if (topic === "/convoy/map" && this.model.map.entities.size > 0) continue;
      batch.push(...seekTail(topic, list, after(list, t)));
    }
    batch.sort((a, b) => a.timeNs - b.timeNs);
    for (const m of batch) this.model.handle(m as SourceMessage);
    this.timeNs = t;
    this.model.timeNs = t;
    this.next = after(rec.messages, t);
  }

  /** Advance the playback clock by the wall time since the last tick (call once per frame). */
  tick(wallMs: number): void {
    // At most 0.25 s at a time: a hidden tab gets no frames, and should not jump on coming back.
    const dt = this.lastWall ? Math.min(250, wallMs - this.lastWall) : 0;
    this.lastWall = wallMs;
    if (!this.playing) return;
    const rec = this.recording;
    const to = Math.min(rec.endNs, this.timeNs + dt * 1e6 * this.rate);
    this.play(to);
    if (to >= rec.endNs) this.playing = false;
  }

  /** Play forward to time t, every message on the way. */
  play(t: number): void {
    const msgs = this.recording.messages;
    // Of the images on the way only the last is worth decoding.
    let lastImage = -1;
    let end = this.next;
    while (end < msgs.length && msgs[end].timeNs <= t) {
      if (isImageTopic(msgs[end].topic)) lastImage = end;
      end++;
    }
    for (let i = this.next; i < end; i++) {
      if (isImageTopic(msgs[i].topic) && i !== lastImage) continue;
      this.model.handle(msgs[i] as SourceMessage);
    }
    this.next = end;
    this.timeNs = t;
    this.model.timeNs = t;
  }

  /** The next time at which something was recorded (step). */
  step(): void {
    const msgs = this.recording.messages;
    if (this.next < msgs.length) this.play(msgs[this.next].timeNs);
    this.playing = false;
  }
}
