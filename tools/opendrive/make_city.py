#!/usr/bin/python3
"""Generates experiments/city_traffic/city.xodr, a small town grid for the city_traffic experiment.

Layout (x east, y north, metres): a main road runs west-east through two junctions,
J1 = junction 100 at (0, 0) and J2 = junction 200 at (200, 0). Each junction also has a side
road running north and south. The north arm of J1 bends to the north-east (an arc), so the map
has a curve as well as straights.

    road 1  main, west arm        (-250, 0) -> J1
    road 2  main, between         J1 -> J2
    road 3  main, east arm        J2 -> (450, 0)
    road 4  side, J1 north arm    J1 -> north, then an arc to the east
    road 5  side, J1 south arm    (0, -150) -> J1
    road 6  side, J2 north arm    J2 -> (200, 150)
    road 7  side, J2 south arm    (200, -150) -> J2
    roads 1000+  connecting roads inside the junctions (paramPoly3 curves, one lane each)

Cross-sections, from the centre line out on each side: main roads have two driving lanes of
3.5 m per direction (broken line between them, solid at the centre and the edges) and a 2.5 m
sidewalk; side roads one driving lane of 3.5 m per direction and a 2.5 m sidewalk. Right-hand
traffic. Speed limits: 50 km/h on main roads, 30 km/h on side roads and in the junctions.

Every junction has all movements but U-turns: straight on (lane k to lane k), left from the
innermost lane, right from the outermost; and sidewalks round its four corners (connecting
roads with one sidewalk lane). At each arm a traffic light (dynamic signal, type
1000001, validity on the arm's incoming lanes) stands before a crosswalk (<object
type="crosswalk"> with an outline across the carriageway). Each junction has two controllers,
switched in sequence: its main-road lights, then its side-road lights.

Usage: /usr/bin/python3 tools/opendrive/make_city.py [OUTPUT]
Deterministic: the same script always writes the same bytes. Standard library only.
"""

import math
import os
import sys

LANE_WIDTH = 3.5
SIDEWALK_WIDTH = 2.5
HALF = 14.0  # junction half size: arms end this far from the junction centre (m)
MAIN_KMH, SIDE_KMH = 50, 30


def fmt(v):
    """Numbers in a stable, compact form."""
    if abs(v) < 5e-13:
        v = 0.0
    return repr(round(v, 12))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


class Road:
    def __init__(self, rid, name, start, pieces, lanes, kmh):
        """pieces: [("line", length)] or [("arc", length, curvature)] in order."""
        self.id, self.name, self.lanes, self.kmh = rid, name, lanes, kmh
        self.geoms = []
        x, y, h = start
        s = 0.0
        for p in pieces:
            self.geoms.append((s, x, y, h) + tuple(p))
            if p[0] == "line":
                x, y = x + p[1] * math.cos(h), y + p[1] * math.sin(h)
            else:
                k, L = p[2], p[1]
                x += (math.sin(h + k * L) - math.sin(h)) / k
                y += (math.cos(h) - math.cos(h + k * L)) / k
                h += k * L
            s += p[1]
        self.length = s
        self.start, self.end = (start[0], start[1], start[2]), (x, y, h)
        self.predecessor = self.successor = None  # (type, id, contact)
        self.signals, self.objects = [], []


def hermite(a, b):
    """paramPoly3 (normalized) from pose a to pose b, tangent lengths = chord; returns
    (length, aU..dU, aV..dV) in a's local frame."""
    ax, ay, ah = a
    bx, by, bh = b
    ch, sh = math.cos(ah), math.sin(ah)
    dx = (bx - ax) * ch + (by - ay) * sh
    dy = -(bx - ax) * sh + (by - ay) * ch
    dh = wrap(bh - ah)
    L = math.hypot(dx, dy)
    u = (0.0, L, 3 * dx - 2 * L - L * math.cos(dh), -2 * dx + L + L * math.cos(dh))
    v = (0.0, 0.0, 3 * dy - L * math.sin(dh), -2 * dy + L * math.sin(dh))
    n, length = 2000, 0.0
    px, py = 0.0, 0.0
    for i in range(1, n + 1):
        p = i / n
        qx = u[0] + u[1] * p + u[2] * p * p + u[3] * p ** 3
        qy = v[0] + v[1] * p + v[2] * p * p + v[3] * p ** 3
        length += math.hypot(qx - px, qy - py)
        px, py = qx, qy
    return length, u, v, abs(dh) < 1e-9 and abs(dy) < 1e-9


def main_lanes():
    return [(1, "driving", LANE_WIDTH, "broken"), (2, "driving", LANE_WIDTH, "solid"),
            (3, "sidewalk", SIDEWALK_WIDTH, None)]


