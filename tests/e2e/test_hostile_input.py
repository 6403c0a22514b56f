"""End-to-end tests of the coordinator on hostile input: names that would lead out of the run
folder, and inputs too large to handle.

As in test_bad_input: each test writes a small experiment into a temp folder, runs `convoy run`
and checks the exit code, one clear message naming the file and JSON pointer (or the engine,
function and datapack), that no engine process is left, and here also that nothing was created
outside the run folder.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_hostile_input
"""

import json
import os
import time
import unittest

from e2e_util import E2ETestCase, basic_config, engine_script, relay_tf

EXIT_USER, EXIT_ENGINE, EXIT_FUNCTION = 2, 3, 4
CONFIG_LIMIT = 64 << 20  # config::kMaxConfigBytes
MAX_ENGINES = 1024  # config::kMaxEngines


class HostileMixin:

    def setUp(self):
        super().setUp()
        for name in ("python_1", "python_2", "escaped"):
            self.write(name + ".py", engine_script(name))
        self.write("relay.py", relay_tf())

    def tree(self, top=None):
        """Every path under `top` (default: the temp folder) except the run folder's."""
        top = top or self.dir
        out = set()
        for root, dirs, files in os.walk(top):
            if root == self.run_dir or root.startswith(self.run_dir + os.sep):
                continue
            for n in dirs + files:
                out.add(os.path.relpath(os.path.join(root, n), top))
        return out

    def check_rejected(self, r, before, *needles):
        self.assertEqual(r.code, EXIT_USER, "expected exit 2, got: %r" % r)
        self.assertStderrHas(r, *needles)
        self.assertOneError(r)
        self.assertEqual(self.engine_pids(), {}, "no engine should have started")
        self.assertNoEngineLeft()
        self.assertEqual(self.tree() - before, set(), "created outside the run folder")


class HostileNames(HostileMixin, E2ETestCase):

    def test_engine_name_with_path_traversal(self):
        cfg = basic_config(tfs=[("relay", "relay.py")])
        # Its log would be <run>/logs/../../escaped.log, next to the run folder.
        cfg["EngineConfigs"].append({"EngineType": "python_json", "EngineName": "../../escaped",
                                     "PythonFileName": "escaped.py"})
        self.write_config(cfg)
        before = self.tree()
        r = self.run_convoy()
        self.check_rejected(
            r, before, os.path.join(self.dir, "simulation_config.json") +
            ": /EngineConfigs/2/EngineName: must not contain '/', '\\' or '..'",
            'got "../../escaped"')
        self.assertFalse(os.path.exists(os.path.join(self.dir, "escaped.log")))

    def test_engine_name_from_override(self):
        self.write_config(basic_config())
        before = self.tree()
        r = self.run_convoy("-o", "EngineConfigs/1/EngineName=../../escaped")
        self.check_rejected(r, before, ": /EngineConfigs/1/EngineName: must not contain '/'")

    def test_function_name_with_path_traversal(self):
        self.write_config(basic_config(tfs=[("../../relay", "relay.py")]))
        before = self.tree()
        r = self.run_convoy()
        self.check_rejected(r, before,
                            ": /DataPackProcessingFunctions/0/Name: must not contain '/'",
                            'got "../../relay"')

    def test_engine_name_with_nul(self):
        cfg = basic_config()
        cfg["EngineConfigs"][1]["EngineName"] = "python_2\u0000.py"
        self.write_config(cfg)
        before = self.tree()
        r = self.run_convoy()
        self.check_rejected(r, before, ": /EngineConfigs/1/EngineName: must not contain NUL",
                            '"python_2\\u0000.py"')

    def test_simulation_name_with_path_traversal(self):
        # The default run folder, $CONVOY_RUNS_DIR/<SimulationName>-<date>-<time>-<pid>, would
        # be next to the runs folder.
        runs = os.path.join(self.dir, "runs")
        os.makedirs(runs)
        self.write_config(basic_config(SimulationName="../escaped"))
        before = self.tree()
        old = dict(os.environ)
        os.environ["CONVOY_RUNS_DIR"] = runs
        try:
            r = self.run_convoy(run_dir=False)
        finally:
            os.environ.clear()
            os.environ.update(old)
        self.check_rejected(r, before, ": /SimulationName: must not contain '/'",
                            'got "../escaped"')
        self.assertEqual(os.listdir(runs), [])

    def test_simulation_name_with_spaces_runs(self):
        runs = os.path.join(self.dir, "runs")
        os.makedirs(runs)
        self.write_config(basic_config(SimulationName="My experiment", timeout=0.02))
        old = dict(os.environ)
        os.environ["CONVOY_RUNS_DIR"] = runs
        try:
            r = self.run_convoy(run_dir=False)
        finally:
            os.environ.clear()
            os.environ.update(old)
        self.assertEqual(r.code, 0, r)
        folders = os.listdir(runs)
        self.assertEqual(len(folders), 1)
        self.assertTrue(folders[0].startswith("My experiment-"), folders)
        self.assertNoEngineLeft()


