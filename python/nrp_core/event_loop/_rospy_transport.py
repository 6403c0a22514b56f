"""The graph's ROS node on Debian's rospy (NRP-Core 1.4's NRPROSProxy): what RosSubscriber
and RosPublisher nodes use when the config has "ROSNode".

    ros = RospyInterface("nrp_core")        # a master is started if none answers (local URI)
    graph = load_computational_graph(files, transports=Transports(ros=ros))
    EventLoop(graph, ros=ros).run(...)
    ros.shutdown()

Message types are rospy message classes; NRP-Core's spelling
(`from nrp_core.data.nrp_ros.std_msgs import String`) gives the same classes
(python/nrp_core/data/nrp_ros). rospy's threads only buffer what arrives; spin_once(), called
by the loop before each cycle, hands it to the input nodes on the loop's thread. A topic that
the master knows with another type is an error naming the topic and both types, at
subscribe/advertise time and (checked once a second) while the loop runs.
"""
import collections
import os
import signal
import socket
import subprocess
import threading
import time
import urllib.parse
import xmlrpc.client

from ._mqtt import _die_with_parent  # the master dies with a killed coordinator
from ._policies import ComputationalGraphError
from ._transport import ROSInterface

DEFAULT_MASTER = "http://localhost:11311"
QUEUE = 10          # messages kept per topic between two cycles (NRP-Core's queue size)
CHECK_PERIOD = 1.0  # s between checks of the topics' types on the master


def master_answers(uri, timeout=2.0):
    old = socket.getdefaulttimeout()
    socket.setdefaulttimeout(timeout)
    try:
        with xmlrpc.client.ServerProxy(uri) as proxy:
            proxy.getPid("/nrp_core")
        return True
    except (OSError, xmlrpc.client.Error):
        return False
    finally:
        socket.setdefaulttimeout(old)


def _is_local(host):
    return host in ("localhost", socket.gethostname(), "::1") or (host or "").startswith("127.")


def start_master(uri, log_path=None, wait=10.0):
    """Starts `rosmaster --core` for `uri` (a local one) in its own session; returns the
    process once the master answers. Raises ComputationalGraphError naming the URI."""
    u = urllib.parse.urlparse(uri)
    if not _is_local(u.hostname):
        raise ComputationalGraphError("no ROS master at %s (ROS_MASTER_URI), and it is not this "
                                      "machine's to start" % uri)
    log = open(log_path, "ab") if log_path else subprocess.DEVNULL
    try:
        proc = subprocess.Popen(["rosmaster", "--core", "-p", str(u.port or 11311)],
                                stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True, preexec_fn=_die_with_parent)
    except OSError as e:
        raise ComputationalGraphError("no ROS master at %s and none can be started: rosmaster: %s"
                                      % (uri, e.strerror)) from None
    finally:
        if log_path:
            log.close()
    deadline = time.monotonic() + wait
    while not master_answers(uri, 0.5):
        if proc.poll() is not None or time.monotonic() > deadline:
            _stop(proc)
            raise ComputationalGraphError("the ROS master started at %s does not answer%s"
                                          % (uri, " (see %s)" % log_path if log_path else ""))
        time.sleep(0.05)
    return proc


def _stop(proc):
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(3.0)
            return
        except subprocess.TimeoutExpired:
            continue