def side_lanes():
    return [(1, "driving", LANE_WIDTH, "solid"), (2, "sidewalk", SIDEWALK_WIDTH, None)]


def build():
    roads = [
        Road("1", "main west", (-250.0, 0.0, 0.0), [("line", 250.0 - HALF)], main_lanes(), MAIN_KMH),
        Road("2", "main centre", (HALF, 0.0, 0.0), [("line", 200.0 - 2 * HALF)], main_lanes(),
             MAIN_KMH),
        Road("3", "main east", (200.0 + HALF, 0.0, 0.0), [("line", 250.0 - HALF)], main_lanes(),
             MAIN_KMH),
        Road("4", "J1 north", (0.0, HALF, math.pi / 2),
             [("line", 60.0), ("arc", 50.0, -1.0 / 80.0), ("line", 40.0)], side_lanes(), SIDE_KMH),
        Road("5", "J1 south", (0.0, -150.0, math.pi / 2), [("line", 150.0 - HALF)], side_lanes(),
             SIDE_KMH),
        Road("6", "J2 north", (200.0, HALF, math.pi / 2), [("line", 150.0 - HALF)], side_lanes(),
             SIDE_KMH),
        Road("7", "J2 south", (200.0, -150.0, math.pi / 2), [("line", 150.0 - HALF)], side_lanes(),
             SIDE_KMH),
    ]
    # (junction id, [(road id, at_end, group)]): group 0 = main road, 1 = side road.
    junctions = [
        ("100", [("1", True, 0), ("2", False, 0), ("4", False, 1), ("5", True, 1)]),
        ("200", [("2", True, 0), ("3", False, 0), ("6", False, 1), ("7", True, 1)]),
    ]
    return connect(roads, junctions)


def connect(roads, junctions):
    """The junctions' connecting roads (appended to `roads`), lights, crosswalks and
    controllers; also used by experiments/city_traffic/make_large_city.py."""
    by_id = {r.id: r for r in roads}
    junction_xml, controllers = [], []
    next_road, next_signal, next_object = 1000, 1, 1
    for jid, arms in junctions:
        info = []
        for rid, at_end, group in arms:
            r = by_id[rid]
            if at_end:
                r.successor = ("junction", jid, None)
                x, y, h = r.end
                outward = wrap(h + math.pi)
            else:
                r.predecessor = ("junction", jid, None)
                x, y, h = r.start
                outward = h
            n = sum(1 for lane in r.lanes if lane[1] == "driving")
            incoming = [(-k if at_end else k) for k in range(1, n + 1)]
            outgoing = [(k if at_end else -k) for k in range(1, n + 1)]
            info.append(dict(road=r, at_end=at_end, group=group, pos=(x, y), outward=outward,
                             n=n, incoming=incoming, outgoing=outgoing))
        connections = []
        for a in info:
            h_in = wrap(a["outward"] + math.pi)
            for b in info:
                if b is a:
                    continue
                turn = wrap(b["outward"] - h_in)
                if abs(turn) < 0.3:
                    pairs = [(k, k) for k in range(1, min(a["n"], b["n"]) + 1)]
                elif abs(turn - math.pi / 2) < 0.3:
                    pairs = [(1, 1)]
                elif abs(turn + math.pi / 2) < 0.3:
                    pairs = [(a["n"], b["n"])]
                else:
                    continue
                for ka, kb in pairs:
                    def inner_border(arm, k, heading):
                        d = (k - 1) * LANE_WIDTH
                        return (arm["pos"][0] + d * math.sin(heading),
                                arm["pos"][1] - d * math.cos(heading), heading)
                    pa = inner_border(a, ka, h_in)
                    pb = inner_border(b, kb, b["outward"])
                    cid = str(next_road)
                    next_road += 1
                    c = Road(cid, "J%s %s->%s" % (jid, a["road"].id, b["road"].id),
                             pa, [], [(-1, "driving", LANE_WIDTH, None)], SIDE_KMH)
                    length, u, v, straight = hermite(pa, pb)
                    c.length = length
                    if straight:
                        c.geoms = [(0.0, pa[0], pa[1], pa[2], "line", length)]
                    else:
                        c.geoms = [(0.0, pa[0], pa[1], pa[2], "paramPoly3", length, u, v)]
                    c.junction = jid
                    c.predecessor = ("road", a["road"].id, "end" if a["at_end"] else "start")
                    c.successor = ("road", b["road"].id, "end" if b["at_end"] else "start")
                    c.lane_links = {-1: (a["incoming"][ka - 1], b["outgoing"][kb - 1])}
                    roads.append(c)
                    connections.append((len(connections), a["road"].id, cid,
                                        a["incoming"][ka - 1]))
        # Sidewalks round the corners: from each arm's sidewalk on its incoming side to the
        # sidewalk on the outgoing side of the arm to its right.
        for a in info:
            h_in = wrap(a["outward"] + math.pi)
            for b in info:
                if b is a or abs(wrap(b["outward"] - h_in) + math.pi / 2) > 0.3:
                    continue

                def edge(arm, heading):
                    d = arm["n"] * LANE_WIDTH
                    return (arm["pos"][0] + d * math.sin(heading),
                            arm["pos"][1] - d * math.cos(heading), heading)
                pa, pb = edge(a, h_in), edge(b, b["outward"])
                cid = str(next_road)
                next_road += 1
                c = Road(cid, "J%s sidewalk %s-%s" % (jid, a["road"].id, b["road"].id), pa, [],
                         [(-1, "sidewalk", SIDEWALK_WIDTH, None)], SIDE_KMH)
                length, u, v, _ = hermite(pa, pb)
                c.length = length
                c.geoms = [(0.0, pa[0], pa[1], pa[2], "paramPoly3", length, u, v)]
                c.junction = jid
                c.predecessor = ("road", a["road"].id, "end" if a["at_end"] else "start")
                c.successor = ("road", b["road"].id, "end" if b["at_end"] else "start")
                sa = -(a["n"] + 1) if a["at_end"] else a["n"] + 1
                sb = b["n"] + 1 if b["at_end"] else -(b["n"] + 1)
                c.lane_links = {-1: (sa, sb)}
                roads.append(c)
                connections.append((len(connections), a["road"].id, cid, sa))
        # Lights and crosswalks at each arm.
        groups = {0: [], 1: []}
        for a in info:
            r, n = a["road"], a["n"]
            half_drive = n * LANE_WIDTH
            if a["at_end"]:
                s_sig, orient, t_sig = r.length - 6.0, "+", -(half_drive + 0.6)
                s0, s1 = r.length - 4.5, r.length - 1.0
                validity = (-n, -1)
            else:
                s_sig, orient, t_sig = 6.0, "-", half_drive + 0.6
                s0, s1 = 1.0, 4.5
                validity = (1, n)
            sid = str(next_signal)
            next_signal += 1
            r.signals.append((sid, s_sig, t_sig, orient, validity))
            groups[a["group"]].append(sid)
            oid = str(next_object)
            next_object += 1
            r.objects.append((oid, s0, s1, half_drive))
        ctrl_ids = []
        for g, name in ((0, "main"), (1, "side")):
            cid = "%s%d" % (jid, g + 1)
            ctrl_ids.append(cid)
            controllers.append((cid, "J%s %s" % (jid, name), groups[g]))
        junction_xml.append((jid, connections, ctrl_ids))
    return roads, junction_xml, controllers


