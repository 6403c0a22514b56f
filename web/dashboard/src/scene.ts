// The 2-D scene the map view draws: foxglove.SceneUpdate entities kept by id, as /convoy/map
// (latched, once) and /convoy/scene (every update) send them. Only what a bird's-eye view needs
// is read: cubes, lines, spheres, texts, their poses and colours, and the entity metadata.

export interface Vec3 { x: number; y: number; z?: number }
export interface Quat { x: number; y: number; z: number; w: number }
export interface Color { r: number; g: number; b: number; a: number }
export interface Pose { position: Vec3; orientation?: Quat }
export interface Cube { pose: Pose; size: Vec3; color?: Color }
export interface Sphere { pose: Pose; size?: Vec3; color?: Color }
export interface Line {
  type?: number; // 0 LINE_STRIP, 1 LINE_LOOP, 2 LINE_LIST
  pose?: Pose;
  thickness?: number;
  scale_invariant?: boolean;
  points: Vec3[];
  color?: Color;
  colors?: Color[];
}
export interface Text { pose: Pose; text: string; color?: Color }
export interface KeyValue { key: string; value: string }
export interface Entity {
  id: string;
  frame_id?: string;
  cubes?: Cube[];
  spheres?: Sphere[];
  lines?: Line[];
  texts?: Text[];
  metadata?: KeyValue[];
}
export interface Deletion { type?: number; id?: string }
export interface SceneUpdate { deletions?: Deletion[]; entities?: Entity[] }

export function meta(e: Entity, key: string): string | undefined {
  return e.metadata?.find((m) => m.key === key)?.value;
}

export function yawOf(q: Quat | undefined): number {
  if (!q) return 0;
  return Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

export function css(c: Color | undefined, fallback = "#9aa4b2", alpha?: number): string {
  if (!c) return fallback;
  const to = (v: number) => Math.round(Math.max(0, Math.min(1, v)) * 255);
  return `rgba(${to(c.r)},${to(c.g)},${to(c.b)},${alpha ?? c.a ?? 1})`;
}

/** Entities by id; `version` changes with every update so that views redraw only then. */
export class EntityStore {
  readonly entities = new Map<string, Entity>();
  version = 0;

  apply(update: SceneUpdate): void {
    for (const d of update.deletions ?? []) {
      if (d.type === 1) this.entities.clear(); // ALL
      else if (d.id !== undefined) this.entities.delete(d.id);
    }
    for (const e of update.entities ?? []) this.entities.set(e.id, e);
    this.version++;
  }

  clear(): void {
    this.entities.clear();
    this.version++;
  }
}

/** A road user: an entity with a cube (the contract's /convoy/scene). */
export function isRoadUser(e: Entity): boolean {
  return (e.cubes?.length ?? 0) > 0 && !e.id.startsWith("ego/");
}

export function isEgo(e: Entity): boolean {
  return meta(e, "ego") === "true";
}

/** The bounds of every point of these entities (x/y), or null when there are none. */
export function bounds(entities: Iterable<Entity>): [number, number, number, number] | null {
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  const add = (p: Vec3) => {
    if (p.x < x0) x0 = p.x;
    if (p.x > x1) x1 = p.x;
    if (p.y < y0) y0 = p.y;
    if (p.y > y1) y1 = p.y;
  };
  for (const e of entities) {
    for (const l of e.lines ?? []) for (const p of l.points) add(p);
    for (const c of e.cubes ?? []) add(c.pose.position);
    for (const s of e.spheres ?? []) add(s.pose.position);
  }
  return x0 <= x1 ? [x0, y0, x1, y1] : null;
}
