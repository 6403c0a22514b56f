"""End-to-end tests of the graph's ROS nodes (@RosSubscriber / @RosPublisher, NRP-Core 1.4's
names) under "SimulationLoop": "EventLoop" and in the FTILoop's "cg" graph, with "ROSNode".

The experiment starts the ROS master: ROS_MASTER_URI points at a free local port no master
answers on, so the coordinator starts `rosmaster --core` there (logs/rosmaster.log) and stops
it at the end. A rospy node (an ExternalProcess, Debian's /usr/bin/python3) publishes
"ping N" on /ext_in; the graph answers "pong ping N" on /graph_out (with engine src's time when
there is an engine: EventLoop with EngineConfigs, FTILoop cg); the node writes what it got to
got.txt. A killed coordinator leaves no master, node or engine.
BadRos: a RosSubscriber topic that the master knows with another type: one message naming the
topic and both types, exit 2, nothing left (master, node, engines).

Run with Debian's /usr/bin/python3 -m unittest test_event_loop_ros."""

import os
import subprocess
import textwrap
import time
import unittest

from e2e_util import NRPCORESIM, E2ETestCase, engine_script, free_port

# Publishes "ping N" on /ext_in every 50 ms until 3 answers came on /graph_out (or 20 s).
ECHO_NODE = textwrap.dedent("""\
    import os, time, rospy
    from std_msgs.msg import String
    rospy.init_node("echo", disable_signals=True)
    got = []
    rospy.Subscriber("/graph_out", String, lambda m: got.append(m.data), tcp_nodelay=True)
    pub = rospy.Publisher("/ext_in", String, queue_size=10, tcp_nodelay=True)
    n, end = 0, time.monotonic() + 20
    while len(got) < 3 and time.monotonic() < end:
        pub.publish(String(data="ping %d" % n))
        n += 1
        time.sleep(0.05)
    with open("got.txt", "w") as f:
        f.write("\\n".join(got))
    """)

# Advertises /ext_in as std_msgs/Bool, then waits to be stopped.
BOOL_NODE = textwrap.dedent("""\
    import time, rospy
    from std_msgs.msg import Bool
    rospy.init_node("bool_pub", disable_signals=True)
    pub = rospy.Publisher("/ext_in", Bool, queue_size=1)
    time.sleep(60)
    """)

GRAPH = textwrap.dedent("""\
    from nrp_core.event_loop import *
    from nrp_core.data.nrp_ros.std_msgs import String

    @RosSubscriber(keyword="ping", address="/ext_in", type=String)
    @RosPublisher(keyword="pong", address="/graph_out", type=String)
    @FunctionalNode(name="answer", outputs=["pong"])
    def answer(ping):
        if ping is None:
            return [None]
        return [String(data="pong " + ping.data)]
    """)

# The same answer, with engine src's time in it (the FTILoop's graph).
ENGINE_GRAPH = GRAPH.replace('@FunctionalNode(name="answer", outputs=["pong"])\n'
                             'def answer(ping):',
                             '@FromEngine(keyword="src", address="/src/src_dp")\n'
                             '@FunctionalNode(name="answer", outputs=["pong"])\n'
                             'def answer(ping, src):').replace(
    'String(data="pong " + ping.data)', 'String(data="pong %s t=%d" % (ping.data, '
                                         '-1 if src is None else src.data["time"]))')


