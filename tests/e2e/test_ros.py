"""End-to-end tests of the ROS 1 bridge (engines/ros_bridge) with rospy nodes.

Drive: a master on a free port (started by the test), the rospy driver of
  experiments/ros_drive (driver_node.py) and the experiment for 15 simulated s: the car
  follows the route, the driver answers each step once, and a second run (a new node) gives
  the same trajectory.csv byte for byte.
BadInput: an unreachable master that cannot be started (MasterURI on 10.255.255.1; a local
  one with StartMaster false), a node
  that never answers (SyncTimeout 2: the message names /convoy/control), a topic of the wrong
  type on the master. Each ends with a non-zero exit and the message.
Every test checks that nothing is left: the masters and nodes it started (their own process
groups, stopped in cleanups whatever happens), the engines, the master the bridge started.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_ros
"""

import csv
import json
import os
import signal
import subprocess
import time
import unittest
import xmlrpc.client

from e2e_util import BIN_DIR, CONVOY, E2ETestCase, free_port, pid_alive
from fault_util import describe, run_processes

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
EXP = os.path.join(REPO, "experiments", "ros_drive")
BRIDGE = os.path.join(BIN_DIR, "convoy-engine-ros_bridge")
GEN_PYTHON = os.path.join(os.path.dirname(BIN_DIR), "python")
EXIT_USER, EXIT_ENGINE = 2, 3
DRIVE_S = 15

# A rospy node that advertises /cmd_vel as TwistStamped (the bridge expects Twist).
WRONG_TYPE_NODE = """
import rospy
from geometry_msgs.msg import TwistStamped
rospy.init_node("wrong_type")
pub = rospy.Publisher("/cmd_vel", TwistStamped, queue_size=1, tcp_nodelay=True)
rospy.spin()
"""


