"""Trajectories of the pool (traffic_pool_bench --trace CSV) and of SUMO (--fcd-output XML) in
one layout: numpy arrays, one row per vehicle and sample, sorted by vehicle then time.

Fields: t (s), vid (vehicle index), lane (lane index; one per pool lane / SUMO lane), s (m,
the front along the lane), speed (m/s), limit (m/s, the lane's), junction (junction index,
-1 outside junctions), road (road index, -1 inside junctions), length (m, the vehicle's), x, y
(m; the pool's box centre, SUMO's front bumper in the network's frame: used for headings only).
Names of the indices: the lists under "names" (road names are OpenDRIVE road ids for both).
"""
import csv
import xml.etree.ElementTree as ET

import numpy as np


class _Codes:
    def __init__(self):
        self.index, self.names = {}, []

    def __call__(self, name):
        k = self.index.get(name)
        if k is None:
            k = self.index[name] = len(self.names)
            self.names.append(name)
        return k


def _finish(cols, roads, junctions):
    ints = ("vid", "lane", "junction", "road")
    out = {k: np.asarray(v, dtype=np.int64 if k in ints else float) for k, v in cols.items()}
    order = np.lexsort((out["t"], out["vid"]))
    out = {k: v[order] for k, v in out.items()}
    out["names"] = {"roads": roads.names, "junctions": junctions.names}
    return out


def _empty():
    return {k: [] for k in ("t", "vid", "lane", "s", "speed", "limit", "junction", "road",
                            "length", "x", "y")}


def load_pool(path):
    """The pool's trace: t,id,road,lane,pool_lane,s,lane_length,speed,accel,limit,junction,..."""
    cols, vids, roads, junctions = _empty(), _Codes(), _Codes(), _Codes()
    with open(path, newline="") as f:
        rd = csv.reader(f)
        head = next(rd)
        ix = {name: k for k, name in enumerate(head)}
        for row in rd:
            j = row[ix["junction"]]
            cols["t"].append(float(row[ix["t"]]))
            cols["vid"].append(vids(row[ix["id"]]))
            cols["lane"].append(int(row[ix["pool_lane"]]))
            cols["s"].append(float(row[ix["s"]]))
            cols["speed"].append(float(row[ix["speed"]]))
            cols["limit"].append(float(row[ix["limit"]]))
            cols["junction"].append(junctions(j) if j else -1)
            cols["road"].append(-1 if j else roads(row[ix["road"]]))
            cols["length"].append(float(row[ix["length"]]))
            cols["x"].append(float(row[ix["x"]]))
            cols["y"].append(float(row[ix["y"]]))
    return _finish(cols, roads, junctions)


def sumo_lanes(net_path):
    """Lane id -> (speed limit, junction id or None, road id or None) of a SUMO network."""
    lanes = {}
    for edge in ET.parse(net_path).getroot().iter("edge"):
        internal = edge.get("function") == "internal"
        eid = edge.get("id")
        for lane in edge.iter("lane"):
            if internal:  # ":<junction>_<link>_<lane>"
                lanes[lane.get("id")] = (float(lane.get("speed")), eid[1:].rsplit("_", 1)[0], None)
            else:
                lanes[lane.get("id")] = (float(lane.get("speed")), None, eid.lstrip("-"))
    return lanes


def load_sumo(fcd_path, net_path, length):
    """SUMO's FCD (timestep/vehicle with speed, pos and lane), vehicles `length` m long."""
    lanes = sumo_lanes(net_path)
    cols, vids, roads, junctions, lane_codes = _empty(), _Codes(), _Codes(), _Codes(), _Codes()
    t = 0.0
    for event, el in ET.iterparse(fcd_path, events=("start", "end")):
        if event == "start":
            if el.tag == "timestep":
                t = float(el.get("time"))
            continue
        if el.tag == "vehicle":
            lid = el.get("lane")
            limit, junction, road = lanes[lid]
            cols["t"].append(t)
            cols["vid"].append(vids(el.get("id")))
            cols["lane"].append(lane_codes(lid))
            cols["s"].append(float(el.get("pos")))
            cols["speed"].append(float(el.get("speed")))
            cols["limit"].append(limit)
            cols["junction"].append(junctions(junction) if junction else -1)
            cols["road"].append(roads(road) if road else -1)
            cols["length"].append(length)
            cols["x"].append(float(el.get("x")))
            cols["y"].append(float(el.get("y")))
        elif el.tag == "timestep":
            el.clear()
    return _finish(cols, roads, junctions)
