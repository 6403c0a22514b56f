"""Suites, weathers and the plan of a campaign (docs/campaigns.md): which `convoy run` command
each task runs.

A suite is a folder. If it holds `suite.json`, that file lists the entries:

    {"entries": [{"name": "cut_in", "config": "../experiments/cut_in/simulation_config.json",
                  "overrides": ["EngineConfigs/0/InitialSpeed=12"]}]}

("config" relative to suite.json's folder; "name" defaults to the config's name below;
"overrides" to none; "type" to the entry type of the config's file suffix.) Otherwise every
`*.json` file in the folder with an "EngineConfigs" list is an entry, in file-name order; other
JSON files (a planner's parameters, say) are not; nor are files of a suffix no entry type
takes (ENTRY_TYPES: ".json" today). An entry's default name is its file's stem
without a leading "simulation_config_"; a bare "simulation_config" takes its folder's name
(experiments/cut_in/simulation_config.json is "cut_in", experiments/autonomous_driving/
simulation_config_rain.json is "rain"). Names must be unique and may hold letters, digits,
"_", "-" and ".": a run folder is named `<name>__s<seed>__<weather>`.

Tasks are entries x seeds x weathers, in that nesting order (entry outermost); a task's index is
its position. Seeds are 0 .. N-1.

Entry types map a file suffix to a function (entry, seed, weather, options) -> argv. The one
type today, ".json" (a simulation config), gives

    convoy run -q -c CONFIG --run-dir RUN_DIR [-o SimulationTimeout=S]
        -o EngineConfigs/<world>/GazeboRNGSeed=<seed>    (each gazebo_grpc / gazebo_json engine)
        -o EngineConfigs/<weather>/Seed=<seed>           (the engine named "weather")
        -o EngineConfigs/<weather>/<Key>=<value> ...     (the weather's keys, WEATHERS)
        -o <the entry's overrides, in order, last>

The weather engine's Schedule, if the config has one, is set to [] so that the campaign's
weather holds for the whole run. If the config gives the sun as SunAltitude / SunAzimuth, the
weather's TimeOfDay is given as those two angles instead (the weather engine takes one or the
other), computed as the engine does (sun_angles). A config without an engine named "weather"
is bad input. Another entry type (OpenSCENARIO ".xosc") registers its suffix with
register_entry_type. An entry expander (register_entry_expander) may replace an entry by
several: an OpenSCENARIO parameter distribution becomes one entry per variant
(convoy_scenario/distribution_entry.py), each with its "parameters".

Errors (bad input) raise SuiteError with a message naming the file or option.
"""

import json
import math
import os
import re

WEATHERS = {
    # Values as tools/dataset/make_dataset.py's draw_weather and experiments/autonomous_driving's
    # _rain, _fog and _night configs; every key set, so that a weather does not depend on the
    # config it is applied to.
    "clear": {"Precipitation": 0.0, "PrecipitationType": "rain", "Surface": "dry",
              "Visibility": 20000.0, "TimeOfDay": 12.0},
    "rain": {"Precipitation": 0.7, "PrecipitationType": "rain", "Surface": "wet",
             "Visibility": 20000.0, "TimeOfDay": 12.0},
    "fog": {"Precipitation": 0.0, "PrecipitationType": "rain", "Surface": "dry",
            "Visibility": 100.0, "TimeOfDay": 12.0},
    "night": {"Precipitation": 0.0, "PrecipitationType": "rain", "Surface": "dry",
              "Visibility": 20000.0, "TimeOfDay": 23.0},
    "snow": {"Precipitation": 0.5, "PrecipitationType": "snow", "Surface": "snow",
             "Visibility": 20000.0, "TimeOfDay": 12.0},
    "dusk": {"Precipitation": 0.0, "PrecipitationType": "rain", "Surface": "dry",
             "Visibility": 20000.0, "TimeOfDay": 17.8},
}
DEFAULT_WEATHERS = ("clear",)
WORLD_ENGINE_TYPES = ("gazebo_grpc", "gazebo_json")
WEATHER_ENGINE = "weather"
NAME_RE = re.compile(r"^[A-Za-z0-9_.-]+$")
ENTRY_KEYS = ("name", "config", "overrides", "type")


class SuiteError(Exception):
    """Bad input: the message names the file or option."""


def sun_angles(hours):
    """(altitude, azimuth) in degrees of the sun at `hours`, as engines/weather's sun_at: up at
    6 in the east, 60 degrees high in the south at 12, down at 18 in the west."""
    phase = (hours - 6.0) / 12.0 * math.pi
    return 60.0 * math.sin(phase), math.fmod(90.0 + (hours - 6.0) * 15.0 + 720.0, 360.0)


def parse_weathers(text):
    """The weather names of a comma-separated --weathers value, checked."""
    names = [w.strip() for w in text.split(",") if w.strip()]
    if not names:
        raise SuiteError("--weathers: no weather given (one of %s)" % ", ".join(WEATHERS))
    for w in names:
        if w not in WEATHERS:
            raise SuiteError("--weathers: unknown weather '%s' (one of %s)" % (w, ", ".join(WEATHERS)))
    if len(set(names)) != len(names):
        raise SuiteError("--weathers: a weather is given twice in '%s'" % text)
    return names


