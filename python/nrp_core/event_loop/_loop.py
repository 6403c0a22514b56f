"""Running a graph: NRP-Core 1.4's EventLoop (a cycle every Timestep, real time, until
Timeout), the FTILoop's "cg" DataPackProcessor step, and the EventLoopInterface base class
that NRP-Core's Python module exports for asynchronous engines.
"""
import abc
import logging
import threading
import time

from ._graph import CLOCK_NODE, ITERATION_NODE

_log = logging.getLogger("nrp_core.event_loop")


def _time_nodes(graph):
    return graph.time_node(CLOCK_NODE), graph.time_node(ITERATION_NODE)


class EventLoop:
    """Runs `graph` every `timestep` seconds (truncated to whole ms, as NRP-Core does) on the
    calling thread. Each cycle: ROS callbacks (ros.spin_once()), the Clock node gets the ms
    since the loop started, the Iteration node the cycle number (0 first), graph.compute().
    With engines, the coordinator runs them in an FTILoop on another thread and moves their
    datapacks with an EngineLink under graph.lock."""

    def __init__(self, graph, timestep=0.01, timestep_warn_threshold=0.001, ros=None,
                 clock=time.monotonic, sleep=time.sleep):
        self.graph = graph
        self.timestep_ms = int(1000 * timestep)
        self.warn_threshold_ms = 1000 * timestep_warn_threshold
        self.ros = ros
        self.iterations = 0
        self._clock = clock
        self._sleep = sleep
        self._stop = threading.Event()
        self._clock_node, self._iteration_node = _time_nodes(graph)

    def run_once(self, elapsed_ms):
        """One cycle, `elapsed_ms` after the loop started."""
        if self.ros is not None:
            self.ros.spin_once()
        if self._clock_node is not None:
            self._clock_node.update(elapsed_ms)
        if self._iteration_node is not None:
            self._iteration_node.update(self.iterations)
        self.graph.compute()
        self.iterations += 1

    def run(self, timeout=0.0, should_stop=None):
        """Runs cycles until `timeout` seconds have passed (0: until stop(), or until
        should_stop() is true: checked before each cycle)."""
        self._stop.clear()
        start = last = self._clock()
        while not self._stop.is_set() and not (should_stop and should_stop()):
            now = self._clock()
            elapsed_ms = int((now - start) * 1000)
            if timeout and now - start >= timeout:
                break
            if (now - last) * 1000 > self.timestep_ms + self.warn_threshold_ms and now != start:
                _log.warning("Event Loop can't run at the target frequency. Actual step duration: "
                             "%.4f (s). Target step duration: %.3f (s).", now - last,
                             self.timestep_ms / 1000.0)
            last = now
            self.run_once(elapsed_ms)
            wait = now + self.timestep_ms / 1000.0 - self._clock()
            if wait > 0:
                self._sleep(wait)

    def stop(self):
        self._stop.set()


class FTIStep:
    """The FTILoop's "cg" DataPackProcessor (NRP-Core's ComputationalGraphHandle, not in
    slave mode): load the graph with fti_loop=True, then call step() once per loop step with
    the engines that finished it."""

    def __init__(self, graph, link, ros=None):
        self.graph = graph
        self.link = link
        self.ros = ros
        self._clock_node, self._iteration_node = _time_nodes(graph)

    def step(self, source, sink, engines, sim_time_ms, iteration):
        """Reads the engines' datapacks, runs one OutputDriven cycle (ToEngine nodes of
        `engines` due; Clock = simulated ms), sends the ToEngine datapacks."""
        with self.graph.lock:
            self.link.update_from_engines(source, engines)
            if self.ros is not None:
                self.ros.spin_once()
            for engine in engines:
                node = self.link.outputs.get(engine)
                if node is not None:
                    node.set_do_compute(True)
            if self._clock_node is not None:
                self._clock_node.update(sim_time_ms)
            if self._iteration_node is not None:
                self._iteration_node.update(iteration)
            self.graph.compute()
            self.link.send_to_engines(sink, engines)


