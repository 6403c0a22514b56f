// The score (/convoy/metrics: the known fields first, then every other number that arrives),
// the infractions as they happen (/convoy/infractions) and the log tail (/convoy/log).
import { hooks } from "./hooks";
import { Model } from "./model";

const KNOWN: [string, string][] = [
  ["driving_score", "driving score"],
  ["route_completion", "route completion"],
  ["infraction_penalty", "infraction penalty"],
];
const LEVELS = ["", "debug", "info", "warning", "error", "fatal"];

export class ScorePanel {
  private metricsVersion = -1;
  private logVersion = -1;

  constructor(private readonly model: Model) {}

  frame(): void {
    const m = this.model;
    if (m.metricsVersion !== this.metricsVersion) {
      this.metricsVersion = m.metricsVersion;
      this.drawScore();
      this.drawInfractions();
      hooks.score = m.metrics;
      hooks.infractions = m.allInfractions();
    }
    if (m.logVersion !== this.logVersion) {
      this.logVersion = m.logVersion;
      this.drawLog();
    }
  }

  private drawScore(): void {
    const el = document.getElementById("score")!;
    const metrics = this.model.metrics;
    if (!metrics) {
      el.innerHTML = `<div class="muted">${hooks.mode === "replay" ? "no score in this recording" : "no /convoy/metrics yet"}</div>`;
      return;
    }
    const rows: string[] = [];
    const seen = new Set<string>(["time_ns"]);
    for (const [key, label] of KNOWN) {
      seen.add(key);
      if (typeof metrics[key] === "number") rows.push(row(key, label, metrics[key] as number, true));
    }
    for (const [key, v] of Object.entries(metrics)) {
      if (seen.has(key)) continue;
      if (typeof v === "number") rows.push(row(key, key.replace(/_/g, " "), v, false));
      else if (typeof v === "boolean") rows.push(row(key, key.replace(/_/g, " "), v ? "yes" : "no", false));
      else if (Array.isArray(v)) rows.push(row(key, key.replace(/_/g, " "), `${v.length}`, false));
    }
    el.innerHTML = rows.join("") || `<div class="muted">no numeric fields</div>`;
  }

  private drawInfractions(): void {
    const list = this.model.allInfractions();
    document.getElementById("infraction-count")!.textContent = list.length ? `(${list.length})` : "";
    const el = document.getElementById("infractions")!;
    el.innerHTML = list.slice(-50).reverse().map((i) => {
      const t = typeof i.time_s === "number" ? `${i.time_s.toFixed(1)} s` : "";
      const rest = Object.entries(i).filter(([k, v]) => k !== "time_s" && k !== "kind" && v !== null && v !== undefined && !(k === "counted" && v === true))
        .map(([k, v]) => `${k} ${typeof v === "number" ? fmt(v) : escape(String(JSON.stringify(v)))}`).join(", ");
      return `<li><span class="t">${t}</span><b>${escape(String(i.kind ?? "infraction"))}</b> <span class="muted">${escape(rest)}</span></li>`;
    }).join("") || `<li class="muted">none</li>`;
  }

  private drawLog(): void {
    const el = document.getElementById("log")!;
    const atBottom = el.scrollHeight - el.scrollTop - el.clientHeight < 24;
    el.innerHTML = this.model.log.slice(-120).map((l) =>
      `<li class="lv${l.level}"><span class="t">${(l.timeNs / 1e9).toFixed(2)}</span><span class="lv">${LEVELS[l.level] ?? l.level}</span>${escape(l.message)}</li>`).join("");
    if (!this.model.log.length) el.innerHTML = `<li class="muted">no log lines</li>`;
    if (atBottom) el.scrollTop = el.scrollHeight;
  }
}

function row(key: string, label: string, v: number | string, big: boolean): string {
  let text: string = typeof v === "number" ? fmt(v) : v;
  let bar = "";
  if (typeof v === "number" && (key === "route_completion" || key === "driving_score")) {
    // CARLA's leaderboard scale: 0-100
    text = key === "route_completion" ? `${v.toFixed(1)} %` : v.toFixed(1);
    bar = `<div class="bar"><i style="width:${Math.max(0, Math.min(100, v))}%"></i></div>`;
  } else if (typeof v === "number" && key === "infraction_penalty") {
    text = `×${v.toFixed(3)}`;
  }
  return `<div class="metric${big ? " big" : ""}" data-key="${escape(key)}"><span class="k">${escape(label)}</span><span class="v">${escape(text)}</span>${bar}</div>`;
}

function fmt(v: number): string {
  if (Number.isInteger(v)) return String(v);
  return Math.abs(v) >= 100 ? v.toFixed(1) : Math.abs(v) >= 1 ? v.toFixed(2) : v.toPrecision(3);
}

function escape(s: string): string {
  return s.replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]!);
}
