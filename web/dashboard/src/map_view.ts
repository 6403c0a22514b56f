// The bird's-eye map: lanes and signal posts of /convoy/map, road users of /convoy/scene as
// oriented boxes (ego highlighted), signal states, the ego's route and trail. Drag to pan, wheel
// to zoom, "follow ego" keeps the ego in the middle. Redraws only when something changed.
import { hooks } from "./hooks";
import { Model } from "./model";
import { Entity, Line, bounds, css, isEgo, isRoadUser, meta, yawOf } from "./scene";

const CATEGORY_COLORS: Record<string, string> = {
  car: "#3d8bfd", truck: "#9b6dff", bus: "#9b6dff", pedestrian: "#ff9f43", cyclist: "#2ecc71",
  bicycle: "#2ecc71", motorcycle: "#2ecc71", ego: "#ff4757",
};
const LEGEND = ["ego", "car", "truck", "pedestrian", "cyclist"];

interface CachedLine { path: Path2D; color: string; width: number; scaleInvariant: boolean }

export class MapView {
  private readonly ctx: CanvasRenderingContext2D;
  private cx = 0;
  private cy = 0;
  private scale = 4; // pixels per metre
  private dirty = true;
  private drawnVersions = "";
  private mapCache: { version: number; lines: CachedLine[] } = { version: -1, lines: [] };
  private fitted = false;
  private followed = false;
  private drag: { x: number; y: number } | null = null;
  follow = true;
  onFollowChange: (follow: boolean) => void = () => {};

  constructor(private readonly canvas: HTMLCanvasElement, private readonly model: Model) {
    this.ctx = canvas.getContext("2d")!;
    new ResizeObserver(() => (this.dirty = true)).observe(canvas);
    canvas.addEventListener("pointerdown", (e) => {
      this.drag = { x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener("pointermove", (e) => {
      if (!this.drag) return;
      const dx = e.clientX - this.drag.x, dy = e.clientY - this.drag.y;
      if (this.follow && Math.hypot(dx, dy) < 3) return;
      this.drag = { x: e.clientX, y: e.clientY };
      this.setFollow(false);
      this.cx -= dx / this.scale;
      this.cy += dy / this.scale;
      this.dirty = true;
    });
    const end = () => (this.drag = null);
    canvas.addEventListener("pointerup", end);
    canvas.addEventListener("pointercancel", end);
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      const r = canvas.getBoundingClientRect();
      const px = e.clientX - r.left - r.width / 2, py = e.clientY - r.top - r.height / 2;
      // Keep the point under the cursor where it is (unless following the ego).
      const wx = this.cx + px / this.scale, wy = this.cy - py / this.scale;
      this.scale = Math.max(0.2, Math.min(80, this.scale * Math.exp(-e.deltaY * 0.0015)));
      if (!this.follow) {
        this.cx = wx - px / this.scale;
        this.cy = wy + py / this.scale;
      }
      this.dirty = true;
    }, { passive: false });
  }

  setFollow(follow: boolean): void {
    if (this.follow === follow) return;
    this.follow = follow;
    this.dirty = true;
    this.onFollowChange(follow);
  }

  /** Show the whole map (or scene). */
  fit(userAction = true): void {
    const b = bounds(this.model.map.entities.values()) ?? bounds(this.model.scene.entities.values());
    if (!b) return;
    const w = this.canvas.clientWidth || 800, h = this.canvas.clientHeight || 600;
    this.cx = (b[0] + b[2]) / 2;
    this.cy = (b[1] + b[3]) / 2;
    this.scale = Math.max(0.2, 0.92 * Math.min(w / Math.max(1, b[2] - b[0]), h / Math.max(1, b[3] - b[1])));
    if (userAction) this.setFollow(false);
    this.dirty = true;
  }

  /** Draw if anything changed; call once per animation frame. */
  frame(): void {
    const versions = `${this.model.map.version}/${this.model.scene.version}`;
    if (!this.dirty && versions === this.drawnVersions) return;
    this.dirty = false;
    this.drawnVersions = versions;
    this.draw();
  }

  private draw(): void {
    const { canvas, ctx, model } = this;
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr);
      canvas.height = Math.round(h * dpr);
    }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#11141a";
    ctx.fillRect(0, 0, w, h);

    const scene = [...model.scene.entities.values()];
    const ego = scene.find(isEgo);
    // The whole map until the ego shows up (then, by default, follow it).
    if (!this.fitted && (model.map.entities.size > 0 || scene.length > 0) && !ego) {
      this.fit(false);
      this.fitted = true;
    }
    if (this.follow && ego?.cubes?.[0]) {
      if (!this.followed) this.scale = Math.max(this.scale, 3);
      this.followed = true;
      this.cx = ego.cubes[0].pose.position.x;
      this.cy = ego.cubes[0].pose.position.y;
    }

