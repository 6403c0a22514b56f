"""The graph's ROS node (RospyInterface) with a real rosmaster and rospy nodes: the interface
starts a master on a free port when none answers; RosSubscriber -> functional node ->
RosPublisher round trips with another rospy process, in NRP-Core's spelling
(nrp_core.data.nrp_ros.std_msgs); a topic of the wrong type is an error naming it; the master
is stopped at the end. rospy allows one node per process: one interface for the module."""
import os
import socket
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

from nrp_core.event_loop import (ComputationalGraphError, EventLoop, RospyInterface, Transports,
                                 load_computational_graph)

HEADER = "from nrp_core.event_loop import *\nfrom nrp_core.data.nrp_ros.std_msgs import String\n"

# Publishes "ping N" on /ext_out until it has received 3 messages on /graph_out, which it
# prints; ends after 15 s in any case.
ECHO_NODE = """
import sys, time, rospy
from std_msgs.msg import String
rospy.init_node("echo", disable_signals=True)
got = []
rospy.Subscriber("/graph_out", String, lambda m: got.append(m.data), tcp_nodelay=True)
pub = rospy.Publisher("/ext_out", String, queue_size=10, tcp_nodelay=True)
n, end = 0, time.monotonic() + 15
while len(got) < 3 and time.monotonic() < end:
    pub.publish(String(data="ping %d" % n))
    n += 1
    time.sleep(0.05)
print("\\n".join(got), flush=True)
"""

# Advertises /typed as std_msgs/Bool and waits.
BOOL_NODE = """
import time, rospy
from std_msgs.msg import Bool
rospy.init_node("bool_pub", disable_signals=True)
pub = rospy.Publisher("/typed", Bool, queue_size=1)
time.sleep(30)
"""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ros_available():
    try:
        import rospy  # noqa: F401
    except ImportError:
        return False
    return any(os.access(os.path.join(d, "rosmaster"), os.X_OK)
               for d in os.environ.get("PATH", "").split(os.pathsep))


@unittest.skipUnless(ros_available(), "rospy or rosmaster not installed (scripts/setup.sh)")
class RosGraph(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.uri = "http://127.0.0.1:%d" % free_port()
        os.environ["ROS_MASTER_URI"] = cls.uri
        os.environ.pop("ROS_HOSTNAME", None)
        os.environ.pop("ROS_IP", None)
        cls.ros = RospyInterface("convoy_graph_test",
                                 master_log=os.path.join(cls.tmp.name, "rosmaster.log"))

    @classmethod
    def tearDownClass(cls):
        master = cls.ros.master
        cls.ros.shutdown()
        cls.tmp.cleanup()
        if master is not None:
            assert master.poll() is not None, "the master is still running"

    def spawn(self, source):
        p = subprocess.Popen([sys.executable, "-c", textwrap.dedent(source)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True, env=dict(os.environ))
        self.addCleanup(self._end, p)
        return p

    @staticmethod
    def _end(p):
        if p.poll() is None:
            p.kill()
        p.communicate()

    def load(self, source, name):
        path = os.path.join(self.tmp.name, name)
        with open(path, "w") as f:
            f.write(HEADER + textwrap.dedent(source))
        return load_computational_graph([name], "AllNodes", Transports(ros=self.ros),
                                        self.tmp.name)

    def test_master_started(self):
        self.assertIsNotNone(self.ros.master, "a master answered at a free port?")
        self.assertEqual(self.ros.node_name, "/convoy_graph_test")

    def test_round_trip(self):
        graph = self.load("""
            @RosSubscriber(keyword="msg", address="/ext_out", type=String)
            @RosPublisher(keyword="out", address="/graph_out", type=String)
            @FunctionalNode(name="upper", outputs=["out"])
            def upper(msg):
                seen.append(msg.data)
                return [String(data=msg.data.upper())]
            seen = []
            """, "round_trip.py")
        echo = self.spawn(ECHO_NODE)
        loop = EventLoop(graph, timestep=0.02, ros=self.ros)
        end = time.monotonic() + 20
        while echo.poll() is None and time.monotonic() < end:
            loop.run_once(0)
            time.sleep(0.02)
        out, err = echo.communicate(timeout=10)
        lines = out.split()
        got = [line for line in out.splitlines() if line]
        self.assertEqual(len(got), 3, "echo node got: %r\n%s" % (out, err))
        for line in got:
            self.assertRegex(line, r"^PING \d+$")
        seen = graph.nodes["upper"].function.__globals__["seen"]
        self.assertTrue(set(g.lower() for g in got) <= set(seen), (got, seen, lines))

    def test_wrong_type_names_topic(self):
        p = self.spawn(BOOL_NODE)
        import rospy
        end = time.monotonic() + 15
        while "/typed" not in dict(rospy.get_published_topics()):
            self.assertIsNone(p.poll(), p.stderr.read() if p.poll() is not None else "")
            self.assertLess(time.monotonic(), end, "bool_pub never advertised /typed")
            time.sleep(0.05)
        with self.assertRaisesRegex(ComputationalGraphError,
                                    "topic /typed is std_msgs/Bool on the master; "
                                    "RosSubscriber expects std_msgs/String"):
            self.load("""
                @RosSubscriber(keyword="msg", address="/typed", type=String)
                @FunctionalNode(name="f", outputs=[])
                def f(msg):
                    pass
                """, "wrong_type.py")

    def test_not_a_message_class(self):
        with self.assertRaisesRegex(ComputationalGraphError, "ROS message type"):
            self.load("""
                @RosSubscriber(keyword="msg", address="/x", type=dict)
                @FunctionalNode(name="g", outputs=[])
                def g(msg):
                    pass
                """, "not_msg.py")


if __name__ == "__main__":
    unittest.main()
