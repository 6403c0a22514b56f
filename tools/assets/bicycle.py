"""The cyclist's city bicycle (make_people.py): its material slots frame, metal, saddle, tyre
and reflector. Frame: x forward, y left, z up, the wheels on the ground at z = 0."""
import math


def bicycle(m):
    """A city bicycle; returns the points the rider uses (saddle, grips, pedals)."""
    R = 0.34
    rear, front = (-0.52, 0.0, R), (0.52, 0.0, R)
    bb = (-0.06, 0.0, 0.28)
    seat = (-0.24, 0.0, 0.86)
    head_top, head_bot = (0.36, 0.0, 0.86), (0.41, 0.0, 0.7)
    m.begin("bicycle", "frame").smooth(50)
    tr = 0.017
    m.tube(seat, head_top, tr, n=6)            # top tube
    m.tube(head_bot, bb, 0.02, n=6)            # down tube
    m.tube(bb, seat, tr, n=6)                  # seat tube
    m.tube(head_bot, head_top, 0.022, n=6)     # head tube
    for s in (1, -1):
        m.tube((bb[0], s * 0.02, bb[2]), (rear[0], s * 0.06, rear[2]), 0.011, n=5)    # chain stays
        m.tube((seat[0], s * 0.015, seat[2] - 0.02), (rear[0], s * 0.06, rear[2]), 0.01, n=5)  # seat stays
        m.tube((head_bot[0], s * 0.02, head_bot[2]), (front[0], s * 0.05, front[2]), 0.012, n=5)  # fork
    # mudguards (frame colour): arcs over the wheels
    for c in (rear, front):
        pts = []
        for k in range(9):
            a = math.radians(20 + 140 * k / 8) if c is rear else math.radians(40 + 130 * k / 8)
            pts.append((c[0] - (R + 0.03) * math.cos(a) * (1 if c is rear else -1), 0.0, c[2] + (R + 0.03) * math.sin(a)))
        for p0, p1 in zip(pts, pts[1:]):
            m.quad((p0[0], 0.03, p0[2]), (p0[0], -0.03, p0[2]), (p1[0], -0.03, p1[2]), (p1[0], 0.03, p1[2]))
            m.quad((p1[0], 0.03, p1[2] - 0.002), (p1[0], -0.03, p1[2] - 0.002), (p0[0], -0.03, p0[2] - 0.002), (p0[0], 0.03, p0[2] - 0.002))
    m.begin("bicycle", "metal").smooth(50)
    stem_top = (0.38, 0.0, 0.98)
    m.tube(head_top, stem_top, 0.014, n=6)
    bar = [(0.3, 0.27, 0.99), (0.38, 0.22, 0.99), (0.38, -0.22, 0.99), (0.3, -0.27, 0.99)]
    for p0, p1 in zip(bar, bar[1:]):
        m.tube(p0, p1, 0.012, n=5)
    m.tube(seat, (seat[0] - 0.03, 0.0, seat[2] + 0.1), 0.013, n=5)  # seat post
    # cranks and pedals (left forward, right back)
    crank = 0.17
    pedals = {}
    for s, ang in ((1, math.radians(-10)), (-1, math.radians(170))):
        p = (bb[0] + crank * math.cos(ang), s * 0.09, bb[2] + crank * math.sin(ang))
        m.tube((bb[0], s * 0.06, bb[2]), p, 0.011, n=5)
        m.use("saddle")
        m.box((p[0], s * 0.12, p[2]), (0.1, 0.08, 0.025))
        m.use("metal")
        pedals["l" if s > 0 else "r"] = (p[0], s * 0.12, p[2] + 0.02)
    m.begin("bicycle", "saddle").smooth(50)
    sd = (seat[0] - 0.03, 0.0, seat[2] + 0.125)
    m.ellipsoid(sd, (0.13, 0.075, 0.035), stacks=3, slices=8)
    for s in (1, -1):
        m.tube((0.27, s * 0.27, 0.99), (0.31, s * 0.245, 0.99), 0.018, n=6)  # grips
    m.use("reflector")
    m.box((rear[0] - 0.05, 0.0, R + 0.36), (0.01, 0.06, 0.03))
    # wheels: a tyre (torus: black outside, grey rim inside), hub
    for c in (rear, front):
        n, tube_pts = 20, [(R - 0.012, 0.018, "tyre"), (R, 0.0, "tyre"), (R - 0.012, -0.018, "tyre"), (R - 0.035, -0.008, "metal"), (R - 0.035, 0.008, "metal")]
        m.begin("bicycle", "tyre").smooth(60)
        rings = []
        for k in range(n + 1):
            a = 2 * math.pi * k / n - math.pi / 2
            rings.append([(c[0] + r * math.cos(a), c[1] + y, c[2] + r * math.sin(a)) for r, y, _ in tube_pts])
        mats = [mt for _, _, mt in tube_pts]
        m.loft(rings, material_of=lambda i, jj: mats[jj] if mats[jj] == mats[(jj + 1) % len(mats)] else "tyre")
        m.use("metal").flat()
        m.tube((c[0], -0.05, c[2]), (c[0], 0.05, c[2]), 0.025, n=6)
    return {"saddle": sd, "grips": {"l": (0.29, 0.26, 1.0), "r": (0.29, -0.26, 1.0)}, "pedals": pedals,
            "rear_axle": rear}
