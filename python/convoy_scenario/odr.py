"""Lane lookups on an OpenDRIVE map: OdrQuery answers `convoy-odr query`'s ops (tools/opendrive,
src/opendrive/query.h) in-process on a RoadMap (roads.py; it used to run the tool as a child
process, and its replies are the same). Used by the config generator (make_config.py) and the
scenario engine (engine_script.py) to turn LanePositions into world poses, to find the lane a
world point is on, and to follow a lane onward (the ego's default route). find_odr finds the
convoy-odr program for what still runs it (worlds.py)."""

import os
import shutil

from .roads import RoadMap
from .xmltree import ScenarioError


def find_odr(bin_dir=None):
    """The convoy-odr binary: in bin_dir, $CONVOY_BIN_DIR, next to this package's build, or on
    PATH."""
    here = os.path.dirname(os.path.abspath(__file__))
    repo = os.path.dirname(os.path.dirname(here))
    for d in (bin_dir, os.environ.get("CONVOY_BIN_DIR"), os.path.join(repo, "build", "bin")):
        if d and os.access(os.path.join(d, "convoy-odr"), os.X_OK):
            return os.path.join(d, "convoy-odr")
    found = shutil.which("convoy-odr")
    if not found:
        raise ScenarioError("convoy-odr not found ($CONVOY_BIN_DIR, build/bin, PATH): it is "
                            "built with Convoy (tools/opendrive)")
    return found


class OdrQuery:
    """The query ops on one map; bin_dir (optional) is the Convoy build's bin directory (the
    module is found in bin_dir/../python, see roads.py)."""

    def __init__(self, xodr, bin_dir=None):
        self.xodr = xodr
        self.map = RoadMap.open(xodr, bin_dir)

    def ask(self, **request):
        """The reply to one request (dict with "op"); ScenarioError "file: op: error"."""
        if self.map is None:
            raise ScenarioError("%s: the map was closed" % os.path.basename(self.xodr))
        return self.map.query(**request)

    def pose(self, road, lane, s, offset=0.0):
        """(x, y, heading in the lane's driving direction) of a lane position."""
        x, y, _, h, _ = self.map.lane_pose(str(road), int(lane), float(s), float(offset))
        return x, y, h

    def locate(self, x, y, yaw=None, max_distance=5.0):
        """The lane at (x, y): dict found, road, lane, s, t, road_t, heading, z, distance, type,
        junction; None when no road is within max_distance."""
        r = self.map.locate(float(x), float(y), None if yaw is None else float(yaw),
                            float(max_distance))
        if r is not None:
            r["found"] = True
        return r

    def follow(self, road, lane, s, length, ds=2.0):
        return self.ask(op="follow", road=str(road), lane=int(lane), s=float(s),
                        length=float(length), ds=float(ds))

    def route(self, frm, to, ds=2.0):
        return self.ask(op="route", ds=float(ds), **{"from": [str(frm[0]), int(frm[1]), float(frm[2])],
                                                       "to": [str(to[0]), int(to[1]), float(to[2])]})

    def info(self):
        return self.ask(op="info")

    def close(self):
        self.map = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def world_pose(odr, position):
    """(x, y, yaw) of a position dict as actions.py gives ({"type": "world", x, y, h} or
    {"type": "lane", road, lane, s, offset[, orientation]}). A world position without h takes
    the heading of the lane it is on (0 off the road)."""
    if position["type"] == "world":
        h = position.get("h")
        if h is None:
            loc = odr.locate(position["x"], position["y"])
            h = loc["heading"] if loc else 0.0
        return float(position["x"]), float(position["y"]), float(h)
    x, y, h = odr.pose(position["road"], position["lane"], position["s"], position.get("offset", 0.0))
    o = position.get("orientation")
    if o:
        h = o["h"] if o.get("type") == "absolute" else h + o.get("h", 0.0)
    return x, y, h
