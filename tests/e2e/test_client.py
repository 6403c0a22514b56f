"""End-to-end tests of the server mode and NRP-Core's Python client (python/nrp_client):
initialize, run_loop, datapacks from the client, reset, run_until_timeout, the status
function's JSON and protobuf data, bad input, and that no process outlives the client.

Run with Debian's /usr/bin/python3 -m unittest test_client."""

import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time

from e2e_util import BIN_DIR, REPO, E2ETestCase, basic_config, engine_script, pid_alive

os.environ.setdefault("CONVOY_BIN_DIR", BIN_DIR)
sys.path.insert(0, os.path.join(REPO, "python"))
from nrp_client import NrpCore, NrpCoreError, find_nrpcoresim  # noqa: E402
from google.protobuf import wrappers_pb2  # noqa: E402

# Adds the "dx" of its "action" datapack to x every step; reset() sets x back to 0.
COUNTER = engine_script("counter", initialize="""
    self._registerDataPack("action")
    self._registerDataPack("obs")
    self.x = 0
    self._setDataPack("obs", {"x": self.x, "t": self._time_ns})
    """, run_loop="""
    action = self._getDataPack("action")
    if isinstance(action, dict):
        self.x += action["dx"]
    elif action is not None:  # a protobuf message (google.protobuf.Int32Value)
        self.x += action.value
    self._setDataPack("obs", {"x": self.x, "t": self._time_ns})
    """, extra="""
    def reset(self):
        action = self._getDataPack("action")
        self.x = action["x0"] if action and "x0" in action else 0
        self._setDataPack("action", None)
        self._setDataPack("obs", {"x": self.x, "t": 0})
""")

