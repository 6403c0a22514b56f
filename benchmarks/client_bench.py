#!/usr/bin/python3
"""NRP-Core client benchmark: run_loop(1) calls per second through python/nrp_client.

  /usr/bin/python3 benchmarks/client_bench.py [--runs 5] [--calls 5000]

A tiny experiment (written to a temporary folder): two python_json engines (10 ms), a TF
relaying a small JSON datapack from one to the other, and a status function returning a
small JsonRawData observation every cycle (done, so every call brings it back). Each run
starts the server (NrpCore), initializes, warms up with 200 calls, then times --calls
run_loop(1) calls, each after a set_json_datapack() (what an RL agent does per step).
Prints each run's calls/s and their median. A bare Python gRPC unary call costs about
150-350 us on the project's VMs; NRP-Core manages at most its loop rate (370-601 steps/s).
"""
import argparse
import os
import shutil
import socket
import statistics
import sys
import tempfile
import textwrap
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "python"))

ENGINE = textwrap.dedent("""\
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("out")
            self._registerDataPack("in")
            self._registerDataPack("action")
            self._setDataPack("out", {"t": self._time_ns, "x": 0.0})

        def runLoop(self, timestep_ns):
            a = self._getDataPack("action")
            self._setDataPack("out", {"t": self._time_ns, "x": a["u"] if a else 0.0})
    """)

TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='src', id=DataPackIdentifier('out', 'python_1'))
    @TransceiverFunction("python_2")
    def relay(src):
        return [JsonDataPack("in", "python_2", src.data)]
    """)

STATUS = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import JsonRawData

    @EngineDataPack(keyword='obs', id=DataPackIdentifier('out', 'python_1'))
    @StatusFunction()
    def status_function(obs):
        return True, [JsonRawData({"x": obs.data["x"], "t": obs.data["t"]})]
    """)

CONFIG = """{
  "SimulationName": "client_bench",
  "SimulationTimeout": 0,
  "EngineConfigs": [
    {"EngineType": "python_json", "EngineName": "python_1", "PythonFileName": "engine.py",
     "EngineTimestep": 0.01},
    {"EngineType": "python_json", "EngineName": "python_2", "PythonFileName": "engine.py",
     "EngineTimestep": 0.01}
  ],
  "DataPackProcessingFunctions": [{"Name": "relay", "FileName": "tf.py"}],
  "StatusFunction": {"Name": "status", "FileName": "status.py"}
}
"""


def free_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "127.0.0.1:%d" % s.getsockname()[1]


def one_run(folder, calls):
    from nrp_client import NrpCore
    nrp = NrpCore(free_address(), experiment_folder=folder, log_output="")
    try:
        nrp.initialize()
        for i in range(200):
            nrp.set_json_datapack("action", "python_1", {"u": 0.0})
            nrp.run_loop(1)
        t0 = time.perf_counter()
        for i in range(calls):
            nrp.set_json_datapack("action", "python_1", {"u": float(i)})
            done, data = nrp.run_loop(1)
        wall = time.perf_counter() - t0
        # the action sent before call i shows in the observation of call i + 1
        assert done and data[0]["x"] == float(calls - 2), data
        # For scale: a unary call that does next to nothing (the descriptors of a small type,
        # cached by the server's registry) through the same channel.
        from nrp_client import nrp_server_pb2 as pb
        describe, request = nrp._calls["describeType"], pb.TypeRequest(typeName="NrpCore.EmptyMessage")
        t0 = time.perf_counter()
        for i in range(calls):
            describe(request)
        bare = time.perf_counter() - t0
    finally:
        nrp.shutdown()
    return calls / wall, calls / bare


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--calls", type=int, default=5000)
    parser.add_argument("--bin-dir", default=os.path.join(REPO, "build", "bin"))
    args = parser.parse_args()
    os.environ.setdefault("CONVOY_BIN_DIR", args.bin_dir)
    folder = tempfile.mkdtemp(prefix="convoy-client-bench-")
    os.environ.setdefault("CONVOY_RUNS_DIR", os.path.join(folder, "runs"))
    try:
        for name, text in (("engine.py", ENGINE), ("tf.py", TF), ("status.py", STATUS),
                           ("simulation_config.json", CONFIG)):
            with open(os.path.join(folder, name), "w") as f:
                f.write(text)
        rates, bare = [], []
        for r in range(args.runs):
            rate, bare_rate = one_run(folder, args.calls)
            rates.append(rate)
            bare.append(bare_rate)
            print("run %d: %.0f run_loop(1) calls/s; a near-empty unary call: %.0f calls/s"
                  % (r + 1, rate, bare_rate), flush=True)
        print("client run_loop(1) calls/s (tiny experiment, median of %d runs of %d calls): %.0f"
              "  target >= 2000 (NRP-Core: its loop rate, 370-601)"
              % (args.runs, args.calls, statistics.median(rates)))
        print("near-empty unary gRPC call through the same channel, calls/s (median): %.0f"
              % statistics.median(bare))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
