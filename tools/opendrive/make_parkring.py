#!/usr/bin/python3
"""Generates experiments/autonomous_driving/parkring.xodr, the Parkring ring road.

The Parkring is the loop road around the business park in Garching-Hochbrueck. This is a
stylised model at real scale (about 1.03 km), not a survey: a rounded, slightly tapered
("teardrop") loop driven counter-clockwise along the reference line, made of four roads.
Each road is a straight followed by a corner, and each corner is a clothoid spiral into a
circular arc and a clothoid spiral out of it:

    road 1: south straight (east)   + corner R  60 m, 105 deg
    road 2: east straight (north)   + corner R  25 m,  80 deg   (the tight north-east end)
    road 3: north straight (west)   + corner R  40 m,  70 deg
    road 4: west straight (south)   + corner R 120 m, 105 deg   (the long sweep back)

The east and west straights converge northwards, which gives the loop its taper.

The corner turns add up to 360 deg, so the heading closes exactly. Two straight lengths are
chosen; the other two follow from a 2x2 linear system so that the position closes too
(corner displacements do not depend on the straights). The script checks the closure by
integrating the whole chain and refuses to write a file that misses 1 cm / 1e-4 rad.

Cross-section (both sides, from the centre line out): driving lane 3.4 m (edge line solid
white at its outer border), shoulder / gutter 0.5 m, grass verge 1.0 m (border), sidewalk
2.0 m. The centre line is broken white. Right-hand traffic: lane -1 runs along the road's s
direction (counter-clockwise), lane 1 against it.

Usage: /usr/bin/python3 tools/opendrive/make_parkring.py [OUTPUT]
Deterministic: the same script always writes the same bytes. Standard library only.
"""

import math
import os
import sys

# (radius m, turn deg, spiral length m) per corner, in driving order along s.
CORNERS = [(60.0, 105.0, 25.0), (25.0, 80.0, 15.0), (40.0, 70.0, 20.0), (120.0, 105.0, 40.0)]
# Straights before each corner; None = solved for closure.
STRAIGHTS = [None, None, 120.0, 100.0]

LANES = [  # (id magnitude, type, width m, road mark type or None)
    (1, "driving", 3.4, "solid"),
    (2, "shoulder", 0.5, None),
    (3, "border", 1.0, None),
    (4, "sidewalk", 2.0, None),
]
MARK_WIDTH = 0.12
SPEED_KMH = 50
GEO_REFERENCE = ("+proj=tmerc +lat_0=48.2475 +lon_0=11.6225 +k=1 +x_0=0 +y_0=0 "
                 "+ellps=WGS84 +units=m +no_defs")  # approximate origin only


def clothoid_local(k0, k1, length, s, steps=4000):
    """(x, y, heading) at arc length s of a spiral starting at the origin with heading 0."""
    if s <= 0.0:
        return 0.0, 0.0, 0.0
    c = (k1 - k0) / length
    n = steps + (steps % 2)
    h = s / n
    sx = sy = 0.0
    for i in range(n + 1):
        t = i * h
        th = k0 * t + 0.5 * c * t * t
        w = 1.0 if i in (0, n) else (4.0 if i % 2 else 2.0)
        sx += w * math.cos(th)
        sy += w * math.sin(th)
    return sx * h / 3.0, sy * h / 3.0, k0 * s + 0.5 * c * s * s


def advance(pose, geom):
    """End pose of a geometry record starting at pose = (x, y, heading)."""
    x, y, hdg = pose
    kind, length = geom[0], geom[1]
    if kind == "line":
        lx, ly, dh = length, 0.0, 0.0
    elif kind == "arc":
        k = geom[2]
        lx, ly, dh = math.sin(k * length) / k, 2.0 * math.sin(0.5 * k * length) ** 2 / k, k * length
    else:
        lx, ly, dh = clothoid_local(geom[2], geom[3], length, length)
    ch, sh = math.cos(hdg), math.sin(hdg)
    return x + ch * lx - sh * ly, y + sh * lx + ch * ly, hdg + dh


def corner(radius, turn_deg, spiral):
    k = 1.0 / radius
    arc_angle = math.radians(turn_deg) - spiral * k
    if arc_angle <= 0.0:
        raise SystemExit(f"corner R={radius}: spirals of {spiral} m turn more than {turn_deg} deg")
    return [("spiral", spiral, 0.0, k), ("arc", radius * arc_angle, k), ("spiral", spiral, k, 0.0)]


def chain(straights):
    return [[("line", straights[i])] + corner(*CORNERS[i]) for i in range(len(CORNERS))]


def solve_straights():
    """Fills the None entries of STRAIGHTS so that the loop closes in position."""
    unknown = [i for i, s in enumerate(STRAIGHTS) if s is None]
    assert len(unknown) == 2
    # End position with the unknown straights at zero is linear in them.
    base = [s if s is not None else 0.0 for s in STRAIGHTS]
    end = walk(chain(base))[-1]
    headings, heading = [], 0.0
    for radius, turn, _ in CORNERS:
        headings.append(heading)
        heading += math.radians(turn)
    (a, b), (c, d) = [(math.cos(headings[i]), math.sin(headings[i])) for i in unknown]
    det = a * d - b * c
    l0 = (-end[0] * d + end[1] * c) / det
    l1 = (-a * end[1] + b * end[0]) / det
    if l0 <= 0.0 or l1 <= 0.0:
        raise SystemExit(f"no closing loop with positive straights ({l0:.2f}, {l1:.2f})")
    base[unknown[0]], base[unknown[1]] = l0, l1
    return base


