"""Worlds for maps the project has no world of: `convoy-odr world` generates one from the map
alone (src/worldgen, docs/worlds.md), cached by the map's content so that the next run starts
at once.

Cache: $CONVOY_CACHE_DIR, else $XDG_CACHE_HOME/convoy, else ~/.cache/convoy, under worlds/;
CONVOY_CACHE_DIR=off generates into the run folder instead. An entry is named by a hash of the
map's bytes, the scenery and seed, the generator binary and the scenery catalog, so a changed
map or a rebuilt generator makes a new entry. The generator writes a folder whole or not at
all, so an entry that exists is complete."""

import hashlib
import os
import subprocess
import sys
import time

from .odr import find_odr
from .xmltree import ScenarioError

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SCENERIES = ("auto", "none", "roadside", "urban")


def cache_root():
    """The cache folder for generated worlds, or None when caching is off."""
    base = os.environ.get("CONVOY_CACHE_DIR")
    if base == "off":
        return None
    if not base:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        base = os.path.join(xdg, "convoy")
    return os.path.join(base, "worlds")


def catalog_path(odr_binary):
    """The scenery catalog convoy-odr reads: next to the binaries, else in the source tree."""
    shared = os.path.join(os.path.dirname(os.path.dirname(odr_binary)), "share", "convoy", "models",
                          "convoy_scenery", "scenery_models.json")
    if os.path.exists(shared):
        return shared
    return os.path.join(REPO, "engines", "gazebo_grpc", "scenery", "scenery_models.json")


def _digest(*paths, extra=""):
    h = hashlib.sha256(extra.encode())
    for p in paths:
        h.update(b"\0" + p.encode() + b"\0")
        if os.path.exists(p):
            with open(p, "rb") as f:
                for chunk in iter(lambda: f.read(1 << 20), b""):
                    h.update(chunk)
    return h.hexdigest()


def default_scenery(xodr):
    """urban where the map has sidewalks (a town), roadside otherwise."""
    with open(xodr, "rb") as f:
        return "urban" if b'type="sidewalk"' in f.read() else "roadside"


def generated_world(xodr, bin_dir=None, scenery="auto", seed=1, out_dir=None, log=sys.stderr):
    """The world.sdf generated for a map: from the cache, else generated (and cached)."""
    if scenery not in SCENERIES:
        raise ScenarioError("scenery must be one of %s, got %r" % (", ".join(SCENERIES), scenery))
    if not os.path.exists(xodr):
        raise ScenarioError("%s: the map does not exist" % xodr)
    if scenery == "auto":
        scenery = default_scenery(xodr)
    odr = find_odr(bin_dir)
    key = _digest(os.path.abspath(xodr), odr, catalog_path(odr), extra="%s/%d/v1" % (scenery, seed))
    name = os.path.splitext(os.path.basename(xodr))[0]
    root = cache_root()
    folder = os.path.join(root, "%s-%s" % (name, key[:20])) if root else os.path.join(out_dir or ".", "world")
    world = os.path.join(folder, "world.sdf")
    if root and os.path.exists(world):
        print("world: %s (generated from %s, cached)" % (world, os.path.basename(xodr)), file=log)
        return world
    os.makedirs(os.path.dirname(folder), exist_ok=True)
    t0 = time.monotonic()
    p = subprocess.run([odr, "world", xodr, folder, "--scenery", scenery, "--seed", str(seed)],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        lines = [l for l in p.stderr.splitlines() if not l.startswith("warning:")]
        raise ScenarioError("cannot make a world of %s: %s" % (xodr, "; ".join(lines) or "convoy-odr failed"))
    warnings = [l for l in p.stderr.splitlines() if l.startswith("warning:")]
    print("world: %s (generated from %s in %.2f s, --scenery %s, %d warnings%s)"
          % (world, os.path.basename(xodr), time.monotonic() - t0, scenery, len(warnings),
             ": see convoy-odr world" if warnings else ""), file=log)
    return world
