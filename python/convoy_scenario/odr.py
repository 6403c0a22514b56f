"""Lane lookups on an OpenDRIVE map through `convoy-odr query` (tools/opendrive): one child
process per map, JSON requests and replies a line each. Used by the config generator
(make_config.py) and the scenario engine (engine.py) to turn LanePositions into world poses,
to find the lane a world point is on, and to follow a lane onward (the ego's default route).

The child reads its requests from a pipe and exits when the pipe closes, so it never outlives
its parent (a killed parent closes the pipe)."""

import json
import os
import shutil
import subprocess

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
    def __init__(self, xodr, bin_dir=None):
        self.xodr = xodr
        self.proc = subprocess.Popen([find_odr(bin_dir), "query", xodr], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     bufsize=1)

    def ask(self, **request):
        try:
            self.proc.stdin.write(json.dumps(request) + "\n")
            self.proc.stdin.flush()
            line = self.proc.stdout.readline()
        except BrokenPipeError:
            line = ""
        if not line:
            err = self.proc.stderr.read().strip() if self.proc.poll() is not None else ""
            raise ScenarioError("%s: convoy-odr query failed%s" % (
                os.path.basename(self.xodr), ": " + err if err else ""))
        reply = json.loads(line)
        if not reply.pop("ok"):
            raise ScenarioError("%s: %s: %s" % (os.path.basename(self.xodr), request.get("op"),
                                                reply["error"]))
        return reply

    def pose(self, road, lane, s, offset=0.0):
        """(x, y, heading in the lane's driving direction) of a lane position."""
        r = self.ask(op="pose", road=str(road), lane=int(lane), s=float(s), offset=float(offset))
        return r["x"], r["y"], r["heading"]

    def locate(self, x, y, yaw=None, max_distance=5.0):
        """The lane at (x, y): dict road, lane, s, t, road_t, heading, distance, type, junction;
        None when no road is within max_distance."""
        r = self.ask(op="locate", x=float(x), y=float(y), yaw=yaw, max_distance=max_distance)
        return r if r.get("found") else None

    def follow(self, road, lane, s, length, ds=2.0):
        return self.ask(op="follow", road=str(road), lane=int(lane), s=float(s),
                        length=float(length), ds=float(ds))

    def route(self, frm, to, ds=2.0):
        return self.ask(op="route", ds=float(ds), **{"from": [str(frm[0]), int(frm[1]), float(frm[2])],
                                                       "to": [str(to[0]), int(to[1]), float(to[2])]})

    def info(self):
        return self.ask(op="info")

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for f in (self.proc.stdout, self.proc.stderr):
            f.close()

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
