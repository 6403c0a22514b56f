"""The status function of a run with a `scenario` engine: ends the run after the cycle in
which the scenario engine says it is done (its storyboard ended, or the ego passed its route's
end). List it as the config's StatusFunction:
{"Name": "scenario_status", "FileName": ".../python/convoy_scenario/status.py"}."""
import json
import os

from nrp_core import *  # noqa: F401,F403


def _scenario_engine():
    with open(os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")) as f:
        for e in json.load(f).get("EngineConfigs", []):
            if e.get("EngineType") == "scenario":
                return e["EngineName"]
    raise RuntimeError("status.py: the config has no engine of type 'scenario'")


@EngineDataPack(keyword="scenario", id=DataPackIdentifier("scenario", _scenario_engine()))
@StatusFunction()
def scenario_status(scenario):
    done = not scenario.isEmpty() and bool(scenario.data.get("done"))
    return done, []
