"""Parameter distributions in campaigns (docs/campaigns.md): an `.xosc` entry whose file is an
OpenSCENARIO ParameterValueDistribution (convoy_scenario.distribution) becomes one entry per
variant, in the distribution's order:

    name        <entry name>_<NNN>    (NNN: the variant's 1-based number, as in its name)
    config      the scenario file the distribution refers to
    parameters  the variant's values ({name: value}; the leaderboard's `parameters` column)
    overrides   the distribution entry's own

Each variant runs like an `.xosc` entry (the `.xosc` entry type's command: seed, weather,
overrides) with its parameters given to the scenario (`convoy run --scenario FILE
--scenario-param NAME=VALUE ...`).
A stochastic distribution without a randomSeed is drawn with seed 0, so a campaign's
variants are the same every time; the campaign's --seeds then repeat each variant.

An `.xosc` file that is not a distribution (or cannot be read: its run says why) stays an
ordinary entry. A distribution that cannot be expanded is bad input (SuiteError: the entry
and file:line: <Element>).
"""

import json
import os

from convoy_campaign.suite import ENTRY_TYPES, SuiteError, register_entry_expander, register_entry_type

from .distribution import expand
from .xmltree import ScenarioError, parse_file

VARIANT_TYPE = ".xosc-variant"
DISTRIBUTION_SEED = 0


def _is_distribution(path):
    try:
        root = parse_file(path)
    except ScenarioError:
        return False  # not readable: the run reports it as for any scenario
    return any(c.tag == "ParameterValueDistribution" for c in root.children)


def expand_entry(entry):
    """None for an ordinary scenario, else the variants' entries (module docstring)."""
    path = entry["config"]
    if not os.path.isfile(path) or not _is_distribution(path):
        return None
    try:
        d = expand(path, DISTRIBUTION_SEED)
    except ScenarioError as e:
        raise SuiteError("%s: %s" % (entry["source"], e)) from None
    out = []
    for v in d.variants:
        number = v.name.rsplit("_", 1)[1]
        out.append({"name": "%s_%s" % (entry["name"], number), "config": d.scenario_file,
                    "overrides": list(entry["overrides"]), "type": VARIANT_TYPE,
                    "source": "%s (variant %s of %s)" % (entry["source"], number, os.path.basename(path)),
                    "parameters": v.values, "distribution": d.path})
    return out


def variant_command(entry, seed, weather, options):
    """argv of a variant's task: the `.xosc` entry type's `convoy run --scenario` command with
    the variant's scenario parameters."""
    run = ENTRY_TYPES[".xosc"](entry, seed, weather, options)
    for k, v in (entry.get("parameters") or {}).items():
        run += ["--scenario-param", "%s=%s" % (k, json.dumps(v))]
    return run


def register():
    """After the `.xosc` entry type (convoy_scenario.campaign_entry.register)."""
    register_entry_expander(".xosc", expand_entry)
    register_entry_type(VARIANT_TYPE, variant_command)
