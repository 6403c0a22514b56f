"""Where points lie on an OpenDRIVE map, read with the standard library and numpy: the road,
the lane and its type, whether the road is in a junction, the lane's direction of travel and
its speed limit. Enough for the city map (experiments/city_traffic/city.xodr) and the Parkring
(experiments/autonomous_driving/parkring.xodr): line, arc, spiral (integrated numerically) and
paramPoly3 geometries, lane offsets, lane sections, lane width polynomials, speeds of road types
or lanes. Other geometries (poly3) are refused (ValueError).

Rules:
- Each road's reference line is sampled every SAMPLE_M (0.25 m). A point lies on a road when
  its nearest sample's tangent puts it between s = 0 and the road's length; its lateral offset
  t (left positive) then gives the lane whose span holds it (none beyond the outermost lane).
- A point is on the carriageway (`on_road`) when on some road it is within the span of the
  driving lanes widened by ROAD_TOLERANCE_M (0.5 m, as CARLA's OutsideRouteLanesTest allows
  beyond a driving lane).
- When several roads hold a point, the one reported is, in order: in a driving lane, not in a
  junction, travelled within 45 deg of the point's heading (when headings are given), nearest
  to its reference line, smallest road id.
- Direction of travel: right-hand traffic (rule "RHT", the default) drives lanes with negative
  ids along s and positive ids against it; "LHT" the other way.
- Speed limit (m/s): the lane's <speed>, else the road type's. For a road in a junction, the
  highest of its predecessor's and successor's limits (nuPlan gives a lane connector the
  limits of the lanes it joins); its own when it has no linked road.
"""

import math
import xml.etree.ElementTree as ET

import numpy as np

SAMPLE_M = 0.25
ROAD_TOLERANCE_M = 0.5
ALIGNED_COS = math.cos(math.radians(45.0))
UNITS = {"m/s": 1.0, "km/h": 1.0 / 3.6, "mph": 0.44704}


