"""Records the vehicle agent's reaction to the cut-in into $CONVOY_RUN_DIR/cut_in.json:
its minimum bumper-to-bumper gap to the cut-in car once that car is in its lane, its minimum
acceleration, whether the boxes ever overlapped, and where both cars ended."""

import json
import math
import os

from nrp_core.engines.python_json import EngineScript

AGENT, CUTTER = "car_0", "cutter"


def _corners(u):
    c, s = math.cos(u["yaw"]), math.sin(u["yaw"])
    cx = u["x"] + u.get("length_offset", 0.0) * c
    cy = u["y"] + u.get("length_offset", 0.0) * s
    hl, hw = u["length"] / 2, u["width"] / 2
    return [(cx + a * hl * c - b * hw * s, cy + a * hl * s + b * hw * c)
            for a, b in ((1, 1), (1, -1), (-1, -1), (-1, 1))]


def _overlap(a, b):
    pa, pb = _corners(a), _corners(b)
    for poly in (pa, pb):
        for i in range(4):
            ex, ey = poly[(i + 1) % 4][0] - poly[i][0], poly[(i + 1) % 4][1] - poly[i][1]
            nx, ny = -ey, ex
            ra = [nx * x + ny * y for x, y in pa]
            rb = [nx * x + ny * y for x, y in pb]
            if max(ra) < min(rb) or max(rb) < min(ra):
                return False
    return True


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("users")
        self.rec = {"min_gap_m": None, "min_agent_acceleration": 0.0, "overlap": False,
                    "cut_in_time_s": None, "steps": 0}

    def runLoop(self, timestep_ns):
        d = self._getDataPack("users")
        users = {u["id"]: u for u in (d or {}).get("users", [])}
        if AGENT not in users or CUTTER not in users:
            return
        a, c = users[AGENT], users[CUTTER]
        r = self.rec
        r["steps"] += 1
        r["min_agent_acceleration"] = min(r["min_agent_acceleration"], a["acceleration"])
        r["overlap"] = r["overlap"] or _overlap(a, c)
        if c.get("lane") == a.get("lane") and c.get("road") == a.get("road"):
            if r["cut_in_time_s"] is None:
                r["cut_in_time_s"] = self._time_ns * 1e-9
            gap = ((c["x"] + c["length_offset"] - c["length"] / 2)
                   - (a["x"] + a["length_offset"] + a["length"] / 2))
            r["min_gap_m"] = gap if r["min_gap_m"] is None else min(r["min_gap_m"], gap)
        r["agent"] = {k: a[k] for k in ("x", "y", "speed", "road", "lane")}
        r["cutter"] = {k: c[k] for k in ("x", "y", "speed", "road", "lane")}
        r["cutter_ahead_in_agent_lane"] = (c.get("lane") == a.get("lane") and c["x"] > a["x"])
        self._write()

    def _write(self):
        run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
        with open(os.path.join(run_dir, "cut_in.json"), "w") as f:
            json.dump(self.rec, f, indent=1, sort_keys=True)

    def shutdown(self):
        self._write()
