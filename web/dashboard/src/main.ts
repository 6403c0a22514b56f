// Convoy's dashboard: live (served by `convoy run --live`, Foxglove WebSocket protocol to the
// same host) or replay (?mcap=URL, or a recording opened or dropped). Wires a source into the
// model and the views, and runs the drawing loop.
import "./styles.css";
import { CameraView } from "./camera_view";
import { Controls, Playback, setConnection, setRunName } from "./controls";
import { frameTapped, hooks, watchFirstPaint } from "./hooks";
import { LiveSource } from "./live_source";
import { MapView, legendHtml } from "./map_view";
import { Model } from "./model";
import { ReplaySource, fetchRecording, readRecording, Recording } from "./replay_source";
import { ScorePanel } from "./score_panel";

watchFirstPaint();
const model = new Model();
const mapView = new MapView(document.getElementById("map") as HTMLCanvasElement, model);
const camera = new CameraView(document.getElementById("camera") as HTMLCanvasElement, model);
const score = new ScorePanel(model);
const controls = new Controls((file) => openFile(file));
model.onImage = (img) => camera.push(img);
model.onFrameTap = frameTapped;
document.getElementById("legend")!.innerHTML = legendHtml();
const follow = document.getElementById("follow") as HTMLInputElement;
follow.addEventListener("change", () => mapView.setFollow(follow.checked));
mapView.onFollowChange = (f) => (follow.checked = f);
document.getElementById("btn-fit")!.addEventListener("click", () => mapView.fit());

let live: LiveSource | null = null;
let replay: ReplaySource | null = null;

function fail(text: string): void {
  hooks.error = text;
  setConnection("error", text);
  document.getElementById("map-empty")!.textContent = text;
  console.error(text);
}

function startLive(url: string): void {
  hooks.mode = "live";
  setRunName("", "live");
  const source = new LiveSource(url, model, {
    state(s, detail) {
      hooks.connected = s === "connected";
      setConnection(s === "closed" ? "ended" : s, detail);
    },
    serverInfo(info) {
      setRunName(info.metadata?.simulation ?? info.name, "live");
    },
    time(ns) {
      model.timeNs = ns;
    },
  });
  live = source;
  controls.setPlayback({
    get paused() { return model.paused; },
    get enabled() { return source.controllable; },
    togglePause: () => source.send(model.paused ? "resume" : "pause"),
    step: () => source.send("step"),
  });
  source.start();
}

function startReplay(rec: Recording, name: string): void {
  live?.stop();
  live = null;
  hooks.mode = "replay";
  hooks.connected = false;
  setRunName(rec.simulation || name, "replay");
  setConnection("recording", `${rec.messages.length} messages`);
  const source = new ReplaySource(rec, model);
  replay = source;
  source.seek(rec.startNs);
  const playback: Playback = {
    get paused() { return !source.playing; },
    enabled: true,
    togglePause() {
      if (!source.playing && source.timeNs >= rec.endNs) source.seek(rec.startNs);
      source.playing = !source.playing;
    },
    step: () => source.step(),
  };
  controls.setPlayback(playback);
  controls.showTimeline(rec.startNs, rec.endNs, (ns) => {
    source.seek(ns);
    if (model.cameraTopic && !rec.byTopic.get(model.cameraTopic)?.some((m) => m.timeNs <= ns)) camera.clear();
  }, (r) => (source.rate = r));
}

async function openFile(file: File): Promise<void> {
  setConnection("loading", file.name);
  try {
    startReplay(await readRecording(new Uint8Array(await file.arrayBuffer())), file.name);
  } catch (e) {
    fail(`${file.name}: ${(e as Error).message}`);
  }
}

function loop(wallMs: number): void {
  replay?.tick(wallMs);
  mapView.frame();
  camera.frame();
  score.frame();
  controls.frame(replay ? replay.timeNs : model.timeNs, wallMs);
  requestAnimationFrame(loop);
}

const params = new URLSearchParams(location.search);
const mcap = params.get("mcap");
if (mcap) {
  hooks.mode = "replay";
  setRunName(mcap.replace(/^.*\//, ""), "replay");
  fetchRecording(mcap, (text) => setConnection("loading", text))
    .then((rec) => startReplay(rec, mcap))
    .catch((e) => fail(`${mcap}: ${(e as Error).message}`));
} else if (params.get("ws") || location.protocol.startsWith("http")) {
  startLive(params.get("ws") ?? `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}`);
} else {
  setConnection("idle", "open a recording.mcap");
  document.getElementById("map-empty")!.textContent = "open or drop a recording.mcap";
}
requestAnimationFrame(loop);
