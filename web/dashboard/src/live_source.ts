// Live mode: Foxglove WebSocket protocol (foxglove.websocket.v1) to the server that served the
// page (`convoy run --live`), with Foxglove's own client. Subscribes to the channels the
// dashboard shows; sends pause/resume/step on /convoy/control (clientPublish).
import { FoxgloveClient } from "@foxglove/ws-protocol";
import type { Channel, MessageData, ServerInfo } from "@foxglove/ws-protocol";
import { Model, wanted } from "./model";

export type ConnectionState = "connecting" | "connected" | "closed" | "error";

export interface LiveEvents {
  state(s: ConnectionState, detail?: string): void;
  serverInfo(info: ServerInfo): void;
  time(ns: number): void;
}

const encoder = new TextEncoder();

export class LiveSource {
  private client: FoxgloveClient | null = null;
  private subscriptions = new Map<number, Channel>(); // subscription id -> channel
  private controlChannel: number | null = null;
  private canPublish = false;
  private everConnected = false;
  private retries = 0;
  private stopped = false;

  constructor(private readonly url: string, private readonly model: Model,
              private readonly events: LiveEvents) {}

  start(): void {
    if (this.stopped) return;
    this.state("connecting");
    const ws = new WebSocket(this.url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    const client = new FoxgloveClient({ ws });
    this.client = client;
    this.subscriptions.clear();
    this.controlChannel = null;
    client.on("open", () => {
      this.everConnected = true;
      this.retries = 0;
      this.state("connected");
    });
    client.on("serverInfo", (info) => {
      this.canPublish = info.capabilities.includes("clientPublish");
      this.events.serverInfo(info);
    });
    client.on("advertise", (channels) => {
      for (const ch of channels) {
        if (!wanted(ch.topic)) continue;
        this.subscriptions.set(client.subscribe(ch.id), ch);
      }
    });
    client.on("unadvertise", (ids) => {
      for (const [sub, ch] of this.subscriptions) if (ids.includes(ch.id)) this.subscriptions.delete(sub);
    });
    client.on("message", (m: MessageData) => this.onMessage(m));
    client.on("time", (t) => this.events.time(Number(t.timestamp)));
    client.on("status", (s) => {
      if (s.level >= 2) console.warn("server:", s.message);
    });
    client.on("error", () => {}); // a close follows
    client.on("close", () => {
      this.client = null;
      if (this.stopped) return;
      // The run ended (the server closes) or the page was opened before it listened.
      if (this.everConnected) {
        this.state("closed", "the run ended");
        return;
      }
      if (this.retries++ < 20) setTimeout(() => this.start(), 500);
      else this.state("error", "cannot connect to " + this.url);
    });
  }

  private state(s: ConnectionState, detail?: string): void {
    if (!this.stopped) this.events.state(s, detail);
  }

  private onMessage(m: MessageData): void {
    const ch = this.subscriptions.get(m.subscriptionId);
    if (!ch || ch.encoding !== "json") return;
    const data = new Uint8Array(m.data.buffer, m.data.byteOffset, m.data.byteLength);
    this.model.handle({ topic: ch.topic, schemaName: ch.schemaName, timeNs: Number(m.timestamp), data });
  }

  stop(): void {
    this.stopped = true;
    this.client?.close();
    this.client = null;
  }

  /** Whether the server takes commands (capability clientPublish). */
  get controllable(): boolean {
    return this.client !== null && this.canPublish;
  }

  send(command: "pause" | "resume" | "step"): void {
    const client = this.client;
    if (!client || !this.canPublish) return;
    if (this.controlChannel === null) {
      this.controlChannel = client.advertise({
        topic: "/convoy/control", encoding: "json", schemaName: "convoy.Control",
      });
    }
    client.sendMessage(this.controlChannel, encoder.encode(JSON.stringify({ command })));
  }
}
