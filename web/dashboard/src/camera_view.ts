// The camera: the first `*/image` channel (foxglove.CompressedImage, base64 JPEG) decoded off
// the main thread by createImageBitmap, newest frame wins (a frame that arrives while one is
// decoding replaces the waiting one). The `*/detections` boxes are drawn over it.
import { frameDrawn } from "./hooks";
import { Detections, ImageMessage, Model } from "./model";

const CLASS_COLORS: Record<string, string> = {
  car: "#3d8bfd", truck: "#9b6dff", bus: "#9b6dff", person: "#ff9f43", pedestrian: "#ff9f43",
  bicycle: "#2ecc71", cyclist: "#2ecc71", "traffic light": "#f1c40f", traffic_light: "#f1c40f",
};
const DETECTIONS_MAX_AGE_NS = 0.2e9; // boxes further than this from the frame are not drawn

export class CameraView {
  private readonly ctx: CanvasRenderingContext2D;
  private decoding = false;
  private waiting: ImageMessage | null = null;
  private bitmap: ImageBitmap | null = null;
  private frameTimeNs = 0;
  private drawnDetections: Detections | null = null;

  constructor(private readonly canvas: HTMLCanvasElement, private readonly model: Model) {
    this.ctx = canvas.getContext("2d")!;
    new ResizeObserver(() => this.draw()).observe(canvas.parentElement!);
  }

  push(img: ImageMessage): void {
    if (this.decoding) {
      this.waiting = img;
      return;
    }
    this.decode(img);
  }

  /** Clear (a replay seeks to before the first frame). */
  clear(): void {
    this.bitmap?.close();
    this.bitmap = null;
    this.draw();
  }

  private async decode(img: ImageMessage): Promise<void> {
    this.decoding = true;
    try {
      const bytes = Uint8Array.from(atob(img.data), (c) => c.charCodeAt(0));
      const bitmap = await createImageBitmap(new Blob([bytes], { type: "image/" + img.format }));
      this.bitmap?.close();
      this.bitmap = bitmap;
      this.frameTimeNs = img.timeNs;
      document.getElementById("camera-topic")!.textContent = img.topic.replace(/\/image$/, "");
      this.draw();
      frameDrawn(img.topic, img.timeNs);
    } catch (e) {
      console.warn("camera frame not decoded:", e);
    } finally {
      this.decoding = false;
      const next = this.waiting;
      this.waiting = null;
      if (next) this.decode(next);
    }
  }

  /** Redraw when detections changed without a new frame. */
  frame(): void {
    if (this.model.detections !== this.drawnDetections && this.bitmap) this.draw();
  }

  private draw(): void {
    const { canvas, ctx, bitmap } = this;
    const box = canvas.parentElement!;
    document.getElementById("camera-empty")!.hidden = bitmap !== null;
    if (!bitmap) {
      ctx.clearRect(0, 0, canvas.width, canvas.height);
      return;
    }
    const dpr = window.devicePixelRatio || 1;
    const aspect = bitmap.width / bitmap.height;
    let w = box.clientWidth, h = w / aspect;
    if (h > box.clientHeight && box.clientHeight > 0) { h = box.clientHeight; w = h * aspect; }
    canvas.style.width = `${w}px`;
    canvas.style.height = `${h}px`;
    if (canvas.width !== Math.round(w * dpr)) canvas.width = Math.round(w * dpr);
    if (canvas.height !== Math.round(h * dpr)) canvas.height = Math.round(h * dpr);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.drawImage(bitmap, 0, 0, w, h);
    const det = this.model.detectionsAt(this.frameTimeNs);
    this.drawnDetections = this.model.detections;
    const info = document.getElementById("camera-info")!;
    if (!det || Math.abs(det.frameTimeNs - this.frameTimeNs) > DETECTIONS_MAX_AGE_NS) {
      info.textContent = `${bitmap.width}x${bitmap.height}`;
      return;
    }
    const sx = w / (det.width || bitmap.width), sy = h / (det.height || bitmap.height);
    ctx.font = "11px system-ui, sans-serif";
    ctx.textBaseline = "bottom";
    for (const d of det.detections) {
      const name = d.class ?? String(d.class_id ?? "?");
      const color = CLASS_COLORS[name] ?? "#e84393";
      const x = d.x_min * sx, y = d.y_min * sy, bw = (d.x_max - d.x_min) * sx, bh = (d.y_max - d.y_min) * sy;
      ctx.strokeStyle = color;
      ctx.lineWidth = 2;
      ctx.strokeRect(x, y, bw, bh);
      const label = d.confidence !== undefined && !det.ground_truth ? `${name} ${d.confidence.toFixed(2)}` : name;
      const tw = ctx.measureText(label).width + 6;
      const ly = y > 14 ? y : y + 14;
      const lx = Math.max(0, Math.min(x - 1, w - tw)); // inside the image
      ctx.fillStyle = color;
      ctx.fillRect(lx, ly - 14, tw, 14);
      ctx.fillStyle = "#0b0d11";
      ctx.fillText(label, lx + 3, ly - 1);
    }
    const source = det.ground_truth ? "ground truth" : `${det.inference_ms?.toFixed(0) ?? "?"} ms`;
    info.textContent = `${det.detections.length} boxes (${source})`;
    if (det.ground_truth) {
      ctx.fillStyle = "rgba(241,196,15,0.9)";
      ctx.fillRect(w - 92, 6, 86, 16);
      ctx.fillStyle = "#0b0d11";
      ctx.fillText("ground truth", w - 86, 21);
    }
  }
}
