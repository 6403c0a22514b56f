"""End-to-end tests of the loop's semantics: multi-rate stepping, PFs, empty datapacks,
argument passing, numpy in JSON datapacks, gRPC engines, and bit-for-bit determinism.

Run with Debian's /usr/bin/python3 -m unittest test_core."""

import json
import os
import shutil
import socket
import subprocess
import tempfile
import textwrap
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
BIN_DIR = os.environ.get("CONVOY_BIN_DIR") or os.path.join(REPO, "build", "bin")
CONVOY = os.path.join(BIN_DIR, "convoy")

# Engine that records, for every step, its time and what it received, into <name>.jsonl.
RECORDER = textwrap.dedent("""\
    import json, os
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self.out = open(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                         self._name + ".jsonl"), "w")
            self._registerDataPack("out")
            self._registerDataPack("in")
            self.x = {seed}
            self._setDataPack("out", {{"x": self.x, "t": self._time_ns}})

        def runLoop(self, timestep_ns):
            got = self._getDataPack("in")
            if got is not None:
                # logistic map, fed by the neighbour: chaotic, so any reordering shows
                self.x = 3.9 * self.x * (1 - self.x) * 0.5 + 0.5 * got["x"] * 0.999
            self.out.write(json.dumps({{"t": self._time_ns, "dt": timestep_ns, "got": got,
                                        "x": self.x}}) + "\\n")
            self._setDataPack("out", {{"x": self.x, "t": self._time_ns}})

        def shutdown(self):
            self.out.close()
    """)