def walk(roads):
    """Start poses of every geometry, road by road, plus the final end pose."""
    pose, poses = (0.0, 0.0, 0.0), []
    for road in roads:
        for geom in road:
            poses.append(pose)
            pose = advance(pose, geom)
    poses.append(pose)
    return poses


def fmt(v):
    text = f"{v:.10f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def lane_xml(side, lane_id, lane_type, width, mark):
    sign = 1 if side == "left" else -1
    lid = sign * lane_id
    mark_xml = (f'<roadMark sOffset="0" type="{mark}" weight="standard" color="standard" '
                f'width="{fmt(MARK_WIDTH)}" laneChange="none"/>' if mark else
                '<roadMark sOffset="0" type="none"/>')
    return (f'          <lane id="{lid}" type="{lane_type}" level="false">\n'
            f'            <link><predecessor id="{lid}"/><successor id="{lid}"/></link>\n'
            f'            <width sOffset="0" a="{fmt(width)}" b="0" c="0" d="0"/>\n'
            f'            {mark_xml}\n'
            f'          </lane>\n')


def road_xml(index, count, geoms, poses):
    rid, pred, succ = index + 1, (index - 1) % count + 1, (index + 1) % count + 1
    length = sum(g[1] for g in geoms)
    out = [f'  <road name="Parkring {rid}" length="{fmt(length)}" id="{rid}" junction="-1" '
           f'rule="RHT">\n',
           f'    <link>\n'
           f'      <predecessor elementType="road" elementId="{pred}" contactPoint="end"/>\n'
           f'      <successor elementType="road" elementId="{succ}" contactPoint="start"/>\n'
           f'    </link>\n',
           f'    <type s="0" type="town"><speed max="{SPEED_KMH}" unit="km/h"/></type>\n',
           '    <planView>\n']
    s = 0.0
    for geom, (x, y, hdg) in zip(geoms, poses):
        kind = geom[0]
        if kind == "line":
            shape = "<line/>"
        elif kind == "arc":
            shape = f'<arc curvature="{fmt(geom[2])}"/>'
        else:
            shape = f'<spiral curvStart="{fmt(geom[2])}" curvEnd="{fmt(geom[3])}"/>'
        out.append(f'      <geometry s="{fmt(s)}" x="{fmt(x)}" y="{fmt(y)}" hdg="{fmt(hdg)}" '
                   f'length="{fmt(geom[1])}">{shape}</geometry>\n')
        s += geom[1]
    out.append('    </planView>\n'
               '    <elevationProfile><elevation s="0" a="0" b="0" c="0" d="0"/></elevationProfile>\n'
               '    <lateralProfile/>\n'
               '    <lanes>\n'
               '      <laneOffset s="0" a="0" b="0" c="0" d="0"/>\n'
               '      <laneSection s="0">\n'
               '        <left>\n')
    for lane in reversed(LANES):
        out.append(lane_xml("left", *lane))
    out.append('        </left>\n'
               '        <center>\n'
               '          <lane id="0" type="none" level="false">\n'
               f'            <roadMark sOffset="0" type="broken" weight="standard" color="standard" '
               f'width="{fmt(MARK_WIDTH)}" laneChange="both"/>\n'
               '          </lane>\n'
               '        </center>\n'
               '        <right>\n')
    for lane in LANES:
        out.append(lane_xml("right", *lane))
    out.append('        </right>\n'
               '      </laneSection>\n'
               '    </lanes>\n'
               '  </road>\n')
    return "".join(out)


def main():
    target = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "experiments",
        "autonomous_driving", "parkring.xodr")
    straights = solve_straights()
    roads = chain(straights)
    poses = walk(roads)
    end = poses[-1]
    gap = math.hypot(end[0], end[1])
    heading_error = abs(end[2] - 2.0 * math.pi)
    if gap > 0.01 or heading_error > 1e-4:
        raise SystemExit(f"loop does not close: gap {gap} m, heading {heading_error} rad")
    half_width = sum(lane[2] for lane in LANES)
    xs = [p[0] for p in poses]
    ys = [p[1] for p in poses]
    total = sum(g[1] for road in roads for g in road)

    parts = ['<?xml version="1.0" encoding="UTF-8"?>\n',
             '<!-- Generated by tools/opendrive/make_parkring.py; do not edit by hand. -->\n',
             '<OpenDRIVE>\n',
             f'  <header revMajor="1" revMinor="6" name="Parkring" version="1.0" '
             f'date="2024-01-01T00:00:00" north="{fmt(max(ys) + half_width)}" '
             f'south="{fmt(min(ys) - half_width)}" east="{fmt(max(xs) + half_width)}" '
             f'west="{fmt(min(xs) - half_width)}" vendor="Convoy">\n',
             f'    <geoReference><![CDATA[{GEO_REFERENCE}]]></geoReference>\n',
             '  </header>\n']
    index = 0
    for i, road in enumerate(roads):
        parts.append(road_xml(i, len(roads), road, poses[index:index + len(road)]))
        index += len(road)
    parts.append('</OpenDRIVE>\n')
    os.makedirs(os.path.dirname(os.path.abspath(target)), exist_ok=True)
    with open(target, "w", encoding="utf-8", newline="\n") as f:
        f.write("".join(parts))
    radii = ", ".join(f"{c[0]:g}" for c in CORNERS)
    print(f"{os.path.normpath(target)}: {len(roads)} roads, {total:.2f} m, straights "
          f"{', '.join(f'{s:.2f}' for s in straights)} m, radii {radii} m, "
          f"closure {gap:.2e} m / {heading_error:.2e} rad")


if __name__ == "__main__":
    main()
