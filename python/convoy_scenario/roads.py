"""OpenDRIVE maps in-process: RoadMap loads a .xodr once (Convoy's C++ library through the
extension module `_convoy_odr`, src/opendrive/python) and answers lane lookups in
microseconds.

    from convoy_scenario.roads import RoadMap
    m = RoadMap("city.xodr")
    x, y, z, heading, pitch = m.lane_pose("3", -1, 25.0)

Road ids are strings, lane ids ints, angles rad, lengths m; t is OpenDRIVE's (lateral, positive
to the left of the road's reference direction). Every error (a missing or malformed map, an
unknown road or lane, a bad query) is a ScenarioError naming the file (and the line, for the
parser's), the road and the lane.

The module is built into the build's python/ directory, which Convoy's embedded interpreters
have on sys.path; elsewhere (Debian's /usr/bin/python3) it is looked for in bin_dir/../python,
$CONVOY_BIN_DIR/../python and the repository's build/python, as odr.find_odr finds convoy-odr.
"""

import importlib.machinery
import importlib.util
import os
import sys

from .xmltree import ScenarioError

MODULE = "_convoy_odr"
_module = None
_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _module_file(d):
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        f = os.path.join(d, MODULE + suffix)
        if os.path.isfile(f):
            return f
    return None


def load_module(bin_dir=None):
    """The _convoy_odr extension module: already imported or importable, else from
    bin_dir/../python, $CONVOY_BIN_DIR/../python or build/python; ScenarioError without it."""
    global _module
    if _module is None:
        mod = sys.modules.get(MODULE) or _import(bin_dir)
        mod.set_error_type(ScenarioError)
        _module = mod
    return _module


def _import(bin_dir):
    dirs = [os.path.join(d, os.pardir, "python")
            for d in (bin_dir, os.environ.get("CONVOY_BIN_DIR")) if d]
    for d in dirs:  # an explicit build first
        f = _module_file(d)
        if f:
            return _load_file(f)
    try:
        return importlib.import_module(MODULE)
    except ImportError:
        pass
    f = _module_file(os.path.join(_REPO, "build", "python"))
    if f:
        return _load_file(f)
    raise ScenarioError("the OpenDRIVE module %s was not found (in %s): it is built with Convoy "
                        "(src/opendrive/python, into build/python)" % (
                            MODULE, ", ".join(dirs + ["sys.path",
                                                      os.path.join(_REPO, "build", "python")])))


def _load_file(path):
    spec = importlib.util.spec_from_file_location(MODULE, path)
    mod = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(mod)
    except ImportError as e:
        raise ScenarioError("%s: cannot be loaded: %s" % (path, e)) from e
    sys.modules[MODULE] = mod
    return mod


_OPENED = {}   # (path, mtime, size) -> RoadMap (RoadMap.open)


class RoadMap:
    """One OpenDRIVE map. `bin_dir` (optional) is the Convoy build's bin directory whose
    ../python holds the module."""

    def __init__(self, path, bin_dir=None):
        self.path = os.fspath(path)
        self._map = load_module(bin_dir).Map(self.path)

    def __repr__(self):
        return "RoadMap(%r)" % self.path

    @classmethod
    def open(cls, path, bin_dir=None):
        """The map at path, loaded once per process (a RoadMap is immutable): the config
        generator, the functions and the player of one process share it."""
        path = os.path.abspath(os.fspath(path))
        try:
            st = os.stat(path)
            key = (path, st.st_mtime_ns, st.st_size)
        except OSError:
            return cls(path, bin_dir)   # the loader says what is wrong with the path
        if key not in _OPENED:
            _OPENED[key] = cls(path, bin_dir)
        return _OPENED[key]

    @property
    def warnings(self):
        """Non-fatal findings of the parser and the lane graph ("file: junction 4 ...")."""
        return self._map.warnings

    def query(self, op=None, **kw):
        """The reply (dict) to one of `convoy-odr query`'s ops (pose, locate, follow, route,
        info, stop_lines; src/opendrive/query.h), the same as the tool's without "ok"."""
        if op is not None:
            kw["op"] = op
        return self._map.query(kw)

    def road_ids(self):
        return self._map.road_ids()

    def road_length(self, road):
        return self._map.road_length(road)

    def road_junction(self, road):
        """The junction id of a road, "-1" outside junctions."""
        return self._map.road_junction(road)

    def lane_pose(self, road, lane, s, t=0.0):
        """(x, y, z, heading, pitch) at s on a lane, t from the lane centre (positive to the
        left of the reference direction); heading of the lane's driving direction, pitch of the
        road in that direction (OpenSCENARIO's sign: positive nose down, uphill negative)."""
        return self._map.lane_pose(road, lane, s, t)

    def road_pose(self, road, s, t=0.0):
        """(x, y, z, heading) at (s, t) from the reference line; heading of the reference
        line (increasing s)."""
        return self._map.road_pose(road, s, t)

    def lane_info(self, road, lane, s):
        """dict type, width (at s), s0, s1 (its section), forward (driven with s), junction,
        left / right (lane ids beside it to the left / right of its driving direction, across
        the centre lane too; None at the edge), change_left / change_right (a lane change to
        that side is allowed: same side, the road mark between may be crossed), centre_t
        (the lane centre's t from the reference line at s)."""
        return self._map.lane_info(road, lane, s)

    def lanes_at(self, road, s):
        """Lane ids of the section at s, left to right (highest first), without lane 0."""
        return self._map.lanes_at(road, s)

    def next_lanes(self, road, lane, s):
        """[dict(road, lane, s, forward, junction, type)]: the lanes that follow in the driving
        direction (through junctions), in the lane graph's order; s where each is entered (its
        section's start if forward, else its end)."""
        return self._map.next_lanes(road, lane, s)

    def prev_lanes(self, road, lane, s):
        """The same for the lanes before it; s where each is left (its section's end if
        forward, else its start)."""
        return self._map.prev_lanes(road, lane, s)

    def locate(self, x, y, heading=None, max_distance=5.0, lane_types=None):
        """The lane at (x, y): dict road, lane, s, t (from the lane centre), road_t (from the
        reference line), heading (lane driving direction), z, distance (0 inside the lane),
        type, junction; among lanes of lane_types only when given; with a heading, of the
        lanes the point is in the one whose direction is closest. None when no lane is within
        max_distance."""
        if lane_types is not None:
            lane_types = [lane_types] if isinstance(lane_types, str) else list(lane_types)
        return self._map.locate(x, y, heading, max_distance, lane_types)

    def route(self, from_, to, ds=2.0):
        """The shortest route between two lane positions (road, lane, s): dict points
        [[x, y, heading], ...] ds apart, length."""
        return self._map.route(from_, to, ds)

    def follow(self, road, lane, s, length, ds=2.0):
        """The lane followed onward from s for `length` m, straight on at junctions: dict
        points, length (reached), lanes [[road, lane], ...]."""
        return self._map.follow(road, lane, s, length, ds)
