"""Passing the weather engine's datapack on (docs/weather.md).

The world engine applies the weather to its cameras and wheels, and road-user engines adapt
to it; each takes it as a JSON datapack named "weather". `weather_targets()` lists the run's
engines that read it (from the run folder's config.json): every gazebo_grpc / gazebo_json,
vehicle_agent and pedestrian_agent engine. Python engines (an ego's planner, say) are not
given it: they see the weather only through their sensors.
"""
import json
import os

from nrp_core.data.nrp_json import JsonDataPack

READERS = ("gazebo_grpc", "gazebo_json", "vehicle_agent", "pedestrian_agent")


def weather_targets(config_path=None):
    """Names of the run's engines that read the weather datapack."""
    path = config_path or os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "config.json")
    with open(path) as f:
        engines = json.load(f)["EngineConfigs"]
    return [e["EngineName"] for e in engines if e.get("EngineType") in READERS]


def weather_datapacks(weather, targets, name="weather"):
    """The weather datapack (an EngineDataPack of the weather engine) for each target."""
    if weather.isEmpty():
        return []
    out = []
    for engine in targets:
        dp = JsonDataPack(name, engine)
        dp.data = weather.data
        out.append(dp)
    return out