def road_xml(r):
    out = []
    junction = getattr(r, "junction", "-1")
    out.append('  <road name="%s" length="%s" id="%s" junction="%s" rule="RHT">' %
               (r.name, fmt(r.length), r.id, junction))
    out.append("    <link>")
    for tag, link in (("predecessor", r.predecessor), ("successor", r.successor)):
        if link:
            contact = ' contactPoint="%s"' % link[2] if link[2] else ""
            out.append('      <%s elementType="%s" elementId="%s"%s/>' % (tag, link[0], link[1],
                                                                          contact))
    out.append("    </link>")
    out.append('    <type s="0" type="town"><speed max="%d" unit="km/h"/></type>' % r.kmh)
    out.append("    <planView>")
    for g in r.geoms:
        s, x, y, h, kind, length = g[:6]
        out.append('      <geometry s="%s" x="%s" y="%s" hdg="%s" length="%s">' %
                   (fmt(s), fmt(x), fmt(y), fmt(h), fmt(length)))
        if kind == "line":
            out.append("        <line/>")
        elif kind == "arc":
            out.append('        <arc curvature="%s"/>' % fmt(g[6]))
        else:
            u, v = g[6], g[7]
            out.append('        <paramPoly3 aU="%s" bU="%s" cU="%s" dU="%s" aV="%s" bV="%s" '
                       'cV="%s" dV="%s" pRange="normalized"/>' %
                       tuple(fmt(c) for c in tuple(u) + tuple(v)))
        out.append("      </geometry>")
    out.append("    </planView>")
    out.append('    <elevationProfile><elevation s="0" a="0" b="0" c="0" d="0"/></elevationProfile>')
    out.append("    <lanes>")
    out.append('      <laneSection s="0">')
    links = getattr(r, "lane_links", {})

    def lane(lid, kind, width, mark):
        o = ['          <lane id="%d" type="%s" level="false">' % (lid, kind)]
        if lid in links:
            p, s = links[lid]
            o.append('            <link><predecessor id="%d"/><successor id="%d"/></link>' % (p, s))
        o.append('            <width sOffset="0" a="%s" b="0" c="0" d="0"/>' % fmt(width))
        if mark:
            o.append('            <roadMark sOffset="0" type="%s" weight="standard" '
                     'color="standard" width="0.12"/>' % mark)
        o.append("          </lane>")
        return o

    left = [x for x in r.lanes if x[0] > 0]
    right = [x for x in r.lanes if x[0] < 0]
    if not right:  # two-way roads: the same lanes mirrored
        right = [(-x[0],) + tuple(x[1:]) for x in left]
    if left and getattr(r, "junction", "-1") == "-1":
        out.append("        <left>")
        for x in sorted(left, key=lambda x: -x[0]):
            out += lane(*x)
        out.append("        </left>")
    centre_mark = "solid" if getattr(r, "junction", "-1") == "-1" else "none"
    out.append("        <center>")
    out.append('          <lane id="0" type="none" level="false">')
    out.append('            <roadMark sOffset="0" type="%s" weight="standard" color="standard" '
               'width="0.12"/>' % centre_mark)
    out.append("          </lane>")
    out.append("        </center>")
    out.append("        <right>")
    for x in sorted(right, key=lambda x: -x[0]):
        out += lane(*x)
    out.append("        </right>")
    out.append("      </laneSection>")
    out.append("    </lanes>")
    if r.objects:
        out.append("    <objects>")
        for oid, s0, s1, half in r.objects:
            out.append('      <object type="crosswalk" id="%s" name="crosswalk" s="%s" t="0" '
                       'zOffset="0" hdg="0" pitch="0" roll="0" orientation="none" length="%s" '
                       'width="%s" height="0">' % (oid, fmt(0.5 * (s0 + s1)), fmt(s1 - s0),
                                                  fmt(2 * half)))
            out.append("        <outline>")
            for s, t in ((s0, -half), (s1, -half), (s1, half), (s0, half)):
                out.append('          <cornerRoad s="%s" t="%s" dz="0" height="0"/>' %
                           (fmt(s), fmt(t)))
            out.append("        </outline>")
            out.append("      </object>")
        out.append("    </objects>")
    if r.signals:
        out.append("    <signals>")
        for sid, s, t, orient, (lo, hi) in r.signals:
            out.append('      <signal s="%s" t="%s" id="%s" name="light%s" dynamic="yes" '
                       'orientation="%s" zOffset="2.5" country="OpenDRIVE" type="1000001" '
                       'subtype="-1" value="-1" height="0.9" width="0.3" hOffset="0" pitch="0" '
                       'roll="0">' % (fmt(s), fmt(t), sid, sid, orient))
            out.append('        <validity fromLane="%d" toLane="%d"/>' % (lo, hi))
            out.append("      </signal>")
        out.append("    </signals>")
    out.append("  </road>")
    return out