def default_name(config_path):
    stem = os.path.splitext(os.path.basename(config_path))[0]
    if stem == "simulation_config":
        return os.path.basename(os.path.dirname(os.path.abspath(config_path)))
    if stem.startswith("simulation_config_"):
        return stem[len("simulation_config_"):]
    return stem


def _read_json(path, what):
    try:
        with open(path) as f:
            return json.load(f)
    except FileNotFoundError:
        raise SuiteError("%s: %s does not exist" % (path, what)) from None
    except OSError as e:
        raise SuiteError("%s: cannot read %s: %s" % (path, what, e.strerror)) from None
    except ValueError as e:
        raise SuiteError("%s: not valid JSON: %s" % (path, e)) from None


def _is_simulation_config(doc):
    return isinstance(doc, dict) and isinstance(doc.get("EngineConfigs"), list)


def load_suite(suite_dir):
    """The suite's entries: [{"name", "config" (absolute), "overrides", "type", "source"}]."""
    if not os.path.isdir(suite_dir):
        what = "is not a folder" if os.path.exists(suite_dir) else "does not exist"
        raise SuiteError("suite folder %s %s" % (suite_dir, what))
    suite_dir = os.path.abspath(suite_dir)
    listing = os.path.join(suite_dir, "suite.json")
    entries = []
    if os.path.isfile(listing):
        doc = _read_json(listing, "the suite listing")
        items = doc.get("entries") if isinstance(doc, dict) else None
        if not isinstance(items, list) or not items:
            raise SuiteError("%s: /entries: expected a non-empty list of {\"name\", \"config\", "
                             "\"overrides\"}" % listing)
        for i, item in enumerate(items):
            where = "%s: /entries/%d" % (listing, i)
            if not isinstance(item, dict):
                raise SuiteError("%s: expected an object" % where)
            for k in item:
                if k not in ENTRY_KEYS:
                    raise SuiteError("%s/%s: unknown key (%s)" % (where, k, ", ".join(ENTRY_KEYS)))
            config = item.get("config")
            if not isinstance(config, str) or not config:
                raise SuiteError("%s/config: expected the path of a simulation config" % where)
            config = os.path.normpath(os.path.join(suite_dir, config))
            overrides = item.get("overrides", [])
            if not isinstance(overrides, list) or not all(isinstance(o, str) for o in overrides):
                raise SuiteError("%s/overrides: expected a list of \"KEY=VALUE\" strings" % where)
            for j, o in enumerate(overrides):
                if "=" not in o or o.startswith("="):
                    raise SuiteError("%s/overrides/%d: '%s' is not KEY=VALUE" % (where, j, o))
            name = item.get("name", default_name(config))
            entries.append({"name": name, "config": config, "overrides": list(overrides),
                            "type": item.get("type") or _suffix(config), "source": where})
    else:
        for f in sorted(os.listdir(suite_dir)):
            path = os.path.join(suite_dir, f)
            suffix = _suffix(f)
            if suffix not in ENTRY_TYPES or not os.path.isfile(path):
                continue
            if suffix != ".json" or _is_simulation_config(_read_json(path, "a simulation config")):
                entries.append({"name": default_name(path), "config": path, "overrides": [],
                                "type": suffix, "source": path})
        if not entries:
            raise SuiteError("suite folder %s holds no run definitions (a suite.json, or "
                             "simulation configs *.json)" % suite_dir)
    entries = _expand(entries)
    seen = {}
    for e in entries:
        if not isinstance(e["name"], str) or not NAME_RE.match(e["name"]):
            raise SuiteError("%s: name %r: use letters, digits, '_', '-' and '.'" % (e["source"], e["name"]))
        if e["name"] in seen:
            raise SuiteError("%s: name '%s' is taken by %s; give the entries names" % (
                e["source"], e["name"], seen[e["name"]]))
        seen[e["name"]] = e["source"]
        if e["type"] not in ENTRY_TYPES:
            raise SuiteError("%s: %s: no entry type for '%s' files (known: %s)" % (
                e["source"], e["config"], e["type"], ", ".join(sorted(ENTRY_TYPES))))
    return entries


def _suffix(path):
    return os.path.splitext(path)[1].lower()


def _expand(entries):
    """Each entry, or in its place the entries an expander of its type makes of it (a
    parameter distribution's variants), in order."""
    out = []
    for e in entries:
        expander = ENTRY_EXPANDERS.get(e["type"])
        more = expander(e) if expander is not None else None
        out += [e] if more is None else more
    return out


# --- entry types ------------------------------------------------------------------------------

def _override_value(v):
    """A value as `convoy run -o` reads it: JSON (strings quoted)."""
    return json.dumps(v)


