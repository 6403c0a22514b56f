// What the dashboard knows about the run, fed by either source (live or replay) one message at
// a time: the map and scene entities, the camera's latest frame and detections, the score,
// infractions, log and paused state. Views read it; the camera is pushed (its decode is async).
import { EntityStore, SceneUpdate } from "./scene";

export interface SourceMessage {
  topic: string;
  schemaName: string;
  timeNs: number; // simulated time of the message (log time)
  data: Uint8Array;
}

export interface ImageMessage { topic: string; timeNs: number; format: string; data: string }
export interface Detection {
  class?: string; class_id?: number; confidence?: number;
  x_min: number; y_min: number; x_max: number; y_max: number;
}
export interface Detections {
  topic: string; timeNs: number; width: number; height: number; inference_ms?: number;
  ground_truth?: boolean; detections: Detection[];
  /** The time of the frame they are of: the detector engine answers a frame one of its steps
   *  later (its `time_ns` is the end of that step), so about the previous answer's time. */
  frameTimeNs: number;
}
export interface LogLine { timeNs: number; level: number; name: string; message: string }
export type Infraction = Record<string, unknown> & { time_s?: number; kind?: string };

const decoder = new TextDecoder();
const LOG_LINES = 300;

export function isImageTopic(topic: string): boolean { return topic.endsWith("/image"); }
export function isDetectionsTopic(topic: string): boolean { return topic.endsWith("/detections"); }

const CONVOY_TOPICS = new Set(["/convoy/map", "/convoy/scene", "/convoy/frames", "/convoy/metrics",
                               "/convoy/infractions", "/convoy/status", "/convoy/log"]);

/** Topics the dashboard reads; the rest are neither subscribed nor kept. */
export function wanted(topic: string): boolean {
  return CONVOY_TOPICS.has(topic) || isImageTopic(topic) || isDetectionsTopic(topic);
}

export class Model {
  readonly map = new EntityStore();
  readonly scene = new EntityStore();
  simulation = "";
  timeNs = 0;
  paused = false;
  metrics: Record<string, unknown> | null = null;
  metricsVersion = 0;
  infractions: Infraction[] = [];
  log: LogLine[] = [];
  logVersion = 0;
  cameraTopic: string | null = null;
  detectionsTopic: string | null = null;
  detections: Detections | null = null; // the latest
  recentDetections: Detections[] = []; // the last few, to match a frame by time
  /** The camera view's input; set by main. */
  onImage: (img: ImageMessage) => void = () => {};
  /** /convoy/frames: {topic, time_ns, wall_ms}; set by main (latency). */
  onFrameTap: (topic: string, timeNs: number, wallMs: number) => void = () => {};
  onStatus: () => void = () => {};

  /** The detections nearest in time to a camera frame (the detector may skip frames). */
  detectionsAt(timeNs: number): Detections | null {
    let best: Detections | null = null;
    for (const d of this.recentDetections)
      if (!best || Math.abs(d.frameTimeNs - timeNs) < Math.abs(best.frameTimeNs - timeNs)) best = d;
    return best;
  }

  /** The infraction events, and those of the score (/convoy/metrics `infractions`, which also
   *  holds the ones scored at the end of a route, e.g. min_speed) that no event announced. */
  allInfractions(): Infraction[] {
    const out = [...this.infractions];
    const scored = this.metrics?.infractions;
    if (!Array.isArray(scored)) return out;
    for (const raw of scored) {
      if (!raw || typeof raw !== "object") continue;
      const { time, ...rest } = raw as Record<string, unknown>;
      const i: Infraction = { time_s: typeof time === "number" ? time : (rest.time_s as number), ...rest };
      const known = out.some((e) => e.kind === i.kind &&
        (typeof e.time_s !== "number" || typeof i.time_s !== "number" || Math.abs(e.time_s - i.time_s) < 0.1));
      if (!known) out.push(i);
    }
    return out.sort((a, b) => (a.time_s ?? 0) - (b.time_s ?? 0));
  }

  /** Forget the time-dependent state (a replay seeks); the map stays. */
  resetDynamic(): void {
    this.scene.clear();
    this.metrics = null;
    this.metricsVersion++;
    this.infractions = [];
    this.log = [];
    this.logVersion++;
    this.detections = null;
    this.recentDetections = [];
  }

  handle(m: SourceMessage): void {
    if (m.timeNs > this.timeNs) this.timeNs = m.timeNs;
    const topic = m.topic;
    if (isImageTopic(topic)) {
      if (this.cameraTopic === null) this.cameraTopic = topic;
      if (topic !== this.cameraTopic) return;
      const v = parse(m.data) as { format?: string; data?: string; timestamp?: { sec: number; nsec: number } };
      if (!v?.data) return;
      const t = v.timestamp ? v.timestamp.sec * 1e9 + v.timestamp.nsec : m.timeNs;
      this.onImage({ topic, timeNs: t, format: v.format ?? "jpeg", data: v.data });
      return;
    }
    if (isDetectionsTopic(topic)) {
      if (this.detectionsTopic === null) this.detectionsTopic = topic;
      if (topic !== this.detectionsTopic) return;
      const v = parse(m.data) as Partial<Detections> & { time_ns?: number };
      if (!v || !Array.isArray(v.detections)) return;
      const timeNs = v.time_ns ?? m.timeNs;
      const prev = this.recentDetections[this.recentDetections.length - 1];
      const step = prev && timeNs > prev.timeNs && timeNs - prev.timeNs < 0.5e9 ? timeNs - prev.timeNs : 0;
      this.detections = {
        topic, timeNs, width: v.width ?? 0, height: v.height ?? 0, inference_ms: v.inference_ms,
        ground_truth: v.ground_truth === true, detections: v.detections, frameTimeNs: timeNs - step,
      };
      this.recentDetections.push(this.detections);
      if (this.recentDetections.length > 12) this.recentDetections.shift();
      return;
    }
    switch (topic) {
      case "/convoy/map": this.map.apply(parse(m.data) as SceneUpdate); break;
      case "/convoy/scene": this.scene.apply(parse(m.data) as SceneUpdate); break;
      case "/convoy/metrics": {
        const v = parse(m.data);
        if (v && typeof v === "object") {
          this.metrics = v as Record<string, unknown>;
          this.metricsVersion++;
        }
        break;
      }
      case "/convoy/infractions": {
        const v = parse(m.data);
        if (v && typeof v === "object") {
          this.infractions.push(v as Infraction);
          this.metricsVersion++;
        }
        break;
      }
      case "/convoy/log": {
        const v = parse(m.data) as { level?: number; name?: string; message?: string } | null;
        if (!v) break;
        this.log.push({ timeNs: m.timeNs, level: v.level ?? 2, name: v.name ?? "", message: v.message ?? "" });
        if (this.log.length > LOG_LINES) this.log.splice(0, this.log.length - LOG_LINES);
        this.logVersion++;
        break;
      }
      case "/convoy/status": {
        const v = parse(m.data) as { paused?: boolean } | null;
        if (v && typeof v.paused === "boolean") {
          this.paused = v.paused;
          this.onStatus();
        }
        break;
      }
      case "/convoy/frames": {
        const v = parse(m.data) as { topic?: string; time_ns?: number; wall_ms?: number } | null;
        if (v?.topic && typeof v.time_ns === "number" && typeof v.wall_ms === "number")
          this.onFrameTap(v.topic, v.time_ns, v.wall_ms);
        break;
      }
    }
  }
}

function parse(data: Uint8Array): any {
  try {
    return JSON.parse(decoder.decode(data));
  } catch {
    return null;
  }
}
