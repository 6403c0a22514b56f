"""The web dashboard (web/dashboard, docs/dashboard.md) in headless Chromium, driven by
tools/dashboard_check (puppeteer-core): a short live run of experiments/city_traffic served by
`convoy run --live` (the page at http://127.0.0.1:PORT/, the Foxglove WebSocket protocol on the
same port) and ended by Ctrl-C once the page has been checked, then its recording replayed by
`convoy view RUN_DIR`. (A live, recorded run that ends by itself: test_live.Watched.)

The check asserts that the page loads without errors, draws the road users (and sees them
move), draws camera frames, shows the score (/convoy/metrics), and that its pause / step / play
buttons pause, step and resume the run (/convoy/control); it prints the figures (first paint,
camera latency) that this test shows with CONVOY_E2E_SHOW=1. Skipped without Chromium,
tools/dashboard_check/node_modules or web/dashboard/dist (scripts/setup.sh makes both)."""
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest

from e2e_util import CONVOY, REPO, free_port

CHECK_DIR = os.path.join(REPO, "tools", "dashboard_check")
DIST = os.path.join(REPO, "web", "dashboard", "dist")
CHROMIUM = os.environ.get("CONVOY_CHROMIUM", "/usr/bin/chromium")
EXAMPLE = os.path.join(REPO, "experiments", "city_traffic")
SIM_S = 60  # simulated seconds, a bound: the check needs about 10 s of the run, then Ctrl-C
SAMPLE_S = "5"  # wall seconds the check watches the page (road users moving, frames drawn)
SHOW = os.environ.get("CONVOY_E2E_SHOW") == "1"


def missing():
    if not os.access(CHROMIUM, os.X_OK):
        return "no Chromium at %s (apt-get install chromium)" % CHROMIUM
    if not shutil.which("node"):
        return "no node"
    if not os.path.isdir(os.path.join(CHECK_DIR, "node_modules", "puppeteer-core")):
        return "tools/dashboard_check/node_modules missing (scripts/setup.sh: npm ci there)"
    if not os.path.exists(os.path.join(DIST, "index.html")):
        return "web/dashboard/dist missing (scripts/setup.sh: npm ci && npm run build there)"
    return None



def wait_for_port(port, proc, seconds):
    deadline = time.time() + seconds
    while time.time() < deadline and proc.poll() is None:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return True
        except OSError:
            time.sleep(0.1)
    return False


def check(tmp, name, url, *flags):
    """Runs tools/dashboard_check; returns (exit code, its JSON figures, stderr)."""
    shot = os.path.join(tmp, name + ".png")
    r = subprocess.run(["node", os.path.join(CHECK_DIR, "check.mjs"), "--url", url,
                        "--screenshot", shot, "--seconds", SAMPLE_S, "--timeout", "120", *flags],
                       capture_output=True, text=True, timeout=300)
    try:
        figures = json.loads(r.stdout)
    except ValueError:
        figures = {}
    if SHOW:
        print("\n%s: %s\n%s" % (name, r.stdout, r.stderr))
    return r.returncode, figures, r.stderr


def stop(proc):
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


