"""The campaign runner's `.xosc` entry type (docs/campaigns.md, "Adding an entry type";
docs/scenarios.md, "Campaigns"): a task runs

    convoy run -q --scenario FILE.xosc --run-dir RUN_DIR [--perception P] [-o SimulationTimeout=S]
        -o EngineConfigs/0/GazeboRNGSeed=<seed> -o EngineConfigs/1/Seed=<seed>
        [-o EngineConfigs/1/<Key>=<value> ...]   the campaign's weather, unless it is "clear"
        -o <the entry's overrides>

In the generated config the world engine is EngineConfigs/0 and the weather engine
EngineConfigs/1 (make_config.py). The weather "clear" (the campaign's default) keeps the
scenario's own weather, its Init EnvironmentActions (the suite's rain and fog scenarios set
theirs); any other weather of the campaign replaces it (Schedule set to [])."""

from convoy_campaign.suite import WEATHERS, register_entry_type, sun_angles, _override_value

WORLD_INDEX = 0
WEATHER_INDEX = 1


def xosc_command(entry, seed, weather, options):
    argv = [options["convoy"], "run", "-q", "--scenario", entry["config"], "--run-dir", options["run_dir"]]
    if options.get("perception"):   # the campaign's --perception
        argv += ["--perception", options["perception"]]
    o = []
    if options.get("seconds") is not None:
        o.append("SimulationTimeout=%s" % _override_value(float(options["seconds"])))
    o.append("EngineConfigs/%d/GazeboRNGSeed=%d" % (WORLD_INDEX, seed))
    o.append("EngineConfigs/%d/Seed=%d" % (WEATHER_INDEX, seed))
    if weather != "clear":
        values = dict(WEATHERS[weather])
        o.append("EngineConfigs/%d/Schedule=[]" % WEATHER_INDEX)
        for k in sorted(values):
            o.append("EngineConfigs/%d/%s=%s" % (WEATHER_INDEX, k, _override_value(values[k])))
    o += entry["overrides"]
    for item in o:
        argv += ["-o", item]
    return argv


def register():
    register_entry_type(".xosc", xosc_command)