def write(path, built=None, name="city"):
    roads, junctions, controllers = built or build()
    xs = [g[1] for r in roads for g in r.geoms] + [r.end[0] for r in roads]
    ys = [g[2] for r in roads for g in r.geoms] + [r.end[1] for r in roads]
    lines = ['<?xml version="1.0" standalone="yes"?>', "<OpenDRIVE>",
             '  <header revMajor="1" revMinor="6" name="%s" version="1.0" date="2026-11-23" '
             'north="%s" south="%s" east="%s" west="%s" vendor="Convoy">' %
             (name, fmt(max(ys)), fmt(min(ys)), fmt(max(xs)), fmt(min(xs))),
             "  </header>"]
    for r in roads:
        lines += road_xml(r)
    for cid, name, signals in controllers:
        lines.append('  <controller id="%s" name="%s" sequence="0">' % (cid, name))
        for sid in signals:
            lines.append('    <control signalId="%s" type="0"/>' % sid)
        lines.append("  </controller>")
    for jid, connections, ctrl_ids in junctions:
        lines.append('  <junction name="J%s" id="%s">' % (jid, jid))
        for i, incoming, connecting, lane_from in connections:
            lines.append('    <connection id="%d" incomingRoad="%s" connectingRoad="%s" '
                         'contactPoint="start">' % (i, incoming, connecting))
            lines.append('      <laneLink from="%d" to="-1"/>' % lane_from)
            lines.append("    </connection>")
        for seq, cid in enumerate(ctrl_ids):
            lines.append('    <controller id="%s" type="0" sequence="%d"/>' % (cid, seq + 1))
        lines.append("  </junction>")
    lines.append("</OpenDRIVE>")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    return len(roads), len(junctions)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.join(here, "..", "..", "experiments", "city_traffic", "city.xodr")
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.normpath(default)
    n_roads, n_junctions = write(path)
    print("%s: %d roads, %d junctions" % (path, n_roads, n_junctions))


if __name__ == "__main__":
    main()