class EventLoopInterface(abc.ABC):
    """NRP-Core's base of Python event loops (the asynchronous engines): subclasses define
    _initialize_cb, _run_loop_cb and _shutdown_cb; run_loop(timeout) calls _run_loop_cb every
    timestep seconds until timeout (0: until stop_loop())."""

    def __init__(self, timestep, timestep_thres):
        self._timestep = timestep
        self._timestep_thres = timestep_thres
        self._is_initialized = False
        self._stop_request = threading.Event()
        self._run_lock = threading.Lock()

    def run_loop_once(self, start_time):
        self._run_loop_cb()
        left = self._timestep - (time.perf_counter() - start_time)
        if left > 0:
            time.sleep(left)

    def run_loop(self, timeout):
        if not self._is_initialized:
            _log.debug("EventLoop is not initialized, runLoop can't be called")
            return
        with self._run_lock:
            start = previous = time.perf_counter()
            while not self._stop_request.is_set():
                now = time.perf_counter()
                if timeout and now - start >= timeout:
                    break
                if now - previous > self._timestep + self._timestep_thres:
                    _log.warning("Event Loop can't run at the target frequency. Actual step "
                                 "duration: %s (s). Target step duration: %s (s).",
                                 now - previous, self._timestep)
                self.run_loop_once(now)
                previous = now
            self._stop_request.clear()

    def stop_loop(self, wait=False):
        self._stop_request.set()
        if wait:
            self.wait_for_loop_end()

    def wait_for_loop_end(self):
        with self._run_lock:
            pass

    def initialize(self):
        if not self._is_initialized:
            self._initialize_cb()
            self._is_initialized = True

    def shutdown(self):
        if self._is_initialized:
            self.stop_loop()
            self._shutdown_cb()
            self._is_initialized = False

    @abc.abstractmethod
    def _initialize_cb(self):
        raise NotImplementedError

    @abc.abstractmethod
    def _run_loop_cb(self):
        raise NotImplementedError

    @abc.abstractmethod
    def _shutdown_cb(self):
        raise NotImplementedError


class EventLoopRun:
    """The coordinator's SimulationLoop "EventLoop" (NRP-Core 1.4's EventLoopSimManager):
    connect() makes the config's MQTTNode client (starting mosquitto on a local MQTTBroker no
    broker answers on) and ROSNode node; load() the ComputationalGraph; run() cycles every
    EventLoop.Timestep until EventLoop.Timeout wall seconds; close() disconnects and stops
    what connect() started.

    With EngineConfigs the coordinator also runs the engines' FTILoop on another thread, its
    DataPackProcessor the graph in slave mode (NRP-Core's ComputationalGraphHandle with
    slaveMode): from load() to close(), event_loop_graph() is this loop's graph, whose
    FromEngine nodes the FTILoop fills and whose ToEngine nodes it drains, without computing.

    `config` is the simulation config (a dict with defaults filled or not); `log_dir` holds
    mosquitto's log. Errors are ComputationalGraphError naming the key."""

    def __init__(self, config, log_dir):
        from ._clients import GraphClients
        loop = config.get("EventLoop") or {}
        self.timeout = float(loop.get("Timeout", 0.0))
        self.timestep = float(loop.get("Timestep", 0.01))
        self.warn_threshold = float(loop.get("TimestepWarnThreshold", 0.001))
        self.exec_mode = loop.get("ExecutionMode", "AllNodes")
        self.clients = GraphClients(config, log_dir)
        self.graph = self.loop = None

    @property
    def broker(self):
        return self.clients.broker

    def connect(self):
        self.clients.connect()

    def load(self, files, base_dir):
        global _running_graph
        from ._loader import load_computational_graph
        from ._policies import ExecutionMode
        mode = ExecutionMode.OUTPUT_DRIVEN if self.exec_mode == "OutputDriven" else \
            ExecutionMode.ALL_NODES
        self.graph = load_computational_graph(files, mode, self.clients.transports(),
                                              base_dir=base_dir)
        self.loop = EventLoop(self.graph, self.timestep, self.warn_threshold,
                              ros=self.clients.ros)
        _running_graph = self.graph

    def run(self, should_stop=None):
        """Runs the loop; returns the number of cycles."""
        _log.info("Creating Event Loop with configuration: timestep=%d(ms), timeout=%d(ms)",
                  int(1000 * self.timestep), int(1000 * self.timeout))
        self.loop.run(self.timeout, should_stop)
        return self.loop.iterations

    def close(self):
        global _running_graph
        if _running_graph is self.graph:
            _running_graph = None
        self.clients.close()


_running_graph = None


def event_loop_graph():
    """The graph of the EventLoop that runs in this process (None without one): the FTILoop's
    DataPackProcessor then works on it in slave mode."""
    return _running_graph
