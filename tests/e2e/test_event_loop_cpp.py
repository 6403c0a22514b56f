"""End-to-end: NRP-Core's cpp_nodes_simple example (experiments/nrp_event_loop/
cpp_nodes_simple, files unchanged) as NRP-Core's README runs it: `build_fn_factory_module.sh
test.h` in the experiment's folder, then `NRPCoreSim -c simulation_config.json` (SimulationLoop
EventLoop, Timeout 1 s, Timestep 0.1 s). py_node_2 prints var_x each cycle: 0, 1, 2... with no
gap, about 10 of them, exit 0. A graph naming a module that was not built: exit 2, one message
naming it.

FtiLoop (runs today): test.h's C++ nodes in the FTILoop's graph ("DataPackProcessor": "cg")
inside the coordinator's embedded Python: an engine's time goes through from_python and
to_python to a python_json engine, step by step.

CppNodes is skipped, saying so, while the coordinator has no EventLoop (it warns
"SimulationLoop EventLoop is not available yet", or finds no EngineConfigs).

Run with Debian's /usr/bin/python3 -m unittest -v test_event_loop_cpp."""

import json
import os
import re
import shutil
import subprocess
import textwrap

from e2e_util import BIN_DIR, NRPCORESIM, E2ETestCase, basic_config, engine_script

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLE = os.path.join(REPO, "experiments", "nrp_event_loop", "cpp_nodes_simple")
BUILD = os.path.join(BIN_DIR, "build_fn_factory_module.sh")
# What the coordinator says while it has no EventLoop (a config without engines is valid only
# for the EventLoop).
NOT_BUILT = ("SimulationLoop EventLoop is not available yet", "/EngineConfigs: is required")


# The sink engine records what it got in each step into dst.jsonl.
SINK = engine_script("dst", initialize="""
    self._registerDataPack("in")
    self.log = open(os.path.join(_HERE, "dst.jsonl"), "w")
    """, run_loop="""
    self.log.write(json.dumps(self._getDataPack("in")) + "\\n")
    self.log.flush()
    """, imports="import json")

FTI_GRAPH = textwrap.dedent("""\
    from nrp_core.event_loop import *
    from nrp_core.data.nrp_json import JsonDataPack

    @FromEngine(keyword="dp", address="/src/src_dp")
    @FunctionalNode(name="ms", outputs=["ms"])
    def ms(dp):
        return [dp.data["time"] // 1000000]

    p = node_policies.functional_node.exec_policy.on_new_message
    fn = createFNFromFactoryModule(module_name="libFNFactoryModule.so",
                                   function_name="from_python", node_name="cpp_1", exec_policy=p)
    FromFunctionalNode("i1", "/ms/ms")(fn)
    fn = createFNFromFactoryModule(module_name="libFNFactoryModule.so",
                                   function_name="to_python", node_name="cpp_2", exec_policy=p)
    FromFunctionalNode("i1", "/cpp_1/o1")(fn)

    @FromFunctionalNode("v", "/cpp_2/o1")
    @ToEngine(keyword="out", address="/dst")
    @FunctionalNode(name="pack", outputs=["out"])
    def pack(v):
        dp = JsonDataPack("in", "dst")
        dp.data["ms"] = v
        return [dp]
    """)


class CppNodesBase(E2ETestCase):
    def setUp(self):
        super().setUp()
        for name in ("fn.py", "test.h", "simulation_config.json"):
            shutil.copy(os.path.join(EXAMPLE, name), self.dir)

    def build_module(self):
        r = subprocess.run([BUILD, "test.h"], cwd=self.dir, capture_output=True, text=True,
                           timeout=240)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.dir, "libFNFactoryModule.so")))

    def output(self, r):
        """stdout, stderr and the run's logs: where py_node_2's prints may go."""
        text = r.stdout + r.stderr
        logs = os.path.join(self.run_dir, "logs")
        for name in sorted(os.listdir(logs)) if os.path.isdir(logs) else []:
            with open(os.path.join(logs, name), errors="replace") as f:
                text += f.read()
        return text

    def skip_without_event_loop(self, r):  # noqa: D102
        for symptom in NOT_BUILT:
            if symptom in r.stderr + r.stdout:
                self.skipTest("the coordinator has no EventLoop yet (%s)" % symptom)


class CppNodes(CppNodesBase):
    def test_example_runs(self):
        self.build_module()
        r = self.run_convoy(binary=NRPCORESIM)
        self.skip_without_event_loop(r)
        self.assertExit(r, 0)
        printed = [int(x) for x in re.findall(r"^(\d+)$", self.output(r), re.M)]
        self.assertGreaterEqual(len(printed), 5, self.output(r))
        self.assertLessEqual(len(printed), 11, self.output(r))
        self.assertEqual(printed, list(range(len(printed))))

    def test_module_not_built(self):
        r = self.run_convoy(binary=NRPCORESIM)
        self.skip_without_event_loop(r)
        self.assertExit(r, 2)
        self.assertStderrHas(r, "libFNFactoryModule.so", "could not be loaded",
                             "build_fn_factory_module.sh")


class FtiLoop(CppNodesBase):
    def test_cpp_nodes_in_fti_graph(self):
        self.build_module()
        self.write("src.py", engine_script("src"))
        self.write("dst.py", SINK)
        self.write("graph.py", FTI_GRAPH)
        self.write_config(basic_config(engines=("src", "dst"), timeout=0.05, timestep=0.01,
                                       DataPackProcessor="cg", ComputationalGraph=["graph.py"]))
        r = self.run_convoy(binary=NRPCORESIM)
        self.assertExit(r, 0)
        with open(os.path.join(self.dir, "dst.jsonl")) as f:
            got = [json.loads(line) for line in f]
        # dst's step k gets what the graph made at cycle k from src's time then (ms), as in
        # test_event_loop.FtiCg: through the two C++ nodes, unchanged
        self.assertEqual(got, [{"ms": 10 * k} for k in range(len(got))], r)
        self.assertGreaterEqual(len(got), 4)
