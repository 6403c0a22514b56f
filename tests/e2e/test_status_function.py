"""End-to-end tests of the status function in a standalone run: when it runs, what it sees
(isUpdated() of engines with different timesteps, @SimulationIteration, @SimulationTime),
its done flag, and its failures.

Run with Debian's /usr/bin/python3 -m unittest test_status_function."""

import json
import os
import textwrap

from e2e_util import E2ETestCase, basic_config, engine_script

# Logs what it sees into status.jsonl; done at iteration DONE_AT.
OBSERVER = textwrap.dedent("""\
    import json, os
    from nrp_core import *
    from nrp_core.data.nrp_json import JsonRawData

    LOG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "status.jsonl")

    @EngineDataPack(keyword='fast', id=DataPackIdentifier('fast_dp', 'fast'))
    @EngineDataPack(keyword='slow', id=DataPackIdentifier('slow_dp', 'slow'))
    @SimulationIteration(keyword="it")
    @SimulationTime(keyword="t")
    @StatusFunction()
    def status_function(fast, slow, it, t):
        with open(LOG, "a") as f:
            f.write(json.dumps({"it": it, "t": t,
                                "fast": [fast.isUpdated(), fast.data["time"]],
                                "slow": [slow.isUpdated(), slow.data["time"]]}) + "\\n")
        return it == DONE_AT, [JsonRawData({"it": it})]
    """)


class StatusFunction(E2ETestCase):
    def experiment(self, status_source, timeout=1.0, tfs=(), **status_cfg):
        self.write("fast.py", engine_script("fast"))
        self.write("slow.py", engine_script("slow"))
        self.write("status.py", status_source)
        cfg = basic_config(engines=("fast", "slow"), timeout=timeout, tfs=tfs)
        cfg["EngineConfigs"][0]["EngineTimestep"] = 0.01
        cfg["EngineConfigs"][1]["EngineTimestep"] = 0.03
        cfg["StatusFunction"] = dict({"Name": "status", "FileName": "status.py"}, **status_cfg)
        self.write_config(cfg)

    def records(self):
        with open(os.path.join(self.dir, "status.jsonl")) as f:
            return [json.loads(line) for line in f]

    def summary(self):
        with open(os.path.join(self.run_dir, "summary.json")) as f:
            return json.load(f)

    def test_runs_every_cycle_and_sees_updates_of_engines_with_different_timesteps(self):
        self.experiment(OBSERVER.replace("DONE_AT", "7"))
        r = self.run_convoy()
        self.assertExit(r, 0)
        recs = self.records()
        self.assertEqual([x["it"] for x in recs], list(range(8)))
        for x in recs:
            it = x["it"]
            self.assertEqual(x["t"], it * 10_000_000)
            # the fast engine (10 ms) delivers every cycle, the slow one (30 ms) every third
            self.assertEqual(x["fast"], [True, it * 10_000_000], x)
            self.assertEqual(x["slow"], [it % 3 == 0, it // 3 * 30_000_000], x)
        # done at iteration 7 ended the run cleanly at 70 ms, long before the 1 s timeout
        s = self.summary()
        self.assertEqual(s["exit_code"], 0)
        self.assertTrue(s["status_function_done"])
        self.assertEqual(s["cycles"], 8)
        self.assertAlmostEqual(s["sim_time_s"], 0.07)
        self.assertIn("the status function returned done at cycle 7", r.stderr)

    def test_never_done_runs_to_the_timeout(self):
        self.experiment(OBSERVER.replace("DONE_AT", "-1"), timeout=0.09)
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertEqual(len(self.records()), 10)  # 0, 10, ... 90 ms
        self.assertFalse(self.summary()["status_function_done"])

    def test_inactive_status_function_does_not_run(self):
        self.experiment(OBSERVER.replace("DONE_AT", "0"), timeout=0.05, IsActive=False)
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "status.jsonl")))
        self.assertNotIn("warning", r.stderr)

    def test_an_exception_is_a_function_failure(self):
        self.experiment(textwrap.dedent("""\
            from nrp_core import *

            @SimulationIteration(keyword="it")
            @StatusFunction()
            def status_function(it):
                if it == 2:
                    raise ValueError("boom at %d" % it)
                return False, []
            """))
        r = self.run_convoy()
        self.assertExit(r, 4)
        self.assertStderrHas(r, "status function 'status'", "status.py", "ValueError: boom at 2")
        self.assertEqual(self.scan_engine_processes(), [])

    def test_a_wrong_return_value_is_a_function_failure(self):
        for ret, says in (("[JsonRawData()]", "returned [JsonRawData"),
                          ("'yes', []", "returned a str as its done flag"),
                          ("True, JsonRawData()", "returned a JsonRawData as its data"),
                          ("True, [42]", "returned a int in its data")):
            with self.subTest(ret=ret):
                self.experiment(textwrap.dedent("""\
                    from nrp_core import *
                    from nrp_core.data.nrp_json import JsonRawData

                    @StatusFunction()
                    def status_function():
                        return %s
                    """ % ret))
                r = self.run_convoy()
                self.assertExit(r, 4)
                self.assertStderrHas(r, "status function 'status'", says,
                                     "it must return a tuple (done, [data])")

    def test_a_status_function_file_with_a_transceiver_function_is_refused(self):
        self.experiment(textwrap.dedent("""\
            from nrp_core import *

            @TransceiverFunction("fast")
            def tf():
                return []
            """))
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "status.py", "the StatusFunction file declares a "
                             "@TransceiverFunction")
        self.assertEqual(self.engine_pids(), {}, "no engine starts")

    def test_a_status_function_among_the_transceiver_functions_is_refused(self):
        self.experiment(OBSERVER.replace("DONE_AT", "0"), tfs=[("tf", "status.py")])
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "declares a @StatusFunction",
                             "configured under \"StatusFunction\"")

    def test_an_input_from_an_unknown_engine_is_refused(self):
        self.experiment(textwrap.dedent("""\
            from nrp_core import *

            @EngineDataPack(keyword='x', id=DataPackIdentifier('x', 'nobody'))
            @StatusFunction()
            def status_function(x):
                return False, []
            """))
        r = self.run_convoy()
        self.assertExit(r, 2)
        self.assertStderrHas(r, "status.py", "unknown engine 'nobody'")
