"""The live server's control and HTTP side (docs/architecture.md "Live server"). Control (a
client in plain Python, live_ws.py): pause, step and resume over the protocol, the status,
metrics and infractions channels, the dashboard over HTTP on the same port. View:
`convoy view PATH` serving a run or campaign folder's files and the dashboard. The protocol
itself: test_live.py."""
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
import urllib.error
import urllib.request

from e2e_util import CONVOY, REPO, free_port
from live_ws import LiveClient
from test_live import CONFIG, convoy, read  # the wheeled-robot run both files watch

DASHBOARD = os.path.join(os.path.dirname(CONVOY), "..", "share", "convoy", "dashboard")


def http_get(url, headers=None, timeout=10):
    """(status, headers, body) of a GET; HTTP errors are answers too."""
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, dict(r.headers), r.read()
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read()


def raw_get(port, target):
    """The status code of a GET of `target` sent as is (urllib would normalise '..')."""
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(("GET %s HTTP/1.1\r\nHost: x\r\n\r\n" % target).encode())
        head = s.recv(200).decode(errors="replace")
    return int(head.split()[1])


def check_dashboard_root(test, status, headers, body):
    """GET / is the built dashboard's index.html, or else a text page saying how to build it."""
    index = os.path.join(DASHBOARD, "index.html")
    test.assertEqual(status, 200)
    if os.path.isfile(index):
        test.assertTrue(headers["Content-Type"].startswith("text/html"), headers)
        test.assertEqual(body, read(index))
    else:
        test.assertTrue(headers["Content-Type"].startswith("text/plain"), headers)
        test.assertIn(b"npm run build", body)


LIVE_TF = """\
\"\"\"Publishes metrics and an infraction to the viewers of a live run (test_live.py).\"\"\"
import convoy_live
from nrp_core import *
from convoy_bench.run_files import INFRACTIONS_TOPIC, publish_live, update_summary

_n = {"cycles": 0}


@SimulationTime(keyword="time_ns")
@TransceiverFunction("logger")
def live_metrics(time_ns):
    _n["cycles"] += 1
    if _n["cycles"] % 50 == 0:
        update_summary({"test_metric": _n["cycles"], "live_enabled": convoy_live.enabled()})
        publish_live(INFRACTIONS_TOPIC, {"time_s": time_ns * 1e-9, "kind": "test_event",
                                         "n": _n["cycles"]})
    return []
"""


