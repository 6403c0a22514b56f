// Opens Convoy's web dashboard (web/dashboard) in headless Chromium and checks what it draws,
// through the page's window.convoyDashboard (docs/dashboard.md). A test instrument
// (tests/e2e/test_dashboard.py).
//
//   node check.mjs --url URL [--screenshot OUT.png] [--seconds N] [--expect-live|--expect-replay]
//                  [--expect-score] [--expect-control] [--size 1280x800] [--timeout S]
//                  [--chromium /usr/bin/chromium]
//
// Asserts: the page loads without page errors; it reaches the expected mode (live: connected;
// replay: the recording read); road users are drawn and at least one moves between two samples;
// camera frames are drawn, more and more; with --expect-score a score (/convoy/metrics) shows;
// with --expect-control (live) the pause button pauses the run (simulated time stops) and the
// play button resumes it. Samples for --seconds (default 8) after the first road users show.
// Prints one JSON object (figures below) and exits 1 with one line per failed check on stderr.
//   firstPaintMs           navigation start -> first contentful paint (Performance API)
//   frameLatencyMedianMs   median of window.convoyDashboard.latencies (live: camera tap -> drawn)
//   framesDrawn, roadUsers, roadUsersMoved, maxMoveM, score, infractions, simTimeS...
import puppeteer from "puppeteer-core";

function parseArgs(argv) {
  const o = { seconds: 8, size: "1280x800", timeout: 60, chromium: "/usr/bin/chromium", expect: null,
              expectScore: false, expectControl: false };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) throw new Error(`${a} needs a value`);
      return argv[++i];
    };
    if (a === "--url") o.url = value();
    else if (a === "--screenshot") o.screenshot = value();
    else if (a === "--seconds") o.seconds = Number(value());
    else if (a === "--size") o.size = value();
    else if (a === "--timeout") o.timeout = Number(value());
    else if (a === "--chromium") o.chromium = value();
    else if (a === "--expect-live") o.expect = "live";
    else if (a === "--expect-replay") o.expect = "replay";
    else if (a === "--expect-score") o.expectScore = true;
    else if (a === "--expect-control") o.expectControl = true;
    else throw new Error(`unknown argument ${a}`);
  }
  if (!o.url) throw new Error("--url URL is needed");
  if (!(o.seconds > 0)) throw new Error("--seconds must be > 0");
  const m = /^(\d+)x(\d+)$/.exec(o.size);
  if (!m) throw new Error("--size must be WxH, e.g. 1280x800");
  o.width = Number(m[1]);
  o.height = Number(m[2]);
  return o;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const median = (xs) => {
  if (!xs.length) return null;
  const s = [...xs].sort((a, b) => a - b);
  const mid = s.length >> 1;
  return s.length % 2 ? s[mid] : (s[mid - 1] + s[mid]) / 2;
};
const quantile = (xs, q) => {
  if (!xs.length) return null;
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
};
const round = (x, n = 1) => (x === null || x === undefined ? null : Math.round(x * 10 ** n) / 10 ** n);

let opts;
try {
  opts = parseArgs(process.argv.slice(2));
} catch (e) {
  console.error(`dashboard_check: ${e.message}`);
  process.exit(2);
}

const failures = [];
const pageErrors = [];
const consoleErrors = [];
const out = { url: opts.url };
const browser = await puppeteer.launch({
  executablePath: opts.chromium,
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", `--window-size=${opts.width},${opts.height}`],
  defaultViewport: { width: opts.width, height: opts.height },
});
const deadline = Date.now() + opts.timeout * 1000;
const state = (page) => page.evaluate(() => {
  const d = window.convoyDashboard;
  if (!d) return null;
  return { mode: d.mode, connected: d.connected, roadUsers: d.roadUsers, positions: d.roadUserPositions,
           frames: d.frames, latencies: d.latencies.length, score: d.score, infractions: d.infractions.length,
           paused: d.paused, timeNs: d.timeNs, error: d.error, lastFrame: d.lastFrame };
});

async function waitFor(page, what, pred) {
  for (;;) {
    const s = await state(page);
    if (s && pred(s)) return s;
    if (s?.error) throw new Error(`${what}: the page says: ${s.error}`);
    if (Date.now() > deadline) throw new Error(`${what}: not within ${opts.timeout} s (last state: ${JSON.stringify(s && { ...s, positions: undefined })})`);
    await sleep(100);
  }
}