class RospyInterface(ROSInterface):
    """A rospy node for the graph (ROSInterface's methods; see _transport.py)."""

    def __init__(self, node_name="nrp_core", master_uri=None, start_master_if_needed=True,
                 master_log=None):
        try:
            import rospy
        except ImportError as e:
            raise ComputationalGraphError("ROSNode: rospy cannot be imported (%s); "
                                          "scripts/setup.sh installs it" % e) from None
        self._rospy = rospy
        self.master_uri = master_uri or os.environ.get("ROS_MASTER_URI") or DEFAULT_MASTER
        os.environ["ROS_MASTER_URI"] = self.master_uri
        self.master = None  # the rosmaster process this interface started
        if not master_answers(self.master_uri):
            if not start_master_if_needed:
                raise ComputationalGraphError("no ROS master at %s (ROS_MASTER_URI)"
                                              % self.master_uri)
            self.master = start_master(self.master_uri, master_log)
        if not rospy.core.is_initialized():
            rospy.init_node(node_name, anonymous=False, disable_signals=True)
        self.node_name = rospy.get_name()
        self._lock = threading.Lock()
        self._pending = collections.OrderedDict()  # topic -> deque of messages
        self._callbacks = {}                        # topic -> [callback]
        self._types = {}                            # topic -> message class
        self._subscribers, self._publishers = [], {}
        self._next_check = 0.0

    # ------------------------------------------------------------------------------ ROSInterface
    def subscribe(self, topic, msg_type, callback):
        self._check_type(topic, msg_type, "RosSubscriber")
        first = topic not in self._callbacks
        self._callbacks.setdefault(topic, []).append(callback)
        if first:
            self._pending[topic] = collections.deque(maxlen=QUEUE)
            self._subscribers.append(self._rospy.Subscriber(
                topic, msg_type, self._on_message, callback_args=topic, queue_size=QUEUE,
                tcp_nodelay=True))

    def advertise(self, topic, msg_type):
        """Creates the publisher at configure time, so that subscribers are connected when
        the first message goes (NRP-Core's OutputROSNode does the same)."""
        self._check_type(topic, msg_type, "RosPublisher")
        if topic not in self._publishers:
            self._publishers[topic] = self._rospy.Publisher(topic, msg_type, queue_size=QUEUE,
                                                            tcp_nodelay=True)
        return self._publishers[topic]

    def publish(self, topic, msg_type, msg):
        pub = self._publishers.get(topic) or self.advertise(topic, msg_type)
        pub.publish(msg)

    def spin_once(self):
        now = time.monotonic()
        if now >= self._next_check and self._types:
            self._next_check = now + CHECK_PERIOD
            for topic, msg_type in self._types.items():
                self._check_type(topic, msg_type, "ROS node")
        with self._lock:
            batches = [(t, list(q)) for t, q in self._pending.items() if q]
            for q in self._pending.values():
                q.clear()
        for topic, messages in batches:
            for cb in self._callbacks[topic]:
                for m in messages:
                    cb(m)

    def shutdown(self):
        """Ends the node (rospy allows no other in this process) and the master it started."""
        for s in self._subscribers:
            s.unregister()
        for p in self._publishers.values():
            p.unregister()
        self._subscribers, self._publishers = [], {}
        self._rospy.signal_shutdown("the graph's loop ended")  # the node, before its master
        if self.master is not None:
            _stop(self.master)
            self.master = None

    # -------------------------------------------------------------------------------- helpers
    def _on_message(self, msg, topic):  # rospy's thread
        with self._lock:
            self._pending[topic].append(msg)

    def _check_type(self, topic, msg_type, what):
        if not hasattr(msg_type, "_type"):
            raise ComputationalGraphError('%s "%s": %r is not a ROS message class'
                                          % (what, topic, msg_type))
        known = self._types.setdefault(topic, msg_type)
        if known._type != msg_type._type:
            raise ComputationalGraphError("topic %s is %s in this graph and %s in another node of "
                                          "it" % (topic, known._type, msg_type._type))
        try:
            published = dict(self._rospy.get_published_topics())
        except Exception as e:  # the master went away
            raise ComputationalGraphError("ROS master at %s: %s (checking topic %s)"
                                          % (self.master_uri, e, topic)) from None
        other = published.get(self._rospy.resolve_name(topic))
        if other is not None and other != msg_type._type:
            raise ComputationalGraphError("topic %s is %s on the master; %s expects %s"
                                          % (topic, other, what, msg_type._type))