def ros_available():
    try:
        subprocess.run(["/usr/bin/python3", "-c", "import rospy, message_filters"],
                       check=True, capture_output=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return False
    return True


def master_answers(uri):
    try:
        with xmlrpc.client.ServerProxy(uri) as master:
            master.getPid("/e2e")
        return True
    except OSError:
        return False


class RosTestCase(E2ETestCase):
    """Starts masters and nodes in their own process groups; stops them in cleanups."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(BRIDGE, os.X_OK):
            raise unittest.SkipTest("no %s (CONVOY_HAVE_ROS off?)" % BRIDGE)
        if not ros_available():
            raise unittest.SkipTest("rospy is not installed (scripts/setup.sh installs it)")

    def setUp(self):
        super().setUp()
        self.groups = []
        self.port = free_port()
        self.uri = "http://127.0.0.1:%d" % self.port
        self.env = dict(os.environ, ROS_MASTER_URI=self.uri, PYTHONDONTWRITEBYTECODE="1",
                        CONVOY_BIN_DIR=BIN_DIR,
                        PYTHONPATH=os.pathsep.join([os.path.join(REPO, "python"), GEN_PYTHON]))
        self.env.pop("ROS_HOSTNAME", None)
        self.env.pop("ROS_IP", None)
        self.addCleanup(self.stop_groups)

    def spawn(self, cmd, log_name):
        log = open(os.path.join(self.dir, log_name), "w")
        self.addCleanup(log.close)
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                             env=self.env, cwd=self.dir, start_new_session=True)
        self.groups.append(p)
        return p

    def stop(self, p):
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                return
            try:
                p.wait(3.0)
                return
            except subprocess.TimeoutExpired:
                continue

    def scan_engine_processes(self):
        """As E2ETestCase's, without the masters and nodes of the test's groups."""
        mine = {p.pid for p in self.groups}
        out = []
        for pid in super().scan_engine_processes():
            try:
                with open("/proc/%d/stat" % pid) as f:
                    st = f.read()
                if int(st[st.rfind(")") + 2:].split()[2]) in mine:
                    continue
            except (OSError, ValueError, IndexError):
                pass
            out.append(pid)
        return out

    def stop_groups(self):
        for p in reversed(self.groups):
            self.stop(p)

    def start_master(self):
        p = self.spawn(["rosmaster", "--core", "-p", str(self.port)], "rosmaster.log")
        deadline = time.monotonic() + 10.0
        while not master_answers(self.uri):
            self.assertIsNone(p.poll(), "rosmaster ended: %s" % self.read_file("rosmaster.log"))
            self.assertLess(time.monotonic(), deadline, "rosmaster does not answer")
            time.sleep(0.05)
        return p

    def read_file(self, name):
        with open(os.path.join(self.dir, name)) as f:
            return f.read()

    def run_env(self, args, timeout):
        """convoy run with the test's environment (ROS_MASTER_URI)."""
        cmd = [CONVOY, "run"] + list(args)
        t0 = time.monotonic()
        try:
            r = subprocess.run(cmd, cwd=self.dir, env=self.env, stdin=subprocess.DEVNULL,
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired as e:
            self.fail("convoy run did not end within %.0f s\n%s" % (timeout, e.stderr))
        r.wall = time.monotonic() - t0
        if os.environ.get("CONVOY_E2E_SHOW"):
            print("\n[%s] exit %d after %.1f s\n%s" % (self._testMethodName, r.returncode,
                                                     r.wall, r.stderr))
        return r

    def assertNothingLeft(self, run_dir, within=5.0):
        """No process of the run (engines, a master the bridge started) and no group the
        test started is alive (the test's own master excepted until its cleanup)."""
        deadline = time.monotonic() + within
        while True:
            left = run_processes(run_dir)
            if not left:
                return
            if time.monotonic() >= deadline:
                self.fail("processes left behind: %s" % [describe(p) for p in left])
            time.sleep(0.05)


class Drive(RosTestCase):
    def drive(self, name):
        """One run of experiments/ros_drive with a new driver node: (trajectory.csv bytes,
        summary, the driver's rows)."""
        run_dir = os.path.join(self.dir, name)
        os.makedirs(run_dir)
        node = self.spawn(["/usr/bin/python3", os.path.join(EXP, "driver_node.py"),
                           "_log:=" + os.path.join(run_dir, "driver.csv")], name + "_node.log")
        r = self.run_env(["-q", "-c", os.path.join(EXP, "simulation_config.json"),
                          "--run-dir", run_dir, "-o", "SimulationTimeout=%d" % DRIVE_S],
                         timeout=120)
        self.stop(node)  # SIGTERM: rospy shuts down and closes driver.csv
        self.assertFalse(pid_alive(node.pid), "the driver node outlived its SIGTERM")
        self.assertEqual(r.returncode, 0, "%s\n--- node ---\n%s" % (
            r.stderr, self.read_file(name + "_node.log")))
        self.assertNothingLeft(run_dir)
        with open(os.path.join(run_dir, "trajectory.csv"), "rb") as f:
            trajectory = f.read()
        with open(os.path.join(run_dir, "summary.json")) as f:
            summary = json.load(f)
        with open(os.path.join(run_dir, "driver.csv")) as f:
            rows = list(csv.DictReader(f))
        return trajectory, summary, rows

    def test_drives_the_route_in_lockstep_and_runs_are_identical(self):
        master = self.start_master()
        a, summary, rows = self.drive("run_a")
        b, _, rows_b = self.drive("run_b")
        self.assertEqual(a, b, "two runs' trajectories differ")
        self.assertEqual(rows, rows_b, "the driver's answers differ between the runs")
        # One answer per step, in order, stamped with the step's time: 0, 0.02, ...
        steps = round(DRIVE_S / 0.02)
        self.assertEqual(len(rows), steps)
        self.assertEqual([round(float(r["stamp"]) / 0.02) for r in rows], list(range(steps)))
        # The car follows the route: ~90 m at up to 7 m/s, on the lane.
        self.assertGreater(summary["distance_m"], 70.0)
        self.assertGreater(summary["waypoints_reached"], 35)
        self.assertLess(summary["cross_track_error_m"]["mean"], 0.3)
        self.assertLess(summary["cross_track_error_m"]["max"], 1.0)
        self.assertFalse(summary["lap_completed"])
        self.assertGreater(max(float(r["speed"]) for r in rows), 6.0)
        self.assertLess(max(float(r["speed"]) for r in rows), 7.5)
        self.assertIn("camera 736x480 rgb8", self.read_file("run_a_node.log"))
        self.stop(master)
        self.assertFalse(pid_alive(master.pid))


class BadInput(RosTestCase):
    def bridge_config(self, **ros):
        ros.setdefault("EngineTimestep", 0.02)
        engine = dict({"EngineType": "ros_bridge", "EngineName": "ros"}, **ros)
        self.write_config({"SimulationName": "e2e_ros", "SimulationTimeout": 1.0,
                           "EngineConfigs": [engine]})

    def run_bridge(self, timeout=40):
        return self.run_env(["-c", os.path.join(self.dir, "simulation_config.json"),
                             "--run-dir", self.run_dir], timeout)

    def check_error(self, r, *needles):
        self.assertIn(r.returncode, (EXIT_USER, EXIT_ENGINE), "%s\n%s" % (r.returncode, r.stderr))
        for n in needles:
            self.assertIn(n, r.stderr)
        self.assertEqual(r.stderr.count("error:"), 1, r.stderr)
        self.assertNothingLeft(self.run_dir)
        self.assertNoEngineLeft()

    def test_no_master_and_none_can_be_started(self):
        # Not this machine's: the bridge may not start one. (Where outgoing connections are
        # intercepted, something accepts the connection but gives no XML-RPC answer: the
        # message says so instead of "none can be started".)
        self.bridge_config(MasterURI="http://10.255.255.1:11311")
        r = self.run_bridge()
        self.check_error(r, "no ROS master at http://10.255.255.1:11311 (MasterURI)")
        if "accepts connections" not in r.stderr:
            self.assertIn("none can be started", r.stderr)
        self.assertLess(r.wall, 30.0)

    def test_no_master_and_start_master_false(self):
        self.bridge_config(StartMaster=False)  # the URI from ROS_MASTER_URI: a free port
        r = self.run_bridge()
        self.check_error(r, "no ROS master at %s (ROS_MASTER_URI)" % self.uri,
                         "none can be started", "StartMaster is false")
        self.assertFalse(master_answers(self.uri))

    def test_a_node_that_never_answers(self):
        # No master runs at the URI: the bridge starts one (and must stop it).
        self.assertFalse(master_answers(self.uri))
        self.bridge_config(SyncTimeout=2)
        r = self.run_bridge()
        self.check_error(r, "no message on /convoy/control for the step at t = 0",
                         "within 2", "nothing publishes /convoy/control")
        self.assertTrue(os.path.isfile(os.path.join(self.run_dir, "logs",
                                                    "ros_rosmaster.log")))
        self.assertFalse(master_answers(self.uri), "the bridge's master is still running")

    def test_a_topic_of_the_wrong_type(self):
        self.start_master()
        self.spawn(["/usr/bin/python3", "-c", WRONG_TYPE_NODE], "wrong_type.log")
        deadline = time.monotonic() + 15.0
        with xmlrpc.client.ServerProxy(self.uri) as master:
            while ["/cmd_vel", "geometry_msgs/TwistStamped"] not in \
                    master.getPublishedTopics("/e2e", "")[2]:
                self.assertLess(time.monotonic(), deadline, self.read_file("wrong_type.log"))
                time.sleep(0.05)
        self.bridge_config(SyncTimeout=2)
        r = self.run_bridge()
        self.check_error(r, "topic /cmd_vel is geometry_msgs/TwistStamped on the master; "
                            "the bridge expects geometry_msgs/Twist")


if __name__ == "__main__":
    unittest.main()