class OversizedInput(HostileMixin, E2ETestCase):

    def test_config_file_of_one_gigabyte(self):
        # Sparse: no disk and no time to write it. Refused by its size, not read.
        path = os.path.join(self.dir, "simulation_config.json")
        with open(path, "w") as f:
            f.write(json.dumps(basic_config()))
            f.truncate(1 << 30)
        before = self.tree()
        t0 = time.monotonic()
        r = self.run_convoy()
        self.check_rejected(r, before, path + ": too large (1073741824 bytes; the limit for a "
                                              "config file is 64 MiB)")
        self.assertLess(time.monotonic() - t0, 10.0)

    def test_config_file_just_above_the_limit(self):
        text = json.dumps(basic_config())
        path = self.write("simulation_config.json", text + " " * (CONFIG_LIMIT + 1 - len(text)))
        self.assertEqual(os.path.getsize(path), CONFIG_LIMIT + 1)
        before = self.tree()
        r = self.run_convoy()
        self.check_rejected(r, before, path + ": too large (67108865 bytes")

    def test_ten_thousand_engines(self):
        cfg = basic_config(engines=())
        cfg["EngineConfigs"] = [{"EngineType": "python_json", "EngineName": "e%d" % i,
                                 "PythonFileName": "python_1.py"} for i in range(10000)]
        self.write_config(cfg)
        before = self.tree()
        t0 = time.monotonic()
        r = self.run_convoy()
        self.check_rejected(r, before, ": /EngineConfigs: 10000 engines, more than the limit "
                                       "of %d" % MAX_ENGINES)
        self.assertLess(time.monotonic() - t0, 10.0)

    def run_small_arena(self, *args):
        """A run with 1 MiB arenas: a message's large blobs must fit in 512 KiB."""
        old = dict(os.environ)
        os.environ["CONVOY_SHM_MB"] = "1"
        try:
            return self.run_convoy(*args)
        finally:
            os.environ.clear()
            os.environ.update(old)

    def test_function_datapack_larger_than_the_arena(self):
        self.write("big_tf.py", relay_tf(fname="make_big", body="""
            import numpy as np
            big = JsonDataPack("big", "python_2")
            big.data["pixels"] = np.zeros(2 << 20, np.uint8)
            return [big]
        """))
        self.write_config(basic_config(tfs=[("big_tf", "big_tf.py")], timeout=0.1))
        r = self.run_small_arena()
        self.assertEqual(r.code, EXIT_FUNCTION, r)
        self.assertStderrHas(r, "transceiver function 'big_tf'", "datapack 'big' of engine 'python_2': a blob of "
                             "2097152 bytes does not fit in the shared-memory arena",
                             "CONVOY_SHM_MB")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        self.assertEqual(self.summary()["exit_code"], EXIT_FUNCTION)

    def test_engine_datapack_larger_than_the_arena(self):
        self.write("python_1.py", engine_script("python_1", imports="import numpy as np", run_loop="""
            self._setDataPack("python_1_dp", {"time": self._time_ns,
                                              "pixels": np.zeros(2 << 20, np.uint8)})
        """))
        self.write_config(basic_config(tfs=[("relay", "relay.py")], timeout=0.1))
        r = self.run_small_arena()
        self.assertEqual(r.code, EXIT_ENGINE, r)
        self.assertStderrHas(r, "engine 'python_1'", "datapack 'python_1_dp' of engine "
                             "'python_1': a blob of 2097152 bytes does not fit")
        self.assertOneError(r)
        self.assertNoEngineLeft(expect_pids=("python_1", "python_2"))
        self.assertLogsKept("python_1", "python_2")
        self.assertEqual(self.summary()["exit_code"], EXIT_ENGINE)


if __name__ == "__main__":
    unittest.main()