def ros_available():
    try:
        subprocess.run(["/usr/bin/python3", "-c", "import rospy"], check=True,
                       capture_output=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return False
    return any(os.access(os.path.join(d, "rosmaster"), os.X_OK)
               for d in os.environ.get("PATH", "").split(os.pathsep))


@unittest.skipUnless(ros_available(), "rospy or rosmaster not installed (scripts/setup.sh)")
class RosCase(E2ETestCase):
    def setUp(self):
        super().setUp()
        self.uri = "http://127.0.0.1:%d" % free_port()
        self._env = {k: os.environ.get(k) for k in ("ROS_MASTER_URI", "ROS_HOSTNAME", "ROS_IP")}
        os.environ["ROS_MASTER_URI"] = self.uri  # the coordinator and its processes inherit it
        os.environ.pop("ROS_HOSTNAME", None)
        os.environ.pop("ROS_IP", None)

    def tearDown(self):
        for k, v in self._env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        super().tearDown()

    def experiment(self, graph, node, **cfg):
        self.write("graph.py", graph)
        self.write("node.py", node)
        config = {"SimulationName": "el_ros", "ROSNode": {"NodeName": "convoy_graph"},
                  "ComputationalGraph": ["graph.py"], "EngineConfigs": [],
                  "ExternalProcesses": [{"ProcCmd": "/usr/bin/python3",
                                         "ProcStartParams": ["node.py"]}]}
        config.update(cfg)
        self.write_config(config)

    def got(self):
        path = os.path.join(self.dir, "got.txt")
        self.assertTrue(os.path.isfile(path), "the rospy node never got 3 answers")
        with open(path) as f:
            return f.read().splitlines()

    def assertMasterStarted(self, r):
        log = os.path.join(self.run_dir, "logs", "rosmaster.log")
        self.assertTrue(os.path.isfile(log), r)  # the experiment started it
        self.assertIn("ROS: started rosmaster on %s for the run" % self.uri, r.stderr)
        self.assertNoEngineLeft(within=5.0)        # ... and stopped it, with the node


class EventLoopRos(RosCase):
    def test_ros_round_trip_in_the_event_loop_with_an_engine(self):
        self.write("src.py", engine_script("src", run_loop="time.sleep(0.001)"))
        self.experiment(ENGINE_GRAPH, ECHO_NODE, SimulationLoop="EventLoop",
                        EventLoop={"Timestep": 0.02, "Timeout": 6},
                        EngineConfigs=[{"EngineType": "python_json", "EngineName": "src",
                                        "PythonFileName": "src.py", "EngineTimestep": 0.01}])
        r = self.run_convoy(binary=NRPCORESIM, timeout=60)
        self.assertExit(r, 0)
        got = self.got()
        self.assertGreaterEqual(len(got), 3, got)  # a kept ping may be answered again
        times = []
        for line in got:
            self.assertRegex(line, r"^pong ping \d+ t=\d+$")  # src's time: the engine ran
            times.append(int(line.rsplit("=", 1)[1]))
        self.assertEqual(times, sorted(times))
        self.assertStderrHas(r, "the engines' FTILoop beside it")
        self.assertNotIn("ROSNode is not supported", r.stderr)
        self.assertMasterStarted(r)

    def test_killed_coordinator_leaves_nothing(self):
        self.experiment(GRAPH, ECHO_NODE, SimulationLoop="EventLoop",
                        EventLoop={"Timestep": 0.02, "Timeout": 0})
        p = self.start([], binary=NRPCORESIM)
        deadline = time.monotonic() + 30
        while not os.path.isfile(os.path.join(self.dir, "got.txt")):
            self.assertLess(time.monotonic(), deadline, "no round trip")
            time.sleep(0.05)
        self.assertTrue(self.scan_engine_processes())  # the master at least
        p.kill()
        p.communicate()
        self.assertNoEngineLeft(within=5.0)

    def test_ros_round_trip_in_the_fti_loop_graph(self):
        # Each step of src sleeps 5 ms: 10 simulated s take about 6 s, time for rospy.
        self.write("src.py", engine_script("src", run_loop="time.sleep(0.005)"))
        self.experiment(ENGINE_GRAPH, ECHO_NODE, SimulationLoop="FTILoop",
                        DataPackProcessor="cg", SimulationTimeout=10,
                        EngineConfigs=[{"EngineType": "python_json", "EngineName": "src",
                                        "PythonFileName": "src.py", "EngineTimestep": 0.01}])
        r = self.run_convoy(timeout=60)
        self.assertExit(r, 0)
        got = self.got()
        self.assertGreaterEqual(len(got), 3, got)  # a kept ping may be answered again
        for line in got:
            self.assertRegex(line, r"^pong ping \d+ t=\d+$")
        self.assertNotIn("ROSNode is not supported", r.stderr)
        self.assertMasterStarted(r)


class BadRos(RosCase):
    def test_unknown_input_stops_the_started_master(self):
        graph = GRAPH.replace("@FunctionalNode", '@FromFunctionalNode(keyword="x", '
                              'address="/nowhere/out")\n@FunctionalNode')
        graph = graph.replace("def answer(ping):", "def answer(ping, x):")
        self.experiment(graph, ECHO_NODE, SimulationLoop="EventLoop",
                        EventLoop={"Timestep": 0.02, "Timeout": 5})
        r = self.run_convoy(binary=NRPCORESIM, timeout=60)
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "nowhere", '"answer"')
        self.assertNotIn("started external process", r.stderr)
        self.assertMasterStarted(r)

    def test_topic_of_the_wrong_type(self):
        # The Bool publisher must be on the master before the graph subscribes: a master of
        # the test's, so that the node can start first.
        master = subprocess.Popen(["rosmaster", "--core", "-p", self.uri.rsplit(":", 1)[1]],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  start_new_session=True)
        self.write("bool_node.py", BOOL_NODE)
        node = subprocess.Popen(["/usr/bin/python3", "bool_node.py"], cwd=self.dir,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(2.5)  # rospy registers its publisher
            self.experiment(GRAPH, "", SimulationLoop="EventLoop", ExternalProcesses=[],
                            EventLoop={"Timestep": 0.02, "Timeout": 5})
            r = self.run_convoy(binary=NRPCORESIM, timeout=60)
        finally:
            node.kill()
            node.wait()
            master.terminate()
            master.wait(10)
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "/ext_in", "std_msgs/Bool", "std_msgs/String")
        self.assertNoEngineLeft(within=5.0)


if __name__ == "__main__":
    unittest.main()
