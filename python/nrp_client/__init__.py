"""NRP-Core's Python client for Convoy: start a simulation in server mode and step it.

    from nrp_client import NrpCore

    nrp = NrpCore("localhost:50051", experiment_folder="experiments/x",
                  config_file="simulation_config.json")
    nrp.initialize()
    nrp.set_json_datapack("action", "car", {"steer": 0.1})
    done, data = nrp.run_loop(1)        # data: what the status function returned
    nrp.reset()
    nrp.shutdown()

NrpCore() starts `NRPCoreSim -c CONFIG -m server --server_address ADDRESS --slave` as a child
process and waits until it serves. shutdown(), the object's deletion and the exit of this
Python process end it; with --slave it also ends by itself when this process is gone.

Pure Python: it needs grpcio and protobuf (Debian's python3-grpcio and python3-protobuf).
NRPCoreSim is looked up in $CONVOY_BIN_DIR, then in the build folder of the Convoy checkout
holding this package, then on PATH.
"""

import atexit
import json
import os
import shlex
import shutil
import signal
import socket
import subprocess
import tempfile
import threading
import time
import weakref

import grpc
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory, symbol_database

from nrp_client import _local, _wire
from nrp_client import nrp_server_pb2 as _pb

__all__ = ["NrpCore", "NrpCoreError"]

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_SERVICE = "/NrpCore.NrpCore/"
_JSON_TYPE = _pb.JsonMessage.DESCRIPTOR.full_name
_JSON_URL = _wire.TYPE_URL_PREFIX + _JSON_TYPE
_CALL_NAMES = {"runLoop": "run_loop()", "runUntilTimeout": "run_until_timeout()",
               "stopLoop": "stop()"}


class NrpCoreError(RuntimeError):
    """A request the simulation refused or failed (the message says which and why)."""


def find_nrpcoresim():
    """The NRPCoreSim program: $CONVOY_BIN_DIR, the checkout's build/bin, or PATH."""
    candidates = []
    if os.environ.get("CONVOY_BIN_DIR"):
        candidates.append(os.path.join(os.environ["CONVOY_BIN_DIR"], "NRPCoreSim"))
    candidates.append(os.path.join(_REPO, "build", "bin", "NRPCoreSim"))
    for c in candidates:
        if os.access(c, os.X_OK):
            return c
    found = shutil.which("NRPCoreSim")
    if found:
        return found
    raise FileNotFoundError("NRPCoreSim not found: looked in %s and on PATH (set CONVOY_BIN_DIR "
                            "to the folder holding Convoy's programs)" % ", ".join(candidates))


def _split_address(address):
    host, sep, port = str(address).rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError("address must be HOST:PORT (e.g. localhost:50051), got %r" % (address,))
    return host.strip("[]"), int(port)


def _check_port_free(address):
    host, port = _split_address(address)
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as e:
        raise ValueError("address %r: unknown host %r (%s)" % (address, host, e)) from None
    family, _, _, _, sockaddr = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as s:
        try:
            s.bind(sockaddr)
        except OSError as e:
            raise ConnectionError("address %s is not free: %s (another server listens there?)"
                                  % (address, e.strerror)) from None


