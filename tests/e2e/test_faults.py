"""Fault injection (issue 30; docs/faults.md): SIGKILL each engine type at random steps of a
recorded run, SIGKILL the coordinator, kill a remote engine and cut its connection mid-step.
After each: the documented exit code (3) and one message naming the engine; summary.json,
steps.csv, logs/, camera.mp4 and recording.mcap readable up to the fault; no process,
shared-memory segment, socket file or temporary file left. Each kill point prints one line
"[fault OK|FAILED] ...". The steps come from CONVOY_FAULT_SEED (default in fault_util.py).

Groups: CityWorld and CityAgents (a trimmed experiments/city_traffic: world, SUMO, lights,
detector, weather, a vehicle and a pedestrian agent, the planner and the recorder writing
camera.mp4), SmallEngines (python_json, python_grpc, datatransfer, scenario), Remote (a remote
engine over gRPC killed, its connection cut), Coordinator, and Checks (the checks catch a bad
run folder).

Each group tries one kill point per fault (the first step drawn from the seed: 16 kill points
in all, the default test run); its twin <Group>Full (ctest label `long`) tries the full set,
3 or 4 per fault (51 kill points), those drawn from the same seed, the default's among them.
Every kill point gets the same checks either way.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_faults.CityWorld   # one group
      cd tests/e2e && /usr/bin/python3 -m unittest -v test_faults            # all, both sets
"""

import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest

import fault_util
from e2e_util import BIN_DIR, CONVOY, REPO, free_port
from fault_util import EXIT_ENGINE, FaultRun, kill_steps

CITY = os.path.join(REPO, "experiments", "city_traffic")
KILLS_PER_TYPE = 3
TIMEOUT_S = 30.0  # simulated: far beyond the kill steps; the fault ends every run


def city_experiment(root):
    """experiments/city_traffic with one vehicle and one pedestrian agent, in root/exp (the
    experiment's files linked, the TF that names every agent limited to those present)."""
    exp = os.path.join(root, "exp")
    here = os.path.join(exp, "city_traffic")
    os.makedirs(here)
    for name in os.listdir(CITY):
        if name not in ("simulation_config.json", "traffic_tf.py", "__pycache__"):
            os.symlink(os.path.join(CITY, name), os.path.join(here, name))
    for d in ("common", "autonomous_driving", "ego_planner"):
        os.symlink(os.path.join(REPO, "experiments", d), os.path.join(exp, d))
    with open(os.path.join(CITY, "traffic_tf.py")) as f:
        tf = f.read()
    line = "AGENTS = VEHICLES + PEDESTRIANS\n"
    assert line in tf, "traffic_tf.py changed: update test_faults.city_experiment"
    tf = tf.replace(line, "VEHICLES = [n for n in VEHICLES if n in _engines()]\n"
                          "PEDESTRIANS = [n for n in PEDESTRIANS if n in _engines()]\n" + line)
    with open(os.path.join(here, "traffic_tf.py"), "w") as f:
        f.write(tf)
    with open(os.path.join(CITY, "simulation_config.json")) as f:
        cfg = json.load(f)
    cfg["EngineConfigs"] = [e for e in cfg["EngineConfigs"]
                            if e["EngineType"] not in ("vehicle_agent", "pedestrian_agent")
                            or e["EngineName"] in ("car_0", "ped_0")]
    with open(os.path.join(here, "simulation_config.json"), "w") as f:
        json.dump(cfg, f, indent=1)
    return here, [e["EngineName"] for e in cfg["EngineConfigs"]]


SRC = """\
import time
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self.step = 0
        self._registerDataPack("counter")
        self._setDataPack("counter", {"step": 0})

    def runLoop(self, timestep_ns):
        self.step += 1
        time.sleep(0.01)
        self._setDataPack("counter", {"step": self.step, "t": self._time_ns})
"""

PG = """\
from nrp_core.engines.python_grpc import GrpcEngineScript
from nrp_protobuf import wrappers_pb2


class Script(GrpcEngineScript):
    def initialize(self):
        self.n = 0
        self._registerDataPack("count", wrappers_pb2.Int64Value)

    def runLoop(self, timestep_ns):
        self.n += 1
        self._getDataPack("count").value = self.n
"""

TF = """\
from nrp_core import *
from nrp_core.data.nrp_json import *


@EngineDataPack(keyword="c", id=DataPackIdentifier("counter", "src"))
@TransceiverFunction("dt")
def to_dt(c):
    if c.isEmpty():
        return []
    return [JsonDataPack("counter", "dt", dict(c.data))]
"""