    const s = this.scale;
    const world = () => ctx.setTransform(dpr * s, 0, 0, -dpr * s, dpr * (w / 2 - this.cx * s), dpr * (h / 2 + this.cy * s));
    world();
    this.drawGrid(w, h);
    for (const l of this.mapLines()) {
      ctx.strokeStyle = l.color;
      ctx.lineWidth = l.scaleInvariant ? l.width / s : Math.max(l.width, 1 / s);
      ctx.stroke(l.path);
    }
    // Signal posts of the map (their state comes with the scene).
    for (const e of model.map.entities.values())
      for (const sp of e.spheres ?? []) this.dot(sp.pose.position.x, sp.pose.position.y, 2.5, "#3a404c");

    const users: Entity[] = [];
    for (const e of scene) {
      if (isRoadUser(e)) users.push(e);
      else this.drawDecoration(e);
    }
    const positions: Record<string, [number, number]> = {};
    // Ego last, on top.
    users.sort((a, b) => Number(isEgo(a)) - Number(isEgo(b)));
    for (const e of users) {
      this.drawRoadUser(e);
      const p = e.cubes![0].pose.position;
      positions[e.id] = [p.x, p.y];
    }
    hooks.roadUsers = users.length;
    hooks.roadUserPositions = positions;

    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    this.drawLabels(users, w, h);
    this.drawScaleBar(h);
    document.getElementById("map-empty")!.hidden = model.map.entities.size > 0 || users.length > 0;
  }

  private mapLines(): CachedLine[] {
    const map = this.model.map;
    if (this.mapCache.version === map.version) return this.mapCache.lines;
    const lines: CachedLine[] = [];
    for (const e of map.entities.values()) {
      for (const l of e.lines ?? []) {
        lines.push({ path: linePath(l), color: css(l.color, "#4a5160"), width: l.thickness ?? 0.15,
                     scaleInvariant: l.scale_invariant === true });
      }
    }
    this.mapCache = { version: map.version, lines };
    return lines;
  }

  private drawGrid(w: number, h: number): void {
    const { ctx, scale: s } = this;
    const step = s > 2 ? 50 : s > 0.5 ? 200 : 1000;
    const x0 = this.cx - w / 2 / s, x1 = this.cx + w / 2 / s, y0 = this.cy - h / 2 / s, y1 = this.cy + h / 2 / s;
    ctx.strokeStyle = "#181c24";
    ctx.lineWidth = 1 / s;
    ctx.beginPath();
    for (let x = Math.floor(x0 / step) * step; x <= x1; x += step) { ctx.moveTo(x, y0); ctx.lineTo(x, y1); }
    for (let y = Math.floor(y0 / step) * step; y <= y1; y += step) { ctx.moveTo(x0, y); ctx.lineTo(x1, y); }
    ctx.stroke();
  }

  /** Route, trail, signal states and anything else that is not a road user. */
  private drawDecoration(e: Entity): void {
    const { ctx, scale: s } = this;
    for (const l of e.lines ?? []) {
      const route = e.id === "ego/route", trail = e.id === "ego/trail";
      ctx.strokeStyle = route ? "rgba(0,210,211,0.55)" : trail ? "rgba(255,71,87,0.8)" : css(l.color);
      ctx.lineWidth = route ? 4 / s : trail ? 2 / s : l.scale_invariant ? (l.thickness ?? 1) / s : Math.max(l.thickness ?? 0.2, 1 / s);
      ctx.setLineDash(route ? [6 / s, 5 / s] : []);
      ctx.stroke(linePath(l));
      ctx.setLineDash([]);
    }
    for (const sp of e.spheres ?? []) {
      const r = Math.max((sp.size?.x ?? 1) / 2, 4 / s);
      this.dot(sp.pose.position.x, sp.pose.position.y, r * s, css(sp.color, "#888"), "#0b0d11");
    }
  }

  private drawRoadUser(e: Entity): void {
    const { ctx, scale: s } = this;
    const cube = e.cubes![0];
    const p = cube.pose.position;
    const yaw = yawOf(cube.pose.orientation);
    const ego = isEgo(e);
    const category = meta(e, "category") ?? "";
    const fill = ego ? CATEGORY_COLORS.ego : css(cube.color, CATEGORY_COLORS[category] ?? "#9aa4b2");
    const len = cube.size.x, wid = cube.size.y;
    if (category === "pedestrian") {
      this.dot(p.x, p.y, Math.max(0.3 * s, 3.5), fill, "rgba(0,0,0,0.6)");
      return;
    }
    if (Math.max(len, wid) * s < 5) { // too small to be a box at this zoom
      this.dot(p.x, p.y, ego ? 5 : 3, fill, ego ? "#fff" : undefined);
      return;
    }
    ctx.save();
    ctx.translate(p.x, p.y);
    ctx.rotate(yaw);
    ctx.fillStyle = fill;
    ctx.fillRect(-len / 2, -wid / 2, len, wid);
    ctx.lineWidth = (ego ? 2.5 : 1) / s;
    ctx.strokeStyle = ego ? "#ffffff" : "rgba(0,0,0,0.6)";
    ctx.strokeRect(-len / 2, -wid / 2, len, wid);
    // The front: a light bar across the box's leading edge.
    ctx.fillStyle = "rgba(255,255,255,0.75)";
    const bar = Math.min(len * 0.18, 0.8);
    ctx.fillRect(len / 2 - bar, -wid / 2, bar, wid);
    ctx.restore();
    if (ego) {
      ctx.strokeStyle = "rgba(255,71,87,0.45)";
      ctx.lineWidth = 2 / s;
      ctx.beginPath();
      ctx.arc(p.x, p.y, Math.max(len, 14 / s), 0, 2 * Math.PI);
      ctx.stroke();
    }
  }

  private drawLabels(users: Entity[], w: number, h: number): void {
    const { ctx, scale: s } = this;
    ctx.font = "11px system-ui, sans-serif";
    ctx.textAlign = "center";
    for (const e of users) {
      if (s < 7 && !isEgo(e)) continue; // the ego's always, the others' when zoomed in
      const p = e.cubes![0].pose.position;
      const x = w / 2 + (p.x - this.cx) * s, y = h / 2 - (p.y - this.cy) * s;
      if (x < 0 || y < 0 || x > w || y > h) continue;
      const speed = Number(meta(e, "speed"));
      const label = (isEgo(e) ? "ego" : e.texts?.[0]?.text ?? e.id) + (Number.isFinite(speed) ? ` ${(speed * 3.6).toFixed(0)} km/h` : "");
      ctx.fillStyle = "rgba(12,14,18,0.7)";
      const tw = ctx.measureText(label).width;
      ctx.fillRect(x - tw / 2 - 3, y - 24, tw + 6, 14);
      ctx.fillStyle = isEgo(e) ? "#ffb3ba" : "#c8ced8";
      ctx.fillText(label, x, y - 13);
    }
  }

  private drawScaleBar(h: number): void {
    const { ctx, scale: s } = this;
    const metres = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000].find((m) => m * s >= 60) ?? 1000;
    const x = 14, y = h - 16;
    ctx.strokeStyle = "#8a93a3";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(x, y - 5); ctx.lineTo(x, y); ctx.lineTo(x + metres * s, y); ctx.lineTo(x + metres * s, y - 5);
    ctx.stroke();
    ctx.fillStyle = "#8a93a3";
    ctx.font = "11px system-ui, sans-serif";
    ctx.textAlign = "left";
    ctx.fillText(`${metres} m`, x + metres * s + 6, y);
  }

  /** A circle of `r` pixels at a world point (in the world transform). */
  private dot(x: number, y: number, r: number, fill: string, stroke?: string): void {
    const { ctx, scale: s } = this;
    ctx.beginPath();
    ctx.arc(x, y, r / s, 0, 2 * Math.PI);
    ctx.fillStyle = fill;
    ctx.fill();
    if (stroke) {
      ctx.lineWidth = 1.5 / s;
      ctx.strokeStyle = stroke;
      ctx.stroke();
    }
  }
}

export function legendHtml(): string {
  return LEGEND.map((c) => `<span><i style="background:${CATEGORY_COLORS[c]}"></i>${c}</span>`).join("");
}

function linePath(l: Line): Path2D {
  const path = new Path2D();
  const ox = l.pose?.position.x ?? 0, oy = l.pose?.position.y ?? 0;
  const yaw = yawOf(l.pose?.orientation), c = Math.cos(yaw), sn = Math.sin(yaw);
  const pt = (i: number): [number, number] => {
    const p = l.points[i];
    return [ox + c * p.x - sn * p.y, oy + sn * p.x + c * p.y];
  };
  if (l.type === 2) { // LINE_LIST: pairs
    for (let i = 0; i + 1 < l.points.length; i += 2) { path.moveTo(...pt(i)); path.lineTo(...pt(i + 1)); }
    return path;
  }
  for (let i = 0; i < l.points.length; i++) (i === 0 ? path.moveTo(...pt(i)) : path.lineTo(...pt(i)));
  if (l.type === 1 && l.points.length > 2) path.closePath();
  return path;
}