class _Server:
    """The NRPCoreSim child process."""

    def __init__(self, command, cwd, log_file, environment=None):
        self.log_file = log_file  # where the server writes its output, or None
        self._early = tempfile.TemporaryFile(mode="w+b")  # its output before that
        env = dict(os.environ, **environment) if environment else None
        self.process = subprocess.Popen(command, cwd=cwd or None, stdin=subprocess.DEVNULL,
                                        stdout=self._early, stderr=subprocess.STDOUT, env=env)

    def alive(self):
        return self.process.poll() is None

    def output_tail(self, lines=25):
        text = b""
        if not self._early.closed:
            self._early.seek(0)
            text += self._early.read()
        if self.log_file and os.path.exists(self.log_file):
            with open(self.log_file, "rb") as f:
                text += f.read()
        tail = text.decode("utf-8", "replace").rstrip().splitlines()[-lines:]
        return "\n".join(tail)

    def describe_exit(self):
        code = self.process.poll()
        if code is None:
            return "is still running"
        how = "was killed by signal %d" % -code if code < 0 else "exited with code %d" % code
        tail = self.output_tail()
        return "%s%s" % (how, ("; its last output:\n" + tail) if tail else "")

    def stop(self, wait_s=15.0):
        """Waits for the process to end (after a shutdown request), then terminates it."""
        p = self.process
        for sig, timeout in ((None, wait_s), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
            if p.poll() is not None:
                break
            if sig is not None:
                try:
                    p.send_signal(sig)
                except ProcessLookupError:
                    break
            try:
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                pass
        self._early.close()


_live_servers = weakref.WeakSet()


@atexit.register
def _stop_all_servers():
    for client in list(_live_servers):
        try:
            client.shutdown()
        except Exception:  # noqa: BLE001 - the process is exiting; kill what is left
            pass


class NrpCore:
    """A simulation served by NRPCoreSim, and the calls of NRP-Core's Python client."""

    def __init__(self, address, experiment_folder="", config_file="simulation_config.json",
                 args="", log_output=".console_output.log", server_timeout=10,
                 local_channel=False, environment=None):
        """Starts NRPCoreSim in server mode at `address` and connects to it.

        :param address: HOST:PORT where the server listens (a loopback address, unless
            args has --insecure)
        :param experiment_folder: the experiment's folder (default: the current one); the
            server works there
        :param config_file: the simulation config, absolute or relative to experiment_folder
        :param args: more NRPCoreSim options, e.g. "-o SimulationTimeout=5"
        :param log_output: file (relative to the experiment folder) that gets the server's
            output; "" leaves it in this process' temporary buffer
        :param server_timeout: seconds to wait for the server to serve
        :param local_channel: (Convoy) also reach the server through a Unix socket in a
            private temporary folder, and send run_loop() and reset() there: the same calls
            and answers at a fraction of gRPC's cost per call (_local.py)
        :param environment: (Convoy) more environment variables for the server and its
            engines, e.g. {"CONVOY_SPIN_US": "0"}
        """
        self._sim_state = "None"
        self._closed = True
        self._channel = None
        self._server = None
        self._json_out = []
        self._proto_out = []
        self._classes = {}  # protobuf type name -> message class
        self._local = None
        self._local_dir = None

        _split_address(address)
        folder = os.path.abspath(experiment_folder) if experiment_folder else os.getcwd()
        if not os.path.isdir(folder):
            raise FileNotFoundError("experiment_folder %s is not a folder" % folder)
        config_path = os.path.join(folder, config_file)
        if not os.path.isfile(config_path):
            raise FileNotFoundError("config_file %s not found" % config_path)
        _check_port_free(address)

        command = [find_nrpcoresim(), "-c", config_file, "-m", "server", "--server_address",
                   address, "--slave"]
        if experiment_folder:
            command += ["-d", folder]
        if args:
            command += shlex.split(args)
        if local_channel:
            self._local_dir = tempfile.mkdtemp(prefix="nrp-local-")  # mode 0700
            command += ["--local_socket", _local.socket_path(self._local_dir)]
        log_file = None
        if log_output:
            command += ["--logoutput=all", "--logfilename=" + log_output]
            log_file = os.path.join(folder, log_output)
        self._server = _Server(command, folder, log_file, environment)
        self._address = address
        _live_servers.add(self)

        self._channel = grpc.insecure_channel(address)
        self._calls = {}
        for method, request, response in (
                ("initialize", _pb.EmptyMessage, _pb.InitializeResponse),
                ("runLoop", _pb.RunLoopMessage, _pb.RunLoopResponse),
                ("runUntilTimeout", _pb.EmptyMessage, _pb.RunLoopResponse),
                ("stopLoop", _pb.EmptyMessage, _pb.Response),
                ("reset", _pb.ResetMessage, _pb.ResetResponse),
                ("shutdown", _pb.EmptyMessage, _pb.Response),
                ("describeType", _pb.TypeRequest, _pb.TypeDescription)):
            self._calls[method] = self._channel.unary_unary(
                _SERVICE + method, request_serializer=request.SerializeToString,
                response_deserializer=response.FromString)

        deadline = time.monotonic() + server_timeout
        ready = grpc.channel_ready_future(self._channel)
        while True:
            if not self._server.alive():
                self._abandon()
                raise ChildProcessError("NRPCoreSim did not start: it " +
                                        self._server.describe_exit())
            try:
                ready.result(timeout=0.1)
                break
            except grpc.FutureTimeoutError:
                if time.monotonic() > deadline:
                    self._abandon()
                    raise TimeoutError("NRPCoreSim did not serve at %s within %g s" %
                                       (address, server_timeout)) from None
        if local_channel:
            self._connect_local(server_timeout)
        self._sim_state = "Created"
        self._closed = False

    # --- NRP-Core's calls ------------------------------------------------------------------
    def current_state(self):
        """The simulation's state after the last call: "Created", "Initialized", "Running",
        "Stopped", "Failed" (or "None" when the server is gone)."""
        return self._sim_state

    def initialize(self):
        """Launches and initializes the engines. Returns the datapacks the functions read, as
        the engines have them after initialization (JSON as dicts, protobuf as messages)."""
        response = self._call("initialize", _pb.EmptyMessage())
        return self._read_trajectory(response.trajectory)

    def run_loop(self, num_iterations, run_async=False, response=None):
        """Runs `num_iterations` steps of the smallest EngineTimestep (0: until stop()), after
        handing the datapacks set with set_*_datapack() to their engines. Returns (done,
        data): data are the status function's observations collected since they were last
        returned, sent back when it says done (NRP-Core's rule).

        With run_async, returns a started Thread, which appends (done, data) to `response`."""
        if not isinstance(num_iterations, int) or num_iterations < 0:
            raise ValueError("num_iterations must be an int >= 0, got %r" % (num_iterations,))
        message = self._run_loop_request(num_iterations)
        if run_async:
            return self._async(lambda: self._run_loop(message), response)
        return self._run_loop(message)

    def run_loop_begin(self, num_iterations):
        """(Convoy) run_loop(num_iterations) in two halves: this one sends the call, with the
        datapacks set, and returns at once; run_loop_finish() waits for its (done, data). One
        thread can so have several servers step at the same time (VectorDrivingEnv). Needs
        local_channel=True; between the two halves this client takes no other call."""
        if self._local is None:
            raise NrpCoreError("run_loop_begin(): needs NrpCore(local_channel=True)")
        if not isinstance(num_iterations, int) or num_iterations < 0:
            raise ValueError("num_iterations must be an int >= 0, got %r" % (num_iterations,))
        message = self._run_loop_request(num_iterations)
        self._checked("runLoop", lambda: self._local.begin("runLoop", message))

    def run_loop_finish(self):
        """(Convoy) The (done, data) of the run_loop_begin() call."""
        r = self._checked("runLoop", lambda: self._local.finish(_pb.RunLoopResponse))
        return r.doneFlag, self._read_trajectory(r.trajectory)

    def run_until_timeout(self, run_async=False, response=None):
        """Runs until the status function says done or SimulationTimeout. Returns (done,
        timed_out, data)."""
        def run():
            r = self._call("runUntilTimeout", _pb.EmptyMessage())
            return r.doneFlag, r.timeoutFlag, self._read_trajectory(r.trajectory)
        if run_async:
            return self._async(run, response)
        return run()

    def stop(self):
        """Stops a run_loop / run_until_timeout in progress (between two loop cycles)."""
        # Its answer ("Running") may come after the run's own ("Stopped"): it changes nothing.
        self._call("stopLoop", _pb.EmptyMessage(), keep_state=True)

    def reset(self):
        """Sends the datapacks set with set_*_datapack() to their engines, resets the
        engines and the loop (time 0, iteration 0). Returns the datapacks the functions read,
        after the reset."""
        message = _pb.ResetMessage()
        message.dataPacks.MergeFromString(self._take_datapacks())
        response = self._call("reset", message)
        return self._read_trajectory(response.trajectory)

    def shutdown(self):
        """Shuts the simulation down and waits for the server to exit. Safe to call twice."""
        _live_servers.discard(self)
        if not self._closed:
            self._closed = True
            try:
                self._calls["shutdown"](_pb.EmptyMessage(), timeout=120)
            except grpc.RpcError:
                pass  # the server is gone already; stop() reports nothing more
        self._sim_state = "None"
        self._abandon()

    def set_proto_datapack(self, datapack_name, engine_name, payload):
        """A protobuf message for engine `engine_name`, sent with the next run_loop() or
        reset()."""
        if not hasattr(payload, "DESCRIPTOR"):
            raise TypeError("payload must be a protobuf message, got %s" % type(payload).__name__)
        self._proto_out.append(_wire.datapack(datapack_name, engine_name,
                                              payload.DESCRIPTOR.full_name,
                                              payload.SerializeToString()))

    def set_json_datapack(self, datapack_name, engine_name, payload):
        """A JSON value (a dict, usually) for engine `engine_name`, sent with the next
        run_loop() or reset()."""
        text = _pb.JsonMessage(data=json.dumps(payload)).SerializeToString()
        self._json_out.append(_wire.datapack(datapack_name, engine_name, _JSON_TYPE, text))

    def __del__(self):
        try:
            self.shutdown()
        except Exception:  # noqa: BLE001 - nothing to do about it here
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()

    # --- the rest --------------------------------------------------------------------------
    def _abandon(self):
        if self._local is not None:
            self._local.close()
            self._local = None
        if self._channel is not None:
            self._channel.close()
            self._channel = None
        if self._server is not None:
            self._server.stop()
        if self._local_dir is not None:
            shutil.rmtree(self._local_dir, ignore_errors=True)
            self._local_dir = None

    def _connect_local(self, timeout_s):
        """run_loop() and reset() through the server's local socket from now on."""
        try:
            self._local = _local.LocalChannel(_local.socket_path(self._local_dir), timeout_s,
                                              self._server.alive)
        except ConnectionError:
            self._abandon()
            raise
        self._calls["runLoop"] = self._local.callable("runLoop", _pb.RunLoopResponse)
        self._calls["reset"] = self._local.callable("reset", _pb.ResetResponse)

    def _take_datapacks(self):
        """The DataPacks message's bytes of the datapacks set since the last call."""
        out = _wire.datapacks(self._json_out, self._proto_out)
        self._json_out, self._proto_out = [], []
        return out

    def _run_loop_request(self, num_iterations):
        """The RunLoopMessage with the datapacks set: its bytes for the local channel."""
        request = _wire.run_loop_message(num_iterations, self._take_datapacks())
        return request if self._local is not None else _pb.RunLoopMessage.FromString(request)

    def _run_loop(self, message):
        r = self._call("runLoop", message)
        return r.doneFlag, self._read_trajectory(r.trajectory)

    def _async(self, run, response):
        if response is None:
            response = []

        def target():
            response.append(run())
        t = threading.Thread(target=target, daemon=True)
        t.start()
        return t

    def _call(self, method, request, keep_state=False):
        return self._checked(method, lambda: self._calls[method](request), keep_state)

    def _checked(self, method, call, keep_state=False):
        """call()'s response, its errors raised as NrpCoreError / ConnectionError, the
        simulation's state noted from it (a call that returns None: only sent)."""
        what = _CALL_NAMES.get(method) or method + "()"
        if self._closed:
            raise NrpCoreError("%s: this client was shut down; make a new NrpCore" % what)
        try:
            response = call()
        except grpc.RpcError as e:
            code = e.code()
            if code in (grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.INVALID_ARGUMENT):
                raise NrpCoreError("%s: %s" % (what, e.details())) from None
            if self._server is not None and not self._server.alive():
                self._closed = True
                self._sim_state = "None"
                raise ConnectionError("%s: the NRPCoreSim server %s" %
                                      (what, self._server.describe_exit())) from None
            raise ConnectionError("%s: NRPCoreSim at %s: %s (%s)" %
                                  (what, self._address, e.details(), code.name)) from None
        if response is None:
            return None
        if not keep_state:
            self._sim_state = response.simState.currentState
        if response.simState.currentState == "Failed":
            raise NrpCoreError("%s failed: %s\nThe only possible action now is shutdown()." %
                               (what, response.simState.errorMsg))
        return response

    def _message_class(self, type_name):
        cls = self._classes.get(type_name)
        if cls is None:
            cls = self._classes[type_name] = self._build_message_class(type_name)
        return cls

    def _build_message_class(self, type_name):
        pool = descriptor_pool.Default()
        try:
            descriptor = pool.FindMessageTypeByName(type_name)
        except KeyError:
            reply = self._calls["describeType"](_pb.TypeRequest(typeName=type_name))
            files = descriptor_pb2.FileDescriptorSet.FromString(reply.fileDescriptorSet)
            for f in files.file:  # dependencies first
                try:
                    pool.FindFileByName(f.name)
                except KeyError:
                    pool.Add(f)
            descriptor = pool.FindMessageTypeByName(type_name)
        get_class = getattr(message_factory, "GetMessageClass", None)  # protobuf >= 4.22
        if get_class is not None:
            return get_class(descriptor)
        # The class of an imported *_pb2 module, else a new one.
        return symbol_database.Default().GetPrototype(descriptor)

    def _read_trajectory(self, trajectory):
        items = [None] * (len(trajectory.jsonTrajectoryMessages) +
                          len(trajectory.protoTrajectoryMessages))
        for m in trajectory.jsonTrajectoryMessages:
            data = m.data
            if data.type_url == _JSON_URL:  # what the server sends (else Unpack's check)
                text = _pb.JsonMessage.FromString(data.value)
            else:
                text = _pb.JsonMessage()
                data.Unpack(text)
            items[m.dataIndex] = json.loads(text.data)
        for m in trajectory.protoTrajectoryMessages:
            message = self._message_class(m.data.TypeName())()
            m.data.Unpack(message)
            items[m.dataIndex] = message
        return items
