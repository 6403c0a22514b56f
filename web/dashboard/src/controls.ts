// The header (run name, simulated time, connection, latency), the play/pause and step buttons,
// the replay timeline (slider, 1x/2x/4x) and opening a recording (file picker, drag and drop).
import { hooks, medianLatency } from "./hooks";

/** What the buttons act on: the live run or the local playback. */
export interface Playback {
  readonly paused: boolean;
  readonly enabled: boolean;
  togglePause(): void;
  step(): void;
}

const $ = (id: string) => document.getElementById(id)!;

export function setRunName(name: string, mode: string): void {
  $("run-name").textContent = name || "-";
  $("mode").textContent = mode;
  document.title = name ? `${name} - Convoy` : "Convoy";
}

export function setConnection(state: string, detail = ""): void {
  const el = $("conn");
  el.textContent = state;
  el.className = "pill " + state.replace(/\s.*/, "");
  el.title = detail;
}

export function formatTime(ns: number): string {
  const s = ns / 1e9;
  if (s < 60) return `${s.toFixed(2)} s`;
  const m = Math.floor(s / 60);
  return `${m}:${(s - 60 * m).toFixed(1).padStart(4, "0")}`;
}

export class Controls {
  private playback: Playback | null = null;
  private lastHeader = 0;
  private sliderHeld = false;
  private pace: [number, number][] = []; // (wall ms, sim ns)

  constructor(onOpenFile: (file: File) => void) {
    $("btn-play").addEventListener("click", () => this.playback?.togglePause());
    $("btn-step").addEventListener("click", () => this.playback?.step());
    window.addEventListener("keydown", (e) => {
      if ((e.target as HTMLElement).tagName === "INPUT" && (e.target as HTMLInputElement).type !== "range") return;
      if (e.code === "Space") { e.preventDefault(); this.playback?.togglePause(); }
      if (e.code === "Period") this.playback?.step();
    });
    const file = $("file") as HTMLInputElement;
    file.addEventListener("change", () => file.files?.[0] && onOpenFile(file.files[0]));
    const drop = $("drop");
    let depth = 0;
    window.addEventListener("dragenter", (e) => { e.preventDefault(); depth++; drop.hidden = false; });
    window.addEventListener("dragleave", () => { if (--depth <= 0) { depth = 0; drop.hidden = true; } });
    window.addEventListener("dragover", (e) => e.preventDefault());
    window.addEventListener("drop", (e) => {
      e.preventDefault();
      depth = 0;
      drop.hidden = true;
      const f = e.dataTransfer?.files?.[0];
      if (f) onOpenFile(f);
    });
  }

  setPlayback(p: Playback): void {
    this.playback = p;
  }

  /** The replay timeline: seek on drag, rate buttons. */
  showTimeline(startNs: number, endNs: number, seek: (ns: number) => void, setRate: (r: number) => void): void {
    $("timeline").hidden = false;
    const slider = $("slider") as HTMLInputElement;
    slider.min = String(startNs / 1e6);
    slider.max = String(endNs / 1e6);
    slider.step = "10";
    $("t-end").textContent = formatTime(endNs);
    slider.addEventListener("input", () => seek(Number(slider.value) * 1e6));
    slider.addEventListener("pointerdown", () => (this.sliderHeld = true));
    window.addEventListener("pointerup", () => (this.sliderHeld = false));
    for (const b of document.querySelectorAll<HTMLButtonElement>("#timeline [data-rate]")) {
      b.addEventListener("click", () => {
        setRate(Number(b.dataset.rate));
        for (const o of document.querySelectorAll("#timeline [data-rate]")) o.classList.toggle("on", o === b);
      });
    }
  }

  /** Once per animation frame: header figures (a few times a second) and button states. */
  frame(timeNs: number, wallMs: number): void {
    const p = this.playback;
    const play = $("btn-play") as HTMLButtonElement;
    const paused = p?.paused ?? false;
    play.disabled = !p?.enabled;
    ($("btn-step") as HTMLButtonElement).disabled = !p?.enabled;
    play.innerHTML = paused ? "&#9654;" : "&#10074;&#10074;";
    play.classList.toggle("on", paused);
    $("mode").classList.toggle("paused", paused);
    $("mode").dataset.paused = paused ? "paused" : "";
    hooks.paused = paused;
    hooks.timeNs = timeNs;
    if (!$("timeline").hidden) {
      const slider = $("slider") as HTMLInputElement;
      if (!this.sliderHeld) slider.value = String(timeNs / 1e6);
      $("t-now").textContent = formatTime(timeNs);
    }
    if (wallMs - this.lastHeader < 200) return;
    this.lastHeader = wallMs;
    $("sim-time").textContent = formatTime(timeNs);
    // Simulated seconds per wall second over the last ~3 s.
    this.pace.push([wallMs, timeNs]);
    while (this.pace.length > 2 && wallMs - this.pace[0][0] > 3000) this.pace.shift();
    const [w0, t0] = this.pace[0];
    const rate = wallMs - w0 > 500 ? (timeNs - t0) / 1e6 / (wallMs - w0) : null;
    $("pace").textContent = rate === null || paused ? "" : `${rate.toFixed(2)}× real time`;
    const lat = medianLatency();
    $("latency").textContent = lat === null ? "-" : `${lat.toFixed(0)} ms`;
  }
}
