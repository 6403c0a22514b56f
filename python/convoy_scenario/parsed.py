"""A scenario read once and handed on (docs/scenarios.md, "Running a scenario"): `convoy run
--scenario` reads the .xosc when it makes the config and saves the immutable Scenario into the
run folder (`scenario.parsed`); the scenario engine loads it instead of reading the file again,
when it was made from the same file (path, modification time, size) with the same parameters,
else it reads the file. The file is Python's pickle of the model's frozen dataclasses, written
and read by Convoy only, in the run folder it made."""

import os
import pickle

from .xosc import _load_key, load

FORMAT = 1


def save_parsed(scenario, xosc, parameters, path):
    key = _load_key(os.path.abspath(xosc), parameters or None)
    with open(path, "wb") as f:
        pickle.dump({"format": FORMAT, "key": key, "scenario": scenario}, f,
                    protocol=pickle.HIGHEST_PROTOCOL)


def load_parsed(path, xosc, parameters):
    """The Scenario saved at path when it matches the file and parameters, else the file read
    again (convoy_scenario.load)."""
    key = _load_key(os.path.abspath(xosc), parameters or None)
    if path and os.path.isfile(path):
        try:
            with open(path, "rb") as f:
                saved = pickle.load(f)
            if saved.get("format") == FORMAT and saved.get("key") == key:
                return saved["scenario"]
        except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError):
            pass
    return load(xosc, parameters=parameters or None)