class FaultCase(unittest.TestCase):
    """Each test: kill points on one experiment, one line printed per kill point."""

    @classmethod
    def setUpClass(cls):
        if not os.access(CONVOY, os.X_OK):
            raise unittest.SkipTest("no coordinator at %s (set CONVOY_BIN_DIR)" % CONVOY)
        print("\n[fault seed %d] (CONVOY_FAULT_SEED)" % fault_util.SEED, flush=True)

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="convoy-fault-%s-" % self._testMethodName)
        self.addCleanup(shutil.rmtree, self.dir, True)
        self.servers = []
        self.addCleanup(self._stop_servers)

    def _stop_servers(self):
        for p in self.servers:
            if p.poll() is None:
                p.kill()
            p.wait()

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(text if isinstance(text, str) else json.dumps(text, indent=1))
        return path

    def convoy_cmd(self, cwd, run_dir, record=True):
        cmd = [CONVOY, "run", "-c", os.path.join(cwd, "simulation_config.json"),
               "--run-dir", run_dir, "-q", "-o", "SimulationTimeout=%g" % TIMEOUT_S]
        return cmd + (["--record"] if record else [])

    def check_engine_kill(self, fr, engine, engines, video=False):
        fr.finish()
        fr.check_exit(EXIT_ENGINE)
        fr.check_one_message(engine)
        fr.check_summary()
        fr.check_steps()
        fr.check_logs(engines)
        fr.check_leftovers()
        if video:  # ffmpeg finishes the file once its engine is gone (checked above)
            fr.check_video()
        fr.check_recording()
        return fr.report()

    # One kill point per fault (the first of the seeded draw); the *Full groups: all n.
    full = False

    def kill_points(self, what, run_one, n=KILLS_PER_TYPE, high=40):
        """run_one(k, i) for the n steps k drawn for `what` (the first of them only unless
        self.full); every kill point must be clean."""
        failed = []
        for i, k in enumerate(kill_steps(what, n, high=high, take=None if self.full else 1)):
            line = run_one(k, i)
            if "[fault FAILED]" in line:
                failed.append(line)
        self.assertEqual(failed, [], "\n".join(failed))


class CityCase(FaultCase):
    """Engines of a trimmed city_traffic run (recorded, with camera.mp4), each killed once
    (3 times in the Full groups)."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(os.path.join(BIN_DIR, "convoy-engine-sumo"), os.X_OK):
            raise unittest.SkipTest("the sumo engine is not built (SUMO not found)")

    def kill_engine(self, engine):
        here, engines = city_experiment(self.dir)

        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            fr = FaultRun(self.convoy_cmd(here, run_dir), here, run_dir,
                          "city engine %s, step %d" % (engine, k))
            fr.kill_at(k, "engine %s" % engine, lambda: fr.engines.get(engine))
            return self.check_engine_kill(fr, engine, engines, video=True)

        self.kill_points("city-" + engine, one)


class CityWorld(CityCase):
    def test_gazebo_grpc_world(self):
        self.kill_engine("gazebo")

    def test_sumo(self):
        self.kill_engine("sumo")

    def test_traffic_lights(self):
        self.kill_engine("lights")

    def test_detector(self):
        self.kill_engine("yolo_detector")


class CityAgents(CityCase):
    def test_weather(self):
        self.kill_engine("weather")

    def test_vehicle_agent(self):
        self.kill_engine("car_0")

    def test_pedestrian_agent(self):
        self.kill_engine("ped_0")

    def test_python_json_recorder_with_camera(self):
        self.kill_engine("recorder")


class SmallEngines(FaultCase):
    """python_json, python_grpc and datatransfer in one small recorded run; the scenario
    engine in a scenario run."""

    def small_experiment(self):
        self.write("src.py", SRC)
        self.write("pg.py", PG)
        self.write("tf.py", TF)
        self.write("simulation_config.json", {
            "SimulationName": "faults", "SimulationTimeout": TIMEOUT_S,
            "EngineConfigs": [
                {"EngineType": "python_json", "EngineName": "src", "PythonFileName": "src.py",
                 "EngineTimestep": 0.01},
                {"EngineType": "python_grpc", "EngineName": "pg", "PythonFileName": "pg.py",
                 "EngineTimestep": 0.01, "ProtobufPackages": ["Wrappers"]},
                {"EngineType": "datatransfer_grpc_engine", "EngineName": "dt",
                 "MQTTBroker": "localhost:1", "simulationID": "faults",
                 "dumps": [{"name": "counter", "file": True}]}],
            "DataPackProcessingFunctions": [{"Name": "to_dt", "FileName": "tf.py"}]})
        return ["src", "pg", "dt"]

    def kill_small(self, engine, what):
        if not os.access(os.path.join(BIN_DIR, "convoy-engine-datatransfer_grpc_engine"), os.X_OK):
            self.skipTest("the datatransfer engine is not built")
        engines = self.small_experiment()

        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            fr = FaultRun(self.convoy_cmd(self.dir, run_dir), self.dir, run_dir,
                          "%s engine %s, step %d" % (what, engine, k))
            fr.kill_at(k, "engine %s" % engine, lambda: fr.engines.get(engine))
            return self.check_engine_kill(fr, engine, engines)

        self.kill_points(what, one)

    def test_python_json(self):
        self.kill_small("src", "python_json")

    def test_python_grpc(self):
        self.kill_small("pg", "python_grpc")

    def test_datatransfer(self):
        self.kill_small("dt", "datatransfer")

    def test_scenario(self):
        import test_scenario  # its stand-in experiment (one python_json engine per entity)
        cfg = test_scenario.ScenarioCase.stand_in_config(
            self, os.path.join(test_scenario.FIXTURES, "lead_brake.xosc"), timeout=TIMEOUT_S)
        # The stand-ins are quick: a pacer keeps the steps slow enough to be caught.
        self.write("pacer.py", SRC)
        cfg["EngineConfigs"].append({"EngineType": "python_json", "EngineName": "src",
                                     "PythonFileName": "pacer.py", "EngineTimestep": 0.05})
        self.write("simulation_config.json", cfg)
        engines = [e["EngineName"] for e in cfg["EngineConfigs"]]

        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            fr = FaultRun(self.convoy_cmd(self.dir, run_dir), self.dir, run_dir,
                          "scenario engine, step %d" % k)
            fr.kill_at(k, "engine scenario", lambda: fr.engines.get("scenario"))
            return self.check_engine_kill(fr, "scenario", engines)

        self.kill_points("scenario", one)


REMOTE_ENGINE = """\
import time
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("remote_dp")
        self._setDataPack("remote_dp", {"t": 0})

    def runLoop(self, timestep_ns):
        time.sleep(0.02)  # a step long enough to be cut in the middle
        self._setDataPack("remote_dp", {"t": self._time_ns})