# Every cycle: the observation, as JSON and as protobuf messages; done when DONE.
STATUS = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import JsonRawData
    import numpy as np
    from nrp_core.data.nrp_protobuf import GazeboCameraDataPack, GazeboLinkDataPack
    from google.protobuf import wrappers_pb2

    @EngineDataPack(keyword='obs', id=DataPackIdentifier('obs', 'counter'))
    @SimulationIteration(keyword="it")
    @SimulationTime(keyword="t")
    @StatusFunction()
    def status_function(obs, it, t):
        data = [JsonRawData({"it": it, "t": t, "x": obs.data["x"],
                             "updated": obs.isUpdated()})]
        if PROTO:
            data.append(RawData(wrappers_pb2.Int32Value(value=it)))
            link = GazeboLinkDataPack("link", "counter")
            link.data.pos = [it, obs.data["x"], 0.5]
            data.append(link)
            cam = GazeboCameraDataPack("cam", "counter")  # 48 KiB: its pixels in a blob
            cam.data.image_height, cam.data.image_width, cam.data.image_depth = 128, 128, 3
            cam.data.image_data = (np.arange(128 * 128 * 3) % 251).astype(np.uint8) + it
            data.append(cam)
        return DONE, data
    """)


def free_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "127.0.0.1:%d" % s.getsockname()[1]


class Client(E2ETestCase):
    def experiment(self, done="True", proto=False, timeout=1.0, timesteps=(0.01,), **extra):
        engines = ["counter"]
        self.write("counter.py", COUNTER)
        for i in range(1, len(timesteps)):  # more engines: plain ones
            engines.append("other%d" % i)
            self.write("other%d.py" % i, engine_script("other%d" % i))
        self.write("status.py", STATUS.replace("DONE", done).replace("PROTO", str(proto)))
        cfg = basic_config(engines=engines, timeout=timeout, **extra)
        for ec, ts in zip(cfg["EngineConfigs"], timesteps):
            ec["EngineTimestep"] = ts
        cfg["StatusFunction"] = {"Name": "status", "FileName": "status.py"}
        self.write_config(cfg)

    def client(self, **kwargs):
        nrp = NrpCore(free_address(), experiment_folder=self.dir, **kwargs)
        self.addCleanup(nrp.shutdown)
        return nrp

    def assertGone(self, pids):
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and any(pid_alive(p) for p in pids):
            time.sleep(0.05)
        self.assertEqual([p for p in pids if pid_alive(p)], [])

    def test_initialize_run_loop_set_datapack_reset_shutdown(self):
        self.experiment()
        nrp = self.client()
        self.assertEqual(nrp.current_state(), "Created")
        # initialize() returns what the functions read, as the engines have it then
        self.assertEqual(nrp.initialize(), [{"x": 0, "t": 0}])
        self.assertEqual(nrp.current_state(), "Initialized")

        # 10 steps: done every cycle, so the 10 observations come back together
        done, data = nrp.run_loop(10)
        self.assertTrue(done)
        self.assertEqual(nrp.current_state(), "Stopped")
        self.assertEqual([d["it"] for d in data], list(range(10)))
        self.assertEqual([d["t"] for d in data], [i * 10_000_000 for i in range(10)])
        self.assertEqual({d["x"] for d in data}, {0})
        self.assertTrue(all(d["updated"] for d in data))

        # a datapack goes with the engine's next step; its effect shows a step later
        nrp.set_json_datapack("action", "counter", {"dx": 5})
        self.assertEqual(nrp.run_loop(1), (True, [{"it": 10, "t": 100_000_000, "x": 0,
                                                   "updated": True}]))
        self.assertEqual(nrp.run_loop(1)[1][0]["x"], 5)
        self.assertEqual(nrp.run_loop(1)[1][0]["x"], 10)  # the engine keeps its action

        # reset: the datapack given before it reaches the engine's reset()
        nrp.set_json_datapack("action", "counter", {"dx": 0, "x0": 7})
        self.assertEqual(nrp.reset(), [{"x": 7, "t": 0}])
        self.assertEqual(nrp.current_state(), "Initialized")
        done, data = nrp.run_loop(2)
        self.assertEqual([(d["it"], d["t"], d["x"]) for d in data],
                         [(0, 0, 7), (1, 10_000_000, 7)])

        pids = list(self.engine_pids().values()) + [nrp._server.process.pid]
        self.assertTrue(all(pid_alive(p) for p in pids))
        nrp.shutdown()
        self.assertEqual(nrp.current_state(), "None")
        self.assertEqual(nrp._server.process.returncode, 0)
        self.assertGone(pids)
        self.assertTrue(os.path.exists(os.path.join(self.dir, "shutdown_counter")))
        with self.assertRaisesRegex(NrpCoreError, "shut down"):
            nrp.run_loop(1)

    def test_json_and_protobuf_data_keep_their_order(self):
        self.experiment(proto=True)
        nrp = self.client()
        nrp.initialize()
        done, data = nrp.run_loop(2)
        self.assertTrue(done)
        self.assertEqual(len(data), 8)
        for it in range(2):
            js, i32, link, cam = data[4 * it:4 * it + 4]
            self.assertEqual(js["it"], it)
            self.assertIsInstance(i32, wrappers_pb2.Int32Value)
            self.assertEqual(i32.value, it)
            # Gazebo.Link and Gazebo.Camera (NRP-Core's names and layouts of the standard link
            # and camera, as NRP-Core's client expects): types this Python did not know; their
            # descriptors come from the server
            self.assertEqual(link.DESCRIPTOR.full_name, "Gazebo.Link")
            self.assertEqual(list(link.position), [it, 0, 0.5])
            self.assertEqual(cam.DESCRIPTOR.full_name, "Gazebo.Camera")
            self.assertEqual((cam.imageHeight, cam.imageWidth, cam.imageDepth), (128, 128, 3))
            self.assertEqual(cam.imageData, bytes((i % 251 + it) for i in range(128 * 128 * 3)))
        # a protobuf datapack from the client reaches the engine as its message
        nrp.set_proto_datapack("action", "counter", wrappers_pb2.Int32Value(value=3))
        nrp.run_loop(2)
        self.assertEqual(nrp.run_loop(1)[1][0]["x"], 6)

    def test_done_flag_and_run_until_timeout(self):
        self.experiment(done="it == 3", timeout=0.05)
        nrp = self.client()
        nrp.initialize()
        # not done: the observations stay in the server until it is (NRP-Core's rule)
        for _ in range(3):
            self.assertEqual(nrp.run_loop(1), (False, []))
        done, data = nrp.run_loop(1)
        self.assertTrue(done)
        self.assertEqual([d["it"] for d in data], [0, 1, 2, 3])
        # run_until_timeout() with the done flag still set returns at once, as in NRP-Core
        self.assertEqual(nrp.run_until_timeout(), (True, False, []))
        nrp.reset()
        done, timed_out, data = nrp.run_until_timeout()
        self.assertEqual((done, timed_out), (True, False))
        self.assertEqual([d["it"] for d in data], [0, 1, 2, 3])
        # on to the 50 ms timeout: iterations 4 (40 ms) only
        self.assertEqual(nrp.run_loop(0 + 1), (False, []))
        done, timed_out, data = nrp.run_until_timeout()
        self.assertEqual((done, timed_out), (False, True))
        self.assertEqual([d["it"] for d in data], [4])

    def test_engines_with_different_timesteps(self):
        # run_loop(1) is one step of the smallest timestep; the slower engine's datapack is
        # updated when it steps
        self.experiment(timesteps=(0.02, 0.01))
        nrp = self.client()
        nrp.initialize()
        done, data = nrp.run_loop(6)
        self.assertEqual([(d["it"], d["t"]) for d in data],
                         [(i, i * 10_000_000) for i in range(6)])
        self.assertEqual([d["updated"] for d in data], [True, False] * 3)

    def test_stop_ends_an_endless_run_loop(self):
        self.experiment(done="False")
        nrp = self.client()
        nrp.initialize()
        response = []
        thread = nrp.run_loop(0, run_async=True, response=response)
        time.sleep(0.3)
        self.assertTrue(thread.is_alive())
        nrp.stop()
        thread.join(10)
        self.assertFalse(thread.is_alive())
        self.assertEqual(response, [(False, [])])
        self.assertEqual(nrp.current_state(), "Stopped")

    def test_calls_in_the_wrong_state_are_refused_clearly(self):
        self.experiment()
        nrp = self.client()
        with self.assertRaisesRegex(NrpCoreError, r"run_loop\(\): can't run the simulation in "
                                    r"state \"Created\" \(call initialize\(\) first\)"):
            nrp.run_loop(1)
        with self.assertRaisesRegex(NrpCoreError, "can't reset"):
            nrp.reset()
        self.assertEqual(nrp.current_state(), "Created")
        nrp.initialize()
        with self.assertRaisesRegex(NrpCoreError, "can't initialize the simulation in state "
                                    "\"Initialized\""):
            nrp.initialize()
        nrp.set_json_datapack("action", "nobody", {"dx": 1})
        with self.assertRaisesRegex(NrpCoreError, "datapack 'action' is for unknown engine "
                                    "'nobody' \\(engines: counter\\)"):
            nrp.run_loop(1)
        self.assertEqual(nrp.current_state(), "Initialized")
        self.assertTrue(nrp.run_loop(1)[0], "the simulation goes on")
        with self.assertRaisesRegex(ValueError, "num_iterations"):
            nrp.run_loop(-1)

    def test_a_failing_status_function_fails_the_simulation(self):
        self.experiment(done="1 / (2 - it) > 100")
        nrp = self.client()
        nrp.initialize()
        nrp.run_loop(2)
        with self.assertRaisesRegex(NrpCoreError, "(?s)run_loop\\(\\) failed: status function "
                                    "'status'.*ZeroDivisionError.*only possible action now is "
                                    "shutdown"):
            nrp.run_loop(1)
        self.assertEqual(nrp.current_state(), "Failed")
        with self.assertRaisesRegex(NrpCoreError, "only shutdown"):
            nrp.run_loop(1)
        nrp.shutdown()
        self.assertEqual(nrp._server.process.returncode, 4)  # a function failure
        self.assertEqual(self.scan_engine_processes(), [])

    def test_bad_addresses_configs_and_folders(self):
        self.experiment()
        with self.assertRaisesRegex(ValueError, "HOST:PORT"):
            NrpCore("garbage_address", experiment_folder=self.dir)
        with self.assertRaisesRegex(FileNotFoundError, "wrong_file"):
            NrpCore(free_address(), experiment_folder=self.dir, config_file="wrong_file")
        with self.assertRaisesRegex(FileNotFoundError, "not a folder"):
            NrpCore(free_address(), experiment_folder=os.path.join(self.dir, "nope"))
        with socket.socket() as taken:
            taken.bind(("127.0.0.1", 0))
            taken.listen()
            address = "127.0.0.1:%d" % taken.getsockname()[1]
            with self.assertRaisesRegex(ConnectionError, "not free"):
                NrpCore(address, experiment_folder=self.dir)
        # a config the server refuses: it exits, and the client says why
        self.write("broken.json", '{"EngineConfigs": [{"EngineName": "x"}]}')
        with self.assertRaisesRegex(ChildProcessError, "(?s)exited with code 2.*EngineType"):
            NrpCore(free_address(), experiment_folder=self.dir, config_file="broken.json")
        # beyond the loopback only with --insecure
        with self.assertRaisesRegex(ChildProcessError, "(?s)exited with code 2.*is not a "
                                    "loopback address"):
            NrpCore("0.0.0.0:%s" % free_address().split(":")[1], experiment_folder=self.dir)

    def test_a_dead_server_is_reported(self):
        self.experiment()
        nrp = self.client()
        nrp.initialize()
        engines = list(self.engine_pids().values())
        os.kill(nrp._server.process.pid, signal.SIGKILL)
        nrp._server.process.wait(10)
        with self.assertRaisesRegex(ConnectionError, "server was killed by signal 9"):
            nrp.run_loop(1)
        self.assertGone(engines)  # engines die with the coordinator

    def test_no_process_outlives_the_client(self):
        self.experiment()
        script = textwrap.dedent("""\
            import os, sys, time
            sys.path.insert(0, %r)
            from nrp_client import NrpCore
            nrp = NrpCore(%r, experiment_folder=%r)
            nrp.initialize()
            print(nrp._server.process.pid, flush=True)
            if sys.argv[1] == "kill":
                os.kill(os.getpid(), 9)   # no atexit: the server notices its client is gone
            # else: exit without shutdown(): atexit shuts the server down
            """)
        for how in ("exit", "kill"):
            with self.subTest(how=how):
                # A fresh port each time: the first server may still hold its port while it ends.
                code = script % (os.path.join(REPO, "python"), free_address(), self.dir)
                r = subprocess.run([sys.executable, "-c", code, how], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, timeout=60)
                self.assertTrue(r.stdout.split(), "the client script failed:\n" + r.stderr)
                server = int(r.stdout.split()[0])
                self.assertGone([server] + list(self.engine_pids().values()))
                self.assertEqual(self.scan_engine_processes(), [])


class LocalChannelClient(Client):
    """Every Client test again, with run_loop() and reset() through NRPCoreSim's local socket
    (NrpCore(local_channel=True), src/transport/local_rpc.h): the same answers and errors."""

    def client(self, **kwargs):
        nrp = NrpCore(free_address(), experiment_folder=self.dir, local_channel=True, **kwargs)
        self.addCleanup(nrp.shutdown)
        return nrp

    def test_the_socket_is_private_and_gone_after_shutdown(self):
        self.experiment()
        nrp = self.client()
        folder = nrp._local_dir
        self.assertEqual(os.stat(folder).st_mode & 0o777, 0o700)
        self.assertEqual(os.listdir(folder), ["nrp.sock"])
        nrp.initialize()
        self.assertEqual(len(nrp.run_loop(3)[1]), 3)
        nrp.shutdown()
        self.assertFalse(os.path.exists(folder))

    def test_local_socket_needs_server_mode(self):
        self.experiment()
        r = subprocess.run([find_nrpcoresim(), "-c", "simulation_config.json",
                            "--local_socket", os.path.join(self.dir, "x.sock")],
                           cwd=self.dir, capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--local_socket needs -m server", r.stderr)


class GeneratedCode(E2ETestCase):
    def test_nrp_server_pb2_is_generated_from_the_proto(self):
        # python/nrp_client/nrp_server_pb2.py is protoc's output for proto/convoy/nrp_server.proto;
        # regenerate it with the command below when the .proto changes.
        protoc = "/usr/bin/protoc"
        if not os.access(protoc, os.X_OK):
            self.skipTest("no protoc")
        subprocess.run([protoc, "--proto_path=" + os.path.join(REPO, "proto"),
                        "--python_out=" + self.dir,
                        os.path.join(REPO, "proto", "convoy", "nrp_server.proto")], check=True)
        with open(os.path.join(self.dir, "convoy", "nrp_server_pb2.py")) as f:
            fresh = f.read()
        with open(os.path.join(REPO, "python", "nrp_client", "nrp_server_pb2.py")) as f:
            self.assertEqual(f.read(), fresh, "regenerate python/nrp_client/nrp_server_pb2.py: "
                             "protoc --proto_path=proto --python_out=/tmp "
                             "proto/convoy/nrp_server.proto && cp /tmp/convoy/nrp_server_pb2.py "
                             "python/nrp_client/")


class RLExample(E2ETestCase):
    def test_drives_the_car_step_by_step_and_resets_between_episodes(self):
        script = os.path.join(REPO, "experiments", "rl_parkring", "rl_drive.py")
        env = dict(os.environ, CONVOY_RUNS_DIR=os.path.join(self.dir, "runs"))
        r = subprocess.run([sys.executable, script, "--steps", "500", "--gains", "0.05", "1.2",
                            "-q"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=240, env=env)
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertIn("the car's link at [0.0, -1.7, 0.6]", r.stdout)
        returns = [line for line in r.stdout.splitlines() if line.startswith("  return")]
        self.assertEqual(len(returns), 2, r.stdout)
        # the sluggish gain leaves the track at the first bend; the other one stays on it
        self.assertIn("left the track", returns[0])
        self.assertNotIn("left the track", returns[1])
        self.assertIn("after 500 steps (25.0 s simulated", returns[1])
        self.assertIn("best steering gain 1.20", r.stdout)