class Control(unittest.TestCase):
    """A viewer pauses the run, lets one cycle through, sends bad commands and resumes, while
    a function publishes metrics; the same experiment without a viewer for comparison."""

    SIM = "16"   # simulated s: about 4 s of wall time

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="convoy_live_control_")
        exp = os.path.join(cls.tmp, "exp")
        shutil.copytree(os.path.dirname(CONFIG), exp)
        with open(os.path.join(exp, "live_tf.py"), "w") as f:
            f.write(LIVE_TF)
        cfg = json.loads(read(os.path.join(exp, "simulation_config.json")))
        cfg["DataPackProcessingFunctions"].append({"Name": "live_metrics", "FileName": "live_tf.py"})
        cls.config = os.path.join(exp, "simulation_config.json")
        with open(cls.config, "w") as f:
            json.dump(cfg, f, indent=1)

        def run(name, *extra):
            return [CONVOY, "run", "-c", cls.config, "-o", "SimulationTimeout=" + cls.SIM,
                    "--run-dir", os.path.join(cls.tmp, name), *extra]

        plain = subprocess.run(run("plain", "-q"), capture_output=True, text=True, timeout=90)
        assert plain.returncode == 0, plain.stderr
        port = free_port()
        proc = subprocess.Popen(run("live", "--live", str(port)), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        try:
            c = LiveClient(port, wait_s=30)
            cls.server_info = c.wait_for(lambda: c.server_info)
            for topic in ("/convoy/status", "/convoy/metrics", "/convoy/infractions"):
                c.subscribe(topic)
            c.advertise(1, "/convoy/control")
            # Once the loop runs (not before its first cycle, where a step does not advance).
            c.wait_for(lambda: c.times and c.times[-1] > 500_000_000, 30)
            c.publish(1, {"command": "pause"})
            cls.first_paused = c.wait_for(
                lambda: [m for m in c.messages("/convoy/status") if m["paused"]])
            time.sleep(0.5)
            cls.t1 = c.last_time()
            cls.status_before_hold = c.messages("/convoy/status")
            # The dashboard (or the page saying how to build it) on the same port, meanwhile.
            cls.root = http_get("http://127.0.0.1:%d/" % port)
            time.sleep(1.5)
            cls.t2 = c.last_time()
            before_step = len(c.messages("/convoy/status"))
            c.publish(1, {"command": "step"})
            cls.after_step = c.wait_for(lambda: c.messages("/convoy/status")[before_step:])
            cls.status_at_step = c.messages("/convoy/status")[:before_step]
            time.sleep(0.3)
            cls.t3 = c.last_time()
            c.publish(1, {"command": "rewind"})
            c.publish(9, {"command": "resume"})
            c.publish(1, b"{not json")
            c.wait_for(lambda: len(c.status) >= 3)
            c.publish(1, {"command": "resume"})
            cls.resumed = c.wait_for(
                lambda: [m for m in c.messages("/convoy/status") if not m["paused"]][1:])
            cls.out, cls.err = proc.communicate(timeout=90)
            cls.rc = proc.returncode
            c.wait_for(lambda: c.closed, 5)
            cls.errors = [m for m in c.status if m.get("level") == 2]
            cls.metrics = c.messages("/convoy/metrics")
            cls.infractions = c.messages("/convoy/infractions")
            cls.status = c.messages("/convoy/status")
            c.close()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        cls.summary = json.loads(read(os.path.join(cls.tmp, "live", "summary.json")))
        cls.plain_summary = json.loads(read(os.path.join(cls.tmp, "plain", "summary.json")))

    @classmethod
    def tearDownClass(cls):
        if os.environ.get("CONVOY_E2E_KEEP") != "1":
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_server_offers_client_publishing(self):
        self.assertIn("clientPublish", self.server_info["capabilities"])
        self.assertEqual(self.server_info["supportedEncodings"], ["json"])

    def test_a_pause_holds_the_simulated_time_and_the_status_says_so(self):
        self.assertTrue(self.first_paused, self.status_before_hold)
        self.assertEqual(self.status_before_hold[0], {"paused": False, "time_ns": 0})
        self.assertIsNotNone(self.t1)
        self.assertEqual(self.t2, self.t1, "the simulated time went on while paused")
        self.assertTrue(self.status_at_step[-1]["paused"])
        self.assertLessEqual(self.status_at_step[-1]["time_ns"], self.t2)
        self.assertGreaterEqual(self.summary["live"]["paused_s"], 1.5)

    def test_a_step_runs_one_cycle_then_holds_again(self):
        self.assertTrue(self.after_step, "no status after the step")
        stepped = self.after_step[0]
        self.assertTrue(stepped["paused"])
        # Both engines step 20 ms: one cycle.
        self.assertEqual(stepped["time_ns"] - self.status_at_step[-1]["time_ns"], 20_000_000)
        self.assertGreater(self.t3, self.t2)
        self.assertLessEqual(self.t3 - self.t2, 40_000_000)

    def test_the_run_ends_normally_after_resume(self):
        self.assertTrue(self.resumed, self.status)
        self.assertEqual(self.rc, 0, self.err)
        self.assertEqual(self.summary["exit_code"], 0)
        self.assertAlmostEqual(self.summary["sim_time_s"], float(self.SIM))
        self.assertEqual(self.summary["live"]["control_commands"], 3)   # pause, step, resume
        # The pause is not the loop's time.
        self.assertLess(self.summary["loop_wall_s"], self.summary["wall_s"] - 1.5)
        # Nothing the run writes depends on the viewer.
        for name in ("trajectory.csv", "camera.png"):
            self.assertEqual(read(os.path.join(self.tmp, "plain", name)),
                             read(os.path.join(self.tmp, "live", name)), name)

    def test_bad_commands_get_status_errors(self):
        text = " | ".join(m["message"] for m in self.errors)
        self.assertEqual(len(self.errors), 3, text)
        self.assertIn("rewind", text)
        self.assertIn("not advertised", text)
        self.assertIn("not JSON", text)
        self.assertEqual(self.summary["live"]["clients"][0]["errors"], 3)

    def test_functions_publish_metrics_and_infractions(self):
        self.assertTrue(self.metrics, "no /convoy/metrics message")
        last = self.metrics[-1]
        self.assertEqual(last["test_metric"], self.plain_summary["test_metric"])
        self.assertIs(last["live_enabled"], True)
        self.assertIn("time_ns", last)
        self.assertEqual(len(self.infractions), self.plain_summary["test_metric"] // 50)
        first = self.infractions[0]
        self.assertEqual((first["kind"], first["n"]), ("test_event", 50))
        self.assertAlmostEqual(first["time_s"] * 1e9, first["time_ns"], delta=1)
        # Without --live, publishing does nothing and the summary is the same.
        self.assertIs(self.plain_summary["live_enabled"], False)
        self.assertEqual(self.summary["test_metric"], self.plain_summary["test_metric"])
        self.assertGreater(self.summary["live"]["metrics_published"], 0)

    def test_the_dashboard_is_served_on_the_live_port(self):
        check_dashboard_root(self, *self.root)
        self.assertIn("live: dashboard at http://127.0.0.1:", self.err)


class PausedInterrupt(unittest.TestCase):
    """Ctrl-C ends a run that a viewer has paused, as it ends a running one."""

    def test_ctrl_c_ends_a_paused_run(self):
        tmp = tempfile.mkdtemp(prefix="convoy_live_int_")
        self.addCleanup(shutil.rmtree, tmp, True)
        port = free_port()
        proc = subprocess.Popen(convoy(tmp, "run", "--live", str(port), "-o",
                                       "SimulationTimeout=60"),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: proc.poll() is None and proc.kill())
        c = LiveClient(port, wait_s=30)
        self.addCleanup(c.close)
        c.subscribe("/convoy/status")
        c.advertise(1, "/convoy/control")
        c.wait_for(lambda: c.times and c.times[-1] > 300_000_000, 30)
        c.publish(1, {"command": "pause"})
        self.assertTrue(c.wait_for(lambda: [m for m in c.messages("/convoy/status") if m["paused"]]))
        time.sleep(0.5)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=20)
        self.assertEqual(proc.returncode, 130, err)
        summary = json.loads(read(os.path.join(tmp, "run", "summary.json")))
        self.assertEqual(summary["exit_code"], 130)
        self.assertLess(summary["sim_time_s"], 60)


class ScenarioScore(unittest.TestCase):
    """A scenario run's live score (convoy_bench/metrics_tf.py) reaches the viewers:
    /convoy/metrics carries the summary's fields, /convoy/infractions each infraction once.
    Its first 14 simulated seconds: two min_speed infractions, then SimulationTimeout's."""

    def test_the_score_and_its_infractions_are_published(self):
        tmp = tempfile.mkdtemp(prefix="convoy_live_score_")
        self.addCleanup(shutil.rmtree, tmp, True)
        port = free_port()
        run_dir = os.path.join(tmp, "run")
        proc = subprocess.Popen([CONVOY, "run", "-q", "--scenario",
                                 os.path.join(REPO, "benchmarks", "suite", "cut_in.xosc"),
                                 "--run-dir", run_dir, "--live", str(port),
                                 "-o", "SimulationTimeout=14"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: proc.poll() is None and proc.kill())
        c = LiveClient(port, wait_s=60)
        self.addCleanup(c.close)
        c.subscribe("/convoy/metrics")
        c.subscribe("/convoy/infractions")
        _, err = proc.communicate(timeout=300)
        self.assertEqual(proc.returncode, 0, err)
        c.wait_for(lambda: c.closed, 5)
        summary = json.loads(read(os.path.join(run_dir, "summary.json")))
        metrics = c.messages("/convoy/metrics")
        self.assertTrue(metrics)
        for key in ("driving_score", "route_completion", "infraction_penalty", "nuplan_score"):
            self.assertEqual(metrics[-1][key], summary[key], key)
        got = sorted((i["kind"], i["time_s"]) for i in c.messages("/convoy/infractions"))
        want = sorted((i["kind"], i["time"]) for i in summary["infractions"])
        self.assertGreaterEqual(len(want), 2, "nothing to compare: no infractions")
        self.assertEqual(got, want)


class View(unittest.TestCase):
    """`convoy view PATH`: the dashboard and PATH's files over HTTP, until Ctrl-C."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="convoy_view_")
        r = subprocess.run(convoy(cls.tmp, "run", "-q", "--record", "-o", "SimulationTimeout=1"),
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, r.stderr
        cls.run_dir = os.path.join(cls.tmp, "run")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def view(self, path, *extra):
        """Starts `convoy view`; (process, the URL it printed)."""
        port = free_port()
        p = subprocess.Popen([CONVOY, "view", path, "--port", str(port), *extra],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: p.poll() is None and p.kill())
        line = p.stdout.readline()
        m = re.match(r"view: (http://127\.0\.0\.1:%d(/\S*))$" % port, line.strip())
        self.assertIsNotNone(m, "printed %r; stderr %s" % (line, p.stderr.read() if p.poll() is not None else ""))
        return p, port, m.group(1), m.group(2)

    def stop(self, p):
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=10)
        self.assertEqual(p.returncode, 0, err)

    def test_a_run_folder(self):
        p, port, url, target = self.view(self.run_dir)
        self.assertEqual(target, "/?mcap=files/recording.mcap")
        base = "http://127.0.0.1:%d" % port
        check_dashboard_root(self, *http_get(base + "/"))
        mcap = read(os.path.join(self.run_dir, "recording.mcap"))
        status, headers, body = http_get(base + "/files/recording.mcap")
        self.assertEqual((status, headers["Content-Type"]), (200, "application/octet-stream"))
        self.assertEqual(int(headers["Content-Length"]), len(mcap))
        self.assertEqual(body, mcap)
        status, headers, body = http_get(base + "/files/recording.mcap", {"Range": "bytes=0-7"})
        self.assertEqual((status, body), (206, mcap[:8]))
        self.assertEqual(headers["Content-Range"], "bytes 0-7/%d" % len(mcap))
        status, headers, body = http_get(base + "/files/summary.json?x=1")
        self.assertEqual((status, headers["Content-Type"]), (200, "application/json"))
        self.assertEqual(json.loads(body)["exit_code"], 0)
        self.assertEqual(http_get(base + "/files/steps.csv")[1]["Content-Type"],
                         "text/csv; charset=utf-8")
        self.assertEqual(http_get(base + "/files/nothing.json")[0], 404)
        for bad in ("/files/../run/summary.json", "/files/%2e%2e/%2e%2e/etc/passwd",
                    "/files/..%2f..%2fetc%2fpasswd", "/../../etc/passwd", "/files//etc/passwd"):
            self.assertEqual(raw_get(port, bad), 404, bad)
        self.stop(p)

    def test_a_recording_and_a_campaign_folder(self):
        p, port, url, target = self.view(os.path.join(self.run_dir, "recording.mcap"))
        self.assertEqual(target, "/?mcap=files/recording.mcap")
        self.stop(p)
        campaign = os.path.join(self.tmp, "campaign")
        os.makedirs(os.path.join(campaign, "runs"))
        shutil.copytree(self.run_dir, os.path.join(campaign, "runs", "a__s0__clear"))
        with open(os.path.join(campaign, "report.html"), "w") as f:
            f.write("<html>report</html>")
        p, port, url, target = self.view(campaign)
        self.assertEqual(target, "/files/report.html")
        self.assertEqual(http_get(url)[2], b"<html>report</html>")
        status, _, body = http_get("http://127.0.0.1:%d/files/runs/a__s0__clear/recording.mcap" % port)
        self.assertEqual((status, body), (200, read(os.path.join(self.run_dir, "recording.mcap"))))
        self.stop(p)

    def test_a_bad_path(self):
        missing = os.path.join(self.tmp, "no such run")
        r = subprocess.run([CONVOY, "view", missing], capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(missing, r.stderr)
        self.assertIn("no such file or folder", r.stderr)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)
        self.assertEqual(r.stdout, "")
        r = subprocess.run([CONVOY, "view"], capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2, r.stderr)

    def test_a_port_in_use(self):
        with socket.socket() as busy:
            busy.bind(("127.0.0.1", 0))
            busy.listen(1)
            port = busy.getsockname()[1]
            r = subprocess.run([CONVOY, "view", self.run_dir, "--port", str(port)],
                               capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("error: convoy view 127.0.0.1:%d: cannot listen there" % port, r.stderr)
        self.assertIn("in use", r.stderr)
        self.assertIn("--port", r.stderr)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)

    def test_a_non_loopback_host_needs_insecure(self):
        r = subprocess.run([CONVOY, "view", self.run_dir, "--host", "0.0.0.0"],
                           capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--insecure", r.stderr)


if __name__ == "__main__":
    unittest.main()