RELAY = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='src', id=DataPackIdentifier('out', '{src}'))
    @TransceiverFunction("{dst}")
    def relay_{src}_{dst}(src):
        if src.isEmpty():
            return []
        dp = JsonDataPack("in", "{dst}")
        dp.data["x"] = src.data["x"]
        dp.data["t"] = src.data["t"]
        return [dp]
    """)


class Experiment:
    def __init__(self, test):
        self.dir = tempfile.mkdtemp(prefix="convoy-core-")
        test.addCleanup(shutil.rmtree, self.dir, True)
        self.engines, self.functions = [], []

    def file(self, name, text):
        with open(os.path.join(self.dir, name), "w") as f:
            f.write(text)

    def engine(self, name, script, timestep=0.01, **extra):
        self.file(name + ".py", script)
        cfg = {"EngineType": "python_json", "EngineName": name, "PythonFileName": name + ".py",
               "EngineTimestep": timestep}
        cfg.update(extra)
        self.engines.append(cfg)

    def function(self, name, text):
        self.file(name + ".py", text)
        self.functions.append({"Name": name, "FileName": name + ".py"})

    def run(self, timeout, *options, run_name="run", expect=0, extra_cfg=None):
        cfg = {"SimulationName": "t", "SimulationTimeout": timeout, "EngineConfigs": self.engines,
               "DataPackProcessingFunctions": self.functions}
        cfg.update(extra_cfg or {})
        self.file("simulation_config.json", json.dumps(cfg, indent=1))
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(self.dir, "simulation_config.json"),
                            "--run-dir", os.path.join(self.dir, run_name)] + list(options),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
        if r.returncode != expect:
            raise AssertionError("exit %d, expected %d\n%s" % (r.returncode, expect, r.stderr))
        return r

    def records(self, name):
        with open(os.path.join(self.dir, name + ".jsonl")) as f:
            return [json.loads(line) for line in f]


class LoopSemantics(unittest.TestCase):
    def test_multi_rate_engines_step_at_their_own_timestep(self):
        ex = Experiment(self)
        ex.engine("fast", RECORDER.format(seed=0.3), timestep=0.01)
        ex.engine("slow", RECORDER.format(seed=0.6), timestep=0.03)
        ex.function("tf_fast_slow", RELAY.format(src="fast", dst="slow"))
        ex.function("tf_slow_fast", RELAY.format(src="slow", dst="fast"))
        ex.run(0.3)
        fast, slow = ex.records("fast"), ex.records("slow")
        self.assertEqual(len(fast), 30)
        self.assertEqual(len(slow), 10)
        # _time_ns is the time at the end of the step being run (NRP-Core)
        self.assertEqual([r["t"] for r in slow], [30_000_000 * (i + 1) for i in range(10)])
        self.assertEqual({r["dt"] for r in slow}, {30_000_000})
        # The slow engine's step ending at 60 ms got what the fast one had at 30 ms, when the
        # slow one was last due.
        self.assertEqual(slow[1]["got"]["t"], 30_000_000)
        # The fast engine sees the slow one's data refreshed only every 3 steps.
        self.assertEqual(fast[3]["got"]["t"], 30_000_000)
        self.assertEqual(fast[4]["got"]["t"], 30_000_000)

    def test_empty_datapack_then_data_and_preprocessing(self):
        ex = Experiment(self)
        ex.engine("src", textwrap.dedent("""\
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("late")      # not set until the first step
                def runLoop(self, timestep_ns):
                    self._setDataPack("late", {"v": self._time_ns // 1000000})
            """))
        ex.engine("dst", textwrap.dedent("""\
            import json, os
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("seen")
                    self.log = []
                def runLoop(self, timestep_ns):
                    self.log.append(self._getDataPack("seen"))
                def shutdown(self):
                    with open(os.path.join(os.path.dirname(__file__), "seen.json"), "w") as f:
                        json.dump(self.log, f)
            """))
        ex.function("pf", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @EngineDataPack(keyword='late', id=DataPackIdentifier('late', 'src'))
            @PreprocessingFunction("src")
            def double(late):
                out = JsonDataPack("doubled", "src")
                out.data["v"] = None if late.isEmpty() else 2 * late.data["v"]
                return [out]
            """))
        ex.function("tf", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @PreprocessedDataPack(keyword='d', id=DataPackIdentifier('doubled', 'src'))
            @EngineDataPack(keyword='late', id=DataPackIdentifier('late', 'src'))
            @TransceiverFunction("dst")
            def tf(d, late):
                out = JsonDataPack("seen", "dst")
                out.data["empty"] = late.isEmpty()
                out.data["doubled"] = d.data["v"]
                return [out]
            """))
        ex.run(0.05)
        with open(os.path.join(ex.dir, "seen.json")) as f:
            seen = json.load(f)
        self.assertEqual(seen[0], {"empty": True, "doubled": None})
        self.assertEqual(seen[1], {"empty": False, "doubled": 20})
        self.assertEqual(seen[4], {"empty": False, "doubled": 80})

    def _mutation_experiment(self, method):
        ex = Experiment(self)
        ex.engine("src", textwrap.dedent("""\
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("dp")
                    self._setDataPack("dp", {"v": 1})
            """))
        ex.engine("dst", textwrap.dedent("""\
            import os
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("r")
                def runLoop(self, timestep_ns):
                    with open(os.path.join(os.path.dirname(__file__), "r.txt"), "w") as f:
                        f.write(repr(self._getDataPack("r")))
            """))
        ex.function("tf_a", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @EngineDataPack(keyword='dp', id=DataPackIdentifier('dp', 'src'))
            @TransceiverFunction("dst")
            def mutate(dp):
                dp.data["v"] = 99
                return []
            """))
        ex.function("tf_b", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @EngineDataPack(keyword='dp', id=DataPackIdentifier('dp', 'src'))
            @TransceiverFunction("dst")
            def read(dp):
                return [JsonDataPack("r", "dst", {"v": dp.data["v"]})]
            """))
        ex.run(0.02, extra_cfg={"FunctionArgumentsPassingMethod": method})
        with open(os.path.join(ex.dir, "r.txt")) as f:
            return f.read()

    def test_arguments_by_value_are_private_copies(self):
        self.assertEqual(self._mutation_experiment("value"), "{'v': 1}")

    def test_arguments_by_reference_are_shared(self):
        self.assertEqual(self._mutation_experiment("reference"), "{'v': 99}")

    def test_numpy_array_in_json_datapack_arrives_as_array(self):
        ex = Experiment(self)
        ex.engine("cam", textwrap.dedent("""\
            import numpy as np
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("img")
                    self._setDataPack("img", {"a": np.arange(24, dtype=np.uint16).reshape(2, 3, 4),
                                              "f": np.float32(1.5), "l": [1, 2, 3]})
            """))
        ex.engine("view", textwrap.dedent("""\
            import os
            import numpy as np
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("img")
                def runLoop(self, timestep_ns):
                    d = self._getDataPack("img")
                    if d is None:
                        return
                    a = d["a"]
                    ok = (isinstance(a, np.ndarray) and a.dtype == np.uint16 and a.shape == (2, 3, 4)
                          and int(a[1, 2, 3]) == 23 and d["f"] == 1.5 and d["l"] == [1, 2, 3]
                          and d["t"].dtype == np.float64)
                    with open(os.path.join(os.path.dirname(__file__), "ok.txt"), "w") as f:
                        f.write(str(ok))
            """))
        ex.function("tf", textwrap.dedent("""\
            import numpy as np
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @EngineDataPack(keyword='img', id=DataPackIdentifier('img', 'cam'))
            @TransceiverFunction("view")
            def tf(img):
                out = JsonDataPack("img", "view")
                assert isinstance(img.data["a"], np.ndarray)
                out.data.update(img.data)
                out.data["t"] = np.array(img.data["a"].T, dtype=np.float64)  # non-contiguous view
                return [out]
            """))
        ex.run(0.02)
        with open(os.path.join(ex.dir, "ok.txt")) as f:
            self.assertEqual(f.read(), "True")


class Determinism(unittest.TestCase):
    def test_same_config_gives_identical_trajectories(self):
        ex = Experiment(self)
        ex.engine("a", RECORDER.format(seed=0.31), timestep=0.01)
        ex.engine("b", RECORDER.format(seed=0.52), timestep=0.02)
        ex.engine("c", RECORDER.format(seed=0.73), timestep=0.03)
        ex.function("tf_ab", RELAY.format(src="a", dst="b"))
        ex.function("tf_bc", RELAY.format(src="b", dst="c"))
        ex.function("tf_ca", RELAY.format(src="c", dst="a"))
        outputs = []
        for i in range(2):
            ex.run(3.0, run_name="run%d" % i)
            run_out = {}
            for n in "abc":
                with open(os.path.join(ex.dir, n + ".jsonl"), "rb") as f:
                    run_out[n] = f.read()
            outputs.append(run_out)
        self.assertEqual(outputs[0], outputs[1])
        self.assertEqual(len(ex.records("a")), 300)
        self.assertEqual(len(ex.records("c")), 100)


class Launcher(unittest.TestCase):
    def test_proc_cmd_start_params_and_env_params(self):
        ex = Experiment(self)
        ex.file("wrapper.sh", "#!/bin/sh\necho \"$@\" > \"$(dirname \"$0\")/args.txt\"\n"
                              "exec \"$CONVOY_TEST_BIN/convoy-engine-python_json\" \"$@\"\n")
        os.chmod(os.path.join(ex.dir, "wrapper.sh"), 0o755)
        ex.engine("e", textwrap.dedent("""\
            import os
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    with open(os.path.join(os.path.dirname(__file__), "env.txt"), "w") as f:
                        f.write(os.environ.get("MY_VAR", "unset") + " " + os.getcwd())
            """), EngineProcCmd=os.path.join(ex.dir, "wrapper.sh"),
                  EngineProcStartParams=["--type", "python_json"],
                  EngineEnvParams=["MY_VAR=hello world", "CONVOY_TEST_BIN=" + BIN_DIR])
        ex.run(0.01)
        with open(os.path.join(ex.dir, "args.txt")) as f:
            self.assertTrue(f.read().startswith("--type python_json --convoy-fd 3"))
        with open(os.path.join(ex.dir, "env.txt")) as f:
            self.assertEqual(f.read(), "hello world " + os.path.realpath(ex.dir))

    def test_engines_get_their_own_logs_and_no_port_is_needed(self):
        ex = Experiment(self)
        for name in ("a", "b", "c"):
            ex.engine(name, "from nrp_core.engines.python_json import EngineScript\n"
                            "class Script(EngineScript):\n"
                            "    def initialize(self):\n"
                            "        print('hello from', self._name)\n")
        ex.run(0.01)
        for name in ("a", "b", "c"):
            with open(os.path.join(ex.dir, "run", "logs", name + ".log")) as f:
                self.assertIn("hello from " + name, f.read())


class RemoteEngine(unittest.TestCase):
    def test_empty_launch_command_connects_over_grpc(self):
        ex = Experiment(self)
        ex.engine("local", RECORDER.format(seed=0.3))
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        ex.engine("remote", RECORDER.format(seed=0.6), ServerAddress="127.0.0.1:%d" % port,
                  EngineLaunchCommand={"LaunchType": "EmptyLaunchCommand"})
        ex.function("tf_lr", RELAY.format(src="local", dst="remote"))
        ex.function("tf_rl", RELAY.format(src="remote", dst="local"))
        server = subprocess.Popen([os.path.join(BIN_DIR, "convoy-engine-python_json"),
                                   "--address", "127.0.0.1:%d" % port], cwd=ex.dir,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            ex.run(0.1)
            server.wait(timeout=5)  # Shutdown ends the server
        finally:
            if server.poll() is None:
                server.kill()
                server.wait()
        remote = ex.records("remote")
        self.assertEqual(len(remote), 10)
        self.assertEqual(remote[-1]["got"]["t"], 90_000_000)


if __name__ == "__main__":
    unittest.main()