try {
  const page = await browser.newPage();
  page.on("pageerror", (e) => pageErrors.push(String(e.message ?? e)));
  page.on("console", (m) => m.type() === "error" && consoleErrors.push(m.text()));
  const response = await page.goto(opts.url, { waitUntil: "load", timeout: opts.timeout * 1000 });
  if (!response || !response.ok()) throw new Error(`GET ${opts.url}: HTTP ${response?.status()}`);
  if (opts.expect) await waitFor(page, `mode ${opts.expect}`, (s) => s.mode === opts.expect && (opts.expect !== "live" || s.connected));
  const first = await waitFor(page, "road users drawn", (s) => s.roadUsers > 0);

  // Sample for --seconds: road users moving, frames drawn.
  const samples = [first];
  const t0 = Date.now();
  while (Date.now() - t0 < opts.seconds * 1000) {
    await sleep(500);
    samples.push(await state(page));
  }
  const last = samples[samples.length - 1];
  let maxMove = 0;
  for (let i = 1; i < samples.length; i++) {
    const a = samples[i - 1].positions, b = samples[i].positions;
    for (const id of Object.keys(b)) if (a[id]) maxMove = Math.max(maxMove, Math.hypot(b[id][0] - a[id][0], b[id][1] - a[id][1]));
  }
  out.mode = last.mode;
  out.roadUsers = Math.max(...samples.map((s) => s.roadUsers));
  out.roadUsersMoved = maxMove > 0.01;
  out.maxMoveM = round(maxMove, 2);
  out.framesDrawn = last.frames;
  out.framesDrawnWhileSampled = last.frames - first.frames;
  out.lastFrame = last.lastFrame;
  out.simTimeS = round(last.timeNs / 1e9, 2);
  out.simTimeSampledS = round((last.timeNs - first.timeNs) / 1e9, 2);
  out.score = last.score;
  out.infractions = last.infractions;

  if (!out.roadUsersMoved) failures.push(`no road user moved in ${opts.seconds} s (${out.roadUsers} drawn)`);
  if (last.frames === 0) failures.push("no camera frame drawn");
  else if (out.framesDrawnWhileSampled <= 0) failures.push(`camera frames stopped at ${last.frames}`);
  if (opts.expectScore) {
    const s = await waitFor(page, "score (/convoy/metrics)", (x) => x.score !== null).catch((e) => (failures.push(e.message), null));
    if (s) out.score = s.score;
  }

  if (opts.expectControl) {
    const click = (id) => page.evaluate((i) => document.getElementById(i).click(), id);
    out.control = {};
    // The button is enabled once serverInfo said clientPublish.
    const enabled = await page.waitForFunction(() => !document.getElementById("btn-play").disabled,
                                               { timeout: 5000 }).then(() => true, () => false);
    if (!enabled) failures.push("the play/pause button is disabled (no clientPublish capability?)");
    else {
      await click("btn-play");
      const p = await waitFor(page, "paused after the pause button", (s) => s.paused).catch((e) => (failures.push(e.message), null));
      if (p) {
        await sleep(1000);
        const a = await state(page);
        await sleep(1000);
        const b = await state(page);
        out.control.pausedAdvanceS = round((b.timeNs - a.timeNs) / 1e9, 3);
        if (b.timeNs !== a.timeNs) failures.push(`simulated time went on while paused (${out.control.pausedAdvanceS} s in 1 s)`);
        await click("btn-step");
        await sleep(1000);
        const c = await state(page);
        out.control.stepAdvanceS = round((c.timeNs - b.timeNs) / 1e9, 3);
        if (!(c.timeNs > b.timeNs) || !c.paused) failures.push(`step: time ${b.timeNs} -> ${c.timeNs}, paused ${c.paused}`);
        await click("btn-play");
        const r = await waitFor(page, "running after the play button", (s) => !s.paused && s.timeNs > c.timeNs)
          .catch((e) => (failures.push(e.message), null));
        out.control.resumed = r !== null;
      }
    }
  }

  out.firstPaintMs = round(await page.evaluate(() => performance.getEntriesByName("first-contentful-paint")[0]?.startTime ?? null));
  const latencies = await page.evaluate(() => window.convoyDashboard.latencies.slice());
  out.frameLatencyMedianMs = round(median(latencies));
  out.frameLatencyP90Ms = round(quantile(latencies, 0.9));
  out.latencySamples = latencies.length;
  if (opts.expect === "live" && latencies.length === 0) out.frameLatencyNote = "no /convoy/frames matched a drawn frame";
  if (opts.screenshot) {
    await page.screenshot({ path: opts.screenshot });
    out.screenshot = opts.screenshot;
  }
} catch (e) {
  failures.push(e.message);
} finally {
  await browser.close().catch(() => {});
}
if (out.firstPaintMs === null || out.firstPaintMs === undefined) {
  if (!failures.length) failures.push("no first contentful paint");
}
for (const e of pageErrors) failures.push(`page error: ${e}`);
out.pageErrors = pageErrors;
out.consoleErrors = consoleErrors;
out.ok = failures.length === 0;
out.failures = failures;
console.log(JSON.stringify(out, null, 1));
for (const f of failures) console.error(`dashboard_check: ${f}`);
process.exit(failures.length ? 1 : 0);