def _geometry_points(g, step):
    """(s, x, y, heading) samples along one <geometry>."""
    s0, x0, y0, h0, length = (float(g.get(k)) for k in ("s", "x", "y", "hdg", "length"))
    n = max(2, int(math.ceil(length / step)) + 1)
    ds = np.linspace(0.0, length, n)
    kind = g[0].tag if len(g) else None
    if kind == "line":
        return s0 + ds, x0 + ds * math.cos(h0), y0 + ds * math.sin(h0), np.full(n, h0)
    if kind == "arc":
        k = float(g[0].get("curvature"))
        if abs(k) < 1e-12:
            return s0 + ds, x0 + ds * math.cos(h0), y0 + ds * math.sin(h0), np.full(n, h0)
        h = h0 + k * ds
        return s0 + ds, x0 + (np.sin(h) - math.sin(h0)) / k, y0 - (np.cos(h) - math.cos(h0)) / k, h
    if kind == "paramPoly3":
        c = {k: float(g[0].get(k, 0.0)) for k in ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV")}
        p = ds if g[0].get("pRange") == "arcLength" else ds / length
        u = c["aU"] + c["bU"] * p + c["cU"] * p ** 2 + c["dU"] * p ** 3
        v = c["aV"] + c["bV"] * p + c["cV"] * p ** 2 + c["dV"] * p ** 3
        du = c["bU"] + 2 * c["cU"] * p + 3 * c["dU"] * p ** 2
        dv = c["bV"] + 2 * c["cV"] * p + 3 * c["dV"] * p ** 2
        ch, sh = math.cos(h0), math.sin(h0)
        return s0 + ds, x0 + u * ch - v * sh, y0 + u * sh + v * ch, h0 + np.arctan2(dv, du)
    if kind == "spiral":
        # a clothoid: curvature from curvStart to curvEnd linearly; integrated numerically on a
        # grid 10 times finer than the samples (trapezoids on cos / sin of the heading)
        k0, k1 = float(g[0].get("curvStart")), float(g[0].get("curvEnd"))
        fine = np.linspace(0.0, length, 10 * (n - 1) + 1)
        hf = h0 + k0 * fine + 0.5 * (k1 - k0) / length * fine * fine
        dx = np.concatenate([[0.0], np.cumsum(0.5 * (np.cos(hf[1:]) + np.cos(hf[:-1])) * np.diff(fine))])
        dy = np.concatenate([[0.0], np.cumsum(0.5 * (np.sin(hf[1:]) + np.sin(hf[:-1])) * np.diff(fine))])
        return s0 + fine[::10], x0 + dx[::10], y0 + dy[::10], hf[::10]
    raise ValueError("geometry %r at s=%g is not supported (line, arc, spiral, paramPoly3)" % (kind, s0))


def _speed(elem):
    if elem is None or elem.get("max") in (None, "no limit", "undefined"):
        return None
    return float(elem.get("max")) * UNITS.get(elem.get("unit", "m/s"), 1.0)


def load(path):
    """The map of an .xodr file: {"roads": [road dicts], "by_id": {id: road}}."""
    root = ET.parse(path).getroot()
    roads = []
    for r in root.findall("road"):
        rid = r.get("id")
        offsets = sorted((float(o.get("s", 0.0)), [float(o.get(k, 0.0)) for k in "abcd"])
                         for o in r.findall("lanes/laneOffset"))
        parts = [_geometry_points(g, SAMPLE_M) for g in r.find("planView").findall("geometry")]
        s, x, y, h = (np.concatenate([p[i] for p in parts]) for i in range(4))
        sections = []
        for sec in r.findall("lanes/laneSection"):
            lanes = {}
            for lane in sec.iter("lane"):
                lid = int(lane.get("id"))
                if lid == 0:
                    continue
                widths = sorted((float(w.get("sOffset", 0.0)), [float(w.get(k, 0.0)) for k in "abcd"])
                                for w in lane.findall("width"))
                lanes[lid] = {"type": lane.get("type"), "widths": widths,
                              "speed": _speed(lane.find("speed"))}
            sections.append((float(sec.get("s", 0.0)), lanes))
        links = [e.get("elementId") for tag in ("predecessor", "successor")
                 for e in r.findall("link/" + tag) if e.get("elementType", "road") == "road"]
        road = {"id": rid, "junction": r.get("junction", "-1") != "-1", "length": float(r.get("length")),
                "s": s, "x": x, "y": y, "h": h, "sections": sorted(sections, key=lambda p: p[0]),
                "speed": _speed(r.find("type/speed")), "links": links, "lht": r.get("rule") == "LHT",
                "offsets": offsets}
        road["bbox"] = (x.min(), x.max(), y.min(), y.max(), _max_extent(road))
        roads.append(road)
    return {"roads": roads, "by_id": {r["id"]: r for r in roads}}


def _width(rec, ds):
    a, b, c, d = rec
    return a + b * ds + c * ds * ds + d * ds ** 3


def _lane_spans(road, s):
    """{lane id: (t_inner, t_outer, type, speed)} at s (t signed, left positive)."""
    sec_s, lanes = road["sections"][0]
    for ss, ls in road["sections"]:
        if ss <= s + 1e-9:
            sec_s, lanes = ss, ls
    spans = {}
    base = 0.0
    applicable = [o for o in road.get("offsets", ()) if o[0] <= s + 1e-9]
    if applicable:
        base = _width(applicable[-1][1], s - applicable[-1][0])  # <laneOffset>: the centre lane's t
    for side in (1, -1):
        edge = base
        for lid in sorted((k for k in lanes if k * side > 0), key=abs):
            ws = lanes[lid]["widths"]
            w = 0.0
            if ws:
                applicable = [p for p in ws if p[0] <= s - sec_s + 1e-9]
                off, rec = applicable[-1] if applicable else ws[0]
                w = _width(rec, s - sec_s - off)
            spans[lid] = (edge, edge + side * w, lanes[lid]["type"], lanes[lid]["speed"])
            edge += side * w
    return spans


def _max_extent(road):
    ext = 0.0
    for s in (0.0, road["length"]):
        for lo, hi, _, _ in _lane_spans(road, s).values():
            ext = max(ext, abs(lo), abs(hi))
    return ext


def _speed_limit(m, road, lane_speed):
    own = lane_speed if lane_speed is not None else road["speed"]
    if not road["junction"]:
        return own
    linked = [m["by_id"][i]["speed"] for i in road["links"] if i in m["by_id"] and m["by_id"][i]["speed"] is not None]
    return max(linked) if linked else own


def locate(m, xs, ys, yaws=None):
    """Per point (optionally with its heading): {"road", "lane", "lane_type", "junction",
    "heading" (the lane's direction of travel, or None off the lanes), "speed_limit",
    "on_road"}; road and lane None off every road."""
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    n = len(xs)
    hits = [[] for _ in range(n)]
    on_road = np.zeros(n, bool)
    for road in m["roads"]:
        x0, x1, y0, y1, ext = road["bbox"]
        pad = ext + 1.0
        idx = np.nonzero((xs >= x0 - pad) & (xs <= x1 + pad) & (ys >= y0 - pad) & (ys <= y1 + pad))[0]
        if len(idx) == 0:
            continue
        dx = xs[idx, None] - road["x"][None, :]
        dy = ys[idx, None] - road["y"][None, :]
        near = np.argmin(dx * dx + dy * dy, axis=1)
        rows = np.arange(len(idx))
        h = road["h"][near]
        ddx, ddy = dx[rows, near], dy[rows, near]
        s = road["s"][near] + ddx * np.cos(h) + ddy * np.sin(h)
        t = -ddx * np.sin(h) + ddy * np.cos(h)
        for k, i in enumerate(idx):
            if not (-1e-6 <= s[k] <= road["length"] + 1e-6):
                continue
            spans = _lane_spans(road, float(s[k]))
            drive = [v for sp in spans.values() if sp[2] == "driving" for v in sp[:2]]
            if drive and min(drive) - ROAD_TOLERANCE_M <= t[k] <= max(drive) + ROAD_TOLERANCE_M:
                on_road[i] = True
            for lid, (a, b, ltype, lspeed) in spans.items():
                if min(a, b) <= t[k] <= max(a, b):
                    along = (lid < 0) != road["lht"]
                    travel = float(h[k]) if along else float(h[k]) + math.pi
                    misaligned = yaws is not None and math.cos(travel - float(yaws[i])) < ALIGNED_COS
                    hits[i].append((ltype != "driving", road["junction"], misaligned, abs(float(t[k])),
                                    road["id"], lid, ltype, travel, lspeed, road))
                    break
    out = []
    for i in range(n):
        if not hits[i]:
            out.append({"road": None, "lane": None, "lane_type": None, "junction": False, "heading": None,
                        "speed_limit": None, "on_road": bool(on_road[i])})
            continue
        best = min(hits[i], key=lambda e: e[:5])
        _, junction, _, _, rid, lid, ltype, heading, lspeed, road = best
        out.append({"road": rid, "lane": lid, "lane_type": ltype, "junction": junction,
                    "heading": math.atan2(math.sin(heading), math.cos(heading)),
                    "speed_limit": _speed_limit(m, road, lspeed) if ltype == "driving" else None,
                    "on_road": bool(on_road[i])})
    return out