class Dashboard(unittest.TestCase):
    """One live run watched by the page, then its recording replayed in it."""

    @classmethod
    def setUpClass(cls):
        reason = missing()
        if reason:
            raise unittest.SkipTest(reason)
        cls.tmp = tempfile.mkdtemp(prefix="convoy_dashboard_")
        cls.run_dir = os.path.join(cls.tmp, "run")
        port = free_port()
        err = open(os.path.join(cls.tmp, "convoy.stderr"), "w")
        # The example's video recorder (camera.mp4 through ffmpeg, not what the page shows)
        # steps once, at t = 0, rather than at 30 Hz.
        with open(os.path.join(EXAMPLE, "simulation_config.json")) as f:
            names = [e["EngineName"] for e in json.load(f)["EngineConfigs"]]
        run = subprocess.Popen(
            [CONVOY, "run", "-c", "simulation_config.json", "-o", "SimulationTimeout=%d" % SIM_S,
             "-o", "EngineConfigs/%d/EngineTimestep=%d" % (names.index("recorder"), SIM_S),
             "--run-dir", cls.run_dir, "--live", str(port), "--record"],
            cwd=EXAMPLE, stdout=subprocess.DEVNULL, stderr=err)
        try:
            if not wait_for_port(port, run, 60):
                raise AssertionError("the live server did not listen on %d" % port)
            cls.live = check(cls.tmp, "live", "http://127.0.0.1:%d/" % port, "--expect-live",
                             "--expect-score", "--expect-control")
            # The page has been checked: Ctrl-C ends the run (its recording is kept), rather
            # than simulating the rest of SIM_S.
            cls.ended_by_us = run.poll() is None
            if cls.ended_by_us:
                run.send_signal(signal.SIGINT)
            cls.run_exit = run.wait(timeout=120)
        finally:
            stop(run)
            err.close()
        with open(os.path.join(cls.tmp, "convoy.stderr")) as f:
            cls.run_stderr = f.read()
        cls.replay = None
        view = subprocess.Popen([CONVOY, "view", cls.run_dir, "--port", str(free_port())],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            line = view.stdout.readline()
            m = re.search(r"view: (http://\S+)", line)
            cls.view_output = line
            if m:
                cls.replay = check(cls.tmp, "replay", m.group(1), "--expect-replay")
        finally:
            stop(view)
            view.stdout.close()

    @classmethod
    def tearDownClass(cls):
        if os.environ.get("CONVOY_E2E_KEEP") != "1":
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_run_ends_on_ctrl_c_with_its_summary_and_recording(self):
        self.assertTrue(self.ended_by_us, "the run ended before the page was checked: raise SIM_S")
        self.assertEqual(self.run_exit, 130, self.run_stderr[-3000:])
        with open(os.path.join(self.run_dir, "summary.json")) as f:
            summary = json.load(f)
        self.assertEqual(summary["exit_code"], 130)
        self.assertGreater(summary["sim_time_s"], 1.0)
        self.assertGreaterEqual(len(summary["live"]["clients"]), 1, summary["live"])
        self.assertTrue(os.path.exists(os.path.join(self.run_dir, "recording.mcap")))

    def test_the_live_page_draws_the_run(self):
        code, got, err = self.live
        self.assertEqual(code, 0, err)
        self.assertEqual(got["mode"], "live")
        self.assertEqual(got["pageErrors"], [])
        # 20 vehicle agents, 10 pedestrians, the ego (and SUMO's traffic).
        self.assertGreaterEqual(got["roadUsers"], 31, got)
        self.assertTrue(got["roadUsersMoved"])
        self.assertGreater(got["framesDrawnWhileSampled"], 0)
        self.assertIn("driving_score", got["score"])
        self.assertGreaterEqual(got["firstPaintMs"], 0)

    def test_the_camera_latency_is_measured(self):
        code, got, err = self.live
        self.assertEqual(code, 0, err)
        # Every drawn frame met its /convoy/frames message (same clock: positive, finite).
        self.assertGreater(got["latencySamples"], 0, got)
        self.assertGreater(got["frameLatencyMedianMs"], 0)
        self.assertLess(got["frameLatencyMedianMs"], 60000)

    def test_pause_step_and_resume_reach_the_run(self):
        code, got, err = self.live
        self.assertEqual(code, 0, err)
        control = got["control"]
        self.assertEqual(control["pausedAdvanceS"], 0)
        self.assertGreater(control["stepAdvanceS"], 0)
        self.assertTrue(control["resumed"])

    def test_the_recording_replays_in_the_page(self):
        if self.replay is None:
            self.fail("convoy view printed no URL: %r" % self.view_output)
        code, got, err = self.replay
        self.assertEqual(code, 0, err)
        self.assertEqual(got["mode"], "replay")
        self.assertGreaterEqual(got["roadUsers"], 31, got)
        self.assertTrue(got["roadUsersMoved"])
        self.assertGreater(got["framesDrawn"], 0)


if __name__ == "__main__":
    unittest.main()
