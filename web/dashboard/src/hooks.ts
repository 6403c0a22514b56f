// window.convoyDashboard: what the page drew, for tests and the curious (the contract in
// docs/dashboard.md), and the camera latency: /convoy/frames says when the coordinator's tap
// got each frame (Unix ms); the camera view says when it drew it. Same machine, same clock.

export interface LastFrame { topic: string; time_ns: number; drawn_wall_ms: number; latency_ms: number | null }

export interface DashboardHooks {
  mode: "live" | "replay" | "idle";
  connected: boolean;
  roadUsers: number;
  roadUserPositions: Record<string, [number, number]>;
  frames: number;
  lastFrame: LastFrame | null;
  latencies: number[];
  score: Record<string, unknown> | null;
  infractions: unknown[];
  paused: boolean;
  firstPaintMs: number | null;
  timeNs: number;
  error: string | null;
}

const KEEP_LATENCIES = 2000;
const KEEP_PENDING = 200;

export const hooks: DashboardHooks = {
  mode: "idle", connected: false, roadUsers: 0, roadUserPositions: {}, frames: 0, lastFrame: null,
  latencies: [], score: null, infractions: [], paused: false, firstPaintMs: null, timeNs: 0,
  error: null,
};
(window as unknown as { convoyDashboard: DashboardHooks }).convoyDashboard = hooks;

export function wallNowMs(): number {
  return performance.timeOrigin + performance.now();
}

// Frames drawn before their /convoy/frames message arrived, and the other way round.
const drawn = new Map<string, LastFrame>();
const tapped = new Map<string, number>();
const key = (topic: string, timeNs: number) => `${topic}@${Math.round(timeNs)}`;

function trim<V>(m: Map<string, V>): void {
  while (m.size > KEEP_PENDING) m.delete(m.keys().next().value as string);
}

function record(frame: LastFrame, tapWallMs: number): void {
  frame.latency_ms = frame.drawn_wall_ms - tapWallMs;
  hooks.latencies.push(frame.latency_ms);
  if (hooks.latencies.length > KEEP_LATENCIES) hooks.latencies.splice(0, hooks.latencies.length - KEEP_LATENCIES);
}

export function frameDrawn(topic: string, timeNs: number): void {
  const frame: LastFrame = { topic, time_ns: timeNs, drawn_wall_ms: wallNowMs(), latency_ms: null };
  hooks.frames++;
  hooks.lastFrame = frame;
  const k = key(topic, timeNs);
  const tap = tapped.get(k);
  if (tap !== undefined) {
    tapped.delete(k);
    record(frame, tap);
  } else if (hooks.mode === "live") {
    drawn.set(k, frame);
    trim(drawn);
  }
}

export function frameTapped(topic: string, timeNs: number, wallMs: number): void {
  const k = key(topic, timeNs);
  const frame = drawn.get(k);
  if (frame) {
    drawn.delete(k);
    record(frame, wallMs);
  } else {
    tapped.set(k, wallMs);
    trim(tapped);
  }
}

export function medianLatency(last = 50): number | null {
  const xs = hooks.latencies.slice(-last).sort((a, b) => a - b);
  if (xs.length === 0) return null;
  const mid = xs.length >> 1;
  return xs.length % 2 ? xs[mid] : (xs[mid - 1] + xs[mid]) / 2;
}

/** First contentful paint, from navigation start (Performance API). */
export function watchFirstPaint(): void {
  const take = (entries: PerformanceEntryList) => {
    for (const e of entries) if (e.name === "first-contentful-paint") hooks.firstPaintMs = e.startTime;
  };
  take(performance.getEntriesByName("first-contentful-paint"));
  if (hooks.firstPaintMs !== null) return;
  try {
    new PerformanceObserver((list) => take(list.getEntries())).observe({ type: "paint", buffered: true });
  } catch {
    // an old browser: no paint timing
  }
}