def config_command(entry, seed, weather, options):
    """argv of `convoy run` for a simulation-config entry (module docstring)."""
    config = entry["config"]
    doc = _read_json(config, "the entry's simulation config")
    if not _is_simulation_config(doc):
        raise SuiteError("%s: not a simulation config (no EngineConfigs list)" % config)
    engines = doc["EngineConfigs"]
    names = [e.get("EngineName") if isinstance(e, dict) else None for e in engines]
    if WEATHER_ENGINE not in names:
        raise SuiteError("%s: no engine named '%s' to apply the weather '%s' to" % (
            config, WEATHER_ENGINE, weather))
    argv = [options["convoy"], "run", "-q", "-c", config, "--run-dir", options["run_dir"]]
    o = []
    if options.get("seconds") is not None:
        o.append("SimulationTimeout=%s" % _override_value(float(options["seconds"])))
    for i, e in enumerate(engines):
        if isinstance(e, dict) and e.get("EngineType") in WORLD_ENGINE_TYPES:
            o.append("EngineConfigs/%d/GazeboRNGSeed=%d" % (i, seed))
    w = names.index(WEATHER_ENGINE)
    o.append("EngineConfigs/%d/Seed=%d" % (w, seed))
    if "Schedule" in engines[w]:
        o.append("EngineConfigs/%d/Schedule=[]" % w)
    values = dict(WEATHERS[weather])
    if "SunAltitude" in engines[w] or "SunAzimuth" in engines[w]:
        alt, az = sun_angles(values.pop("TimeOfDay"))
        values.update(SunAltitude=round(alt, 6), SunAzimuth=round(az, 6))
    for k in sorted(values):
        o.append("EngineConfigs/%d/%s=%s" % (w, k, _override_value(values[k])))
    o += entry["overrides"]
    for item in o:
        argv += ["-o", item]
    return argv


ENTRY_TYPES = {".json": config_command}
ENTRY_EXPANDERS = {}


def register_entry_type(suffix, command):
    """Adds an entry type: `command(entry, seed, weather, options)` returns the argv of the
    task's run (options: "convoy", "run_dir", "seconds"), raising SuiteError for bad input."""
    ENTRY_TYPES[suffix.lower()] = command


def register_entry_expander(suffix, expand):
    """Adds an expander for entries of type `suffix`: `expand(entry)` returns None (the entry
    stays as it is) or the list of entries to run in its place, each with "name", "config",
    "overrides", "type", "source" and optionally "parameters" ({name: value}, shown in the
    leaderboard); SuiteError for bad input. The parameter distributions of
    convoy_scenario.distribution_entry expand so."""
    ENTRY_EXPANDERS[suffix.lower()] = expand


# --- the plan ---------------------------------------------------------------------------------

def task_name(scenario, seed, weather):
    return "%s__s%d__%s" % (scenario, seed, weather)


def make_plan(entries, seeds, weathers, out_dir, convoy, seconds=None, record=False, perception=None):
    """The campaign's plan: {"version", "out", "convoy", "seconds", "seeds", "weathers",
    "record", "tasks": [{"index", "name", "scenario", "seed", "weather", "config", "run_dir",
    "argv", ["parameters"]}]} ("parameters": a distribution variant's, when it has any). With `record` each run also writes RUN_DIR/recording.mcap (`convoy run
    --record`), which report.html links to the dashboard. With `perception` ("ground_truth" or
    "sensors": the default ego's, `convoy run --scenario --perception`) each OpenSCENARIO task
    runs with it, and the plan and its tasks say so ("perception"); a simulation-config entry
    is then bad input (its ego is the config's)."""
    out_dir = os.path.abspath(out_dir)
    if perception is not None:
        for e in entries:
            if e["type"] == ".json":
                raise SuiteError("--perception %s: applies to OpenSCENARIO entries; %s is a simulation "
                                 "config (its ego is the config's)" % (perception, e["source"]))
    tasks = []
    for e in entries:
        for seed in range(seeds):
            for weather in weathers:
                name = task_name(e["name"], seed, weather)
                run_dir = os.path.join(out_dir, "runs", name)
                argv = ENTRY_TYPES[e["type"]](e, seed, weather, {
                    "convoy": convoy, "run_dir": run_dir, "seconds": seconds, "perception": perception})
                if record:
                    argv.insert(argv.index("run") + 1, "--record")  # after `convoy run`
                task = {"index": len(tasks), "name": name, "scenario": e["name"],
                        "seed": seed, "weather": weather, "config": e["config"],
                        "run_dir": run_dir, "argv": argv}
                if e.get("parameters"):
                    task["parameters"] = dict(e["parameters"])
                if perception is not None:
                    task["perception"] = perception
                tasks.append(task)
    plan = {"version": 1, "out": out_dir, "convoy": convoy, "seconds": seconds, "seeds": seeds,
            "weathers": list(weathers), "record": bool(record), "tasks": tasks}
    if perception is not None:
        plan["perception"] = perception
    return plan