"""


RELAY_TF = """\
from nrp_core import *
from nrp_core.data.nrp_json import *


@EngineDataPack(keyword="c", id=DataPackIdentifier("counter", "src"))
@EngineDataPack(keyword="r", id=DataPackIdentifier("remote_dp", "remote"))
@TransceiverFunction("remote")
def relay(c, r):
    return [] if c.isEmpty() else [JsonDataPack("remote_dp", "remote", dict(c.data))]
"""


class Remote(FaultCase):
    """A remote engine (EmptyLaunchCommand, gRPC) next to a local one: its server SIGKILLed,
    or its connection cut, mid-step."""

    def remote_experiment(self, port):
        self.write("src.py", SRC)
        self.write("remote.py", REMOTE_ENGINE)
        self.write("relay_tf.py", RELAY_TF)
        self.write("simulation_config.json", {
            "SimulationName": "faults_remote", "SimulationTimeout": TIMEOUT_S,
            "EngineConfigs": [
                {"EngineType": "python_json", "EngineName": "src", "PythonFileName": "src.py",
                 "EngineTimestep": 0.01},
                {"EngineType": "python_json", "EngineName": "remote",
                 "PythonFileName": "remote.py", "EngineTimestep": 0.01,
                 "ServerAddress": "127.0.0.1:%d" % port, "EngineCommandTimeout": 5,
                 "EngineLaunchCommand": {"LaunchType": "EmptyLaunchCommand"}}],
            "DataPackProcessingFunctions": [{"Name": "relay", "FileName": "relay_tf.py"}]})

    def start_server(self, log):
        port = free_port()
        with open(log, "w") as f:
            server = subprocess.Popen([os.path.join(BIN_DIR, "convoy-engine-python_json"),
                                       "--address", "127.0.0.1:%d" % port], cwd=self.dir,
                                      stdout=f, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL, start_new_session=True)
        self.servers.append(server)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            with open(log) as f:
                if "serving gRPC" in f.read():
                    return server, port
            time.sleep(0.01)
        self.fail("the remote engine did not start: %s" % open(log).read())

    def remote_run(self, what, cut, n=KILLS_PER_TYPE):
        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            server, port = self.start_server(os.path.join(self.dir, "server%d.log" % i))
            relay = fault_util.Relay(port) if cut else None
            self.remote_experiment(relay.port if cut else port)
            fr = FaultRun(self.convoy_cmd(self.dir, run_dir), self.dir, run_dir,
                          "%s, step %d" % (what, k))
            if cut:
                fr.act_at(k, "connection of remote engine 'remote' cut", relay.cut)
            else:
                fr.kill_at(k, "remote engine server", lambda: server.pid)
            fr.seen.add(server.pid)
            result = fr.finish()
            if cut and server.poll() is None:  # the server is the user's: it goes on serving
                server.kill()
            server.wait()
            return self.check_engine_kill(result, "remote", ["src"])

        self.kill_points(what, one, n)

    def test_remote_engine_killed(self):
        self.remote_run("remote engine killed", cut=False)

    def test_remote_connection_cut(self):
        self.remote_run("remote connection cut", cut=True, n=4)


class Coordinator(FaultCase):
    """SIGKILL of convoy run itself: the engines die with it (PDEATHSIG), ffmpeg finishes
    camera.mp4, and the run folder keeps what was written."""

    def check_coordinator_kill(self, fr, engines, video):
        fr.finish()
        if fr.code != -signal.SIGKILL:
            fr.findings.append("exit %s, expected death by SIGKILL" % fr.code)
        fr.check_summary(ended=False)
        fr.check_steps()
        fr.check_logs(engines)
        fr.check_leftovers()
        if video:
            fr.check_video()
        fr.check_recording(finished=False)
        return fr.report()

    def test_city(self):
        here, engines = city_experiment(self.dir)

        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            fr = FaultRun(self.convoy_cmd(here, run_dir), here, run_dir,
                          "city coordinator, step %d" % k)
            fr.kill_at(k, "coordinator", lambda: fr.proc.pid)
            return self.check_coordinator_kill(fr, engines, video=True)

        self.kill_points("coordinator-city", one, n=4)

    def test_small(self):
        if not os.access(os.path.join(BIN_DIR, "convoy-engine-datatransfer_grpc_engine"), os.X_OK):
            self.skipTest("the datatransfer engine is not built")
        engines = SmallEngines.small_experiment(self)

        def one(k, i):
            run_dir = os.path.join(self.dir, "run%d" % i)
            fr = FaultRun(self.convoy_cmd(self.dir, run_dir), self.dir, run_dir,
                          "small coordinator, step %d" % k)
            fr.kill_at(k, "coordinator", lambda: fr.proc.pid)
            return self.check_coordinator_kill(fr, engines, video=False)

        # Up to 300 steps of 10 ms: some kill points after whole recording chunks.
        self.kill_points("coordinator-small", one, n=4, high=300)


# The full set of kill points (ctest label `long`): the groups above with every step drawn.
class CityWorldFull(CityWorld):
    full = True


class CityAgentsFull(CityAgents):
    full = True


class SmallEnginesFull(SmallEngines):
    full = True


class RemoteFull(Remote):
    full = True


class CoordinatorFull(Coordinator):
    full = True


class Checks(FaultCase):
    """The checks themselves find what they look for: a run folder as a careless coordinator
    would leave it (a summary half written, a cut row, temp files, a socket, a process)."""

    def test_a_bad_run_folder_is_found_out(self):
        run_dir = os.path.join(self.dir, "run")
        os.makedirs(os.path.join(run_dir, "logs"))
        self.write("run/summary.json", '{"state": "ended", "exit_co')
        self.write("run/steps.csv", "cycle,sim_time_s,cycle_wall_us\n0,0.01\n1,0.0")
        self.write("run/logs/coordinator.log", "run folder: x\n")
        self.write("run/summary.json.tmp-1", "{}")
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(os.path.join(run_dir, "engine.sock"))
        self.addCleanup(sock.close)
        stray = subprocess.Popen(["sleep", "30"], env=dict(os.environ, CONVOY_RUN_DIR=run_dir))
        self.addCleanup(stray.wait)
        fr = FaultRun(["true"], self.dir, run_dir, "self-test").finish()
        fr.rows_at_kill = 2
        stray_tmp = os.path.join(tempfile.gettempdir(), "fault-check.%d.tmp" % fr.proc.pid)
        open(stray_tmp, "w").close()
        self.addCleanup(os.remove, stray_tmp)
        fault_util.LEFTOVER_GRACE_S, grace = 0.2, fault_util.LEFTOVER_GRACE_S
        try:
            fr.check_summary()
            fr.check_steps()
            fr.check_logs(["engine"])
            fr.check_leftovers()
            fr.check_recording()
        finally:
            fault_util.LEFTOVER_GRACE_S = grace
        found = "\n".join(fr.findings)
        for needle in ("summary.json unreadable", "last line is cut", "lines [1] are not whole",
                       "1 rows, 2 were there", "logs missing: ['engine']", "processes left",
                       "engine.sock", "summary.json.tmp-1", stray_tmp,
                       "recording.mcap unreadable"):
            self.assertIn(needle, found)
        self.assertEqual(stray.wait(timeout=5), -signal.SIGKILL, "the stray was not ended")
        self.assertIn("[fault FAILED]", fr.report(show=False))


if __name__ == "__main__":
    unittest.main()
