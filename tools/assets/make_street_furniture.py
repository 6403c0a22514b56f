"""Street furniture for the scenery (see make_scenery.py): street light, bench, litter bin, bus
stop shelter, bollard, guide post, guard rail (a 4 m W-beam segment on posts) and concrete
barrier (a 4 m New Jersey segment). Frame: +x towards the road (a bench's sitter looks along
+x, the street light's arm reaches out along +x), z up, metres; rails and barriers run along
y. Each builder returns the mesh and its collision boxes."""
import math

import make_signals
from meshkit import Mesh

MATERIALS = {
    "steel": {"kd": (0.55, 0.56, 0.57), "ks": (0.45, 0.45, 0.45), "ns": 50},
    "galvanised": {"kd": (0.66, 0.67, 0.68), "ks": (0.5, 0.5, 0.5), "ns": 40},
    "anthracite": {"kd": (0.16, 0.17, 0.18), "ks": (0.2, 0.2, 0.2), "ns": 24},
    "lamp_glass": {"kd": (0.9, 0.9, 0.82), "ks": (0.6, 0.6, 0.6), "ns": 80, "ke": (0.15, 0.15, 0.12)},
    "wood": {"kd": (0.5, 0.33, 0.18), "ks": (0.08, 0.08, 0.08), "ns": 10},
    "bin_green": {"kd": (0.1, 0.3, 0.18), "ks": (0.2, 0.2, 0.2), "ns": 20},
    "black": {"kd": (0.03, 0.03, 0.03), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "glass": {"kd": (0.5, 0.58, 0.62), "ks": (0.7, 0.7, 0.7), "ns": 100},
    "white": {"kd": (0.86, 0.86, 0.84), "ks": (0.1, 0.1, 0.1), "ns": 12},
    "reflector": {"kd": (0.85, 0.75, 0.15), "ks": (0.7, 0.7, 0.7), "ns": 90},
    "reflector_red": {"kd": (0.75, 0.08, 0.05), "ks": (0.7, 0.7, 0.7), "ns": 90},
    "concrete": {"kd": (0.62, 0.61, 0.58), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "timetable": {"kd": (0.9, 0.9, 0.88), "ks": (0.3, 0.3, 0.3), "ns": 40},
}
MATERIALS.update(make_signals.MATERIALS)


def street_light():
    """An 8 m tapered pole, a curved arm reaching 1.6 m out, a flat lamp head."""
    m = Mesh()
    m.begin("pole", "galvanised").smooth(60)
    m.tube((0, 0, 0), (0, 0, 0.9), 0.11, 0.1, n=10, cap_a=False)  # the foot
    m.tube((0, 0, 0.9), (0, 0, 7.6), 0.085, 0.055, n=10, cap_a=False)
    arm = [(0, 0, 7.5)] + [(0.9 * (1 - math.cos(a)) + 0.05, 0, 7.5 + 0.9 * math.sin(a))
                           for a in (0.35, 0.7, 1.05)] + [(1.65, 0, 8.25)]
    for a, b in zip(arm, arm[1:]):
        m.tube(a, b, 0.05, 0.045, n=7)
    m.begin("head", "anthracite").flat()
    m.block((1.35, -0.2, 8.12), (2.05, 0.2, 8.3), skip=())
    m.block((1.45, -0.14, 8.3), (1.95, 0.14, 8.36), skip=("-z",))
    m.begin("lamp", "lamp_glass").flat()
    m.block((1.42, -0.16, 8.09), (1.98, 0.16, 8.12), skip=("+z",))
    return m, [((0, 0, 4.0, 0), (0.22, 0.22, 8.0))]


def bench():
    """A park bench 1.8 m long: wooden slats on two cast-iron frames."""
    m = Mesh()
    L = 0.9
    m.begin("frame", "anthracite").flat()
    for y in (-0.72, 0.72):
        m.block((0.15, y - 0.03, 0.0), (0.21, y + 0.03, 0.43))  # front leg
        m.block((-0.24, y - 0.03, 0.0), (-0.18, y + 0.03, 0.43))  # back leg
        m.block((-0.24, y - 0.03, 0.4), (0.22, y + 0.03, 0.45))  # seat bearer
        m.block((-0.26, y - 0.03, 0.43), (-0.2, y + 0.03, 0.85))  # backrest bearer
    m.begin("slats", "wood").flat()
    for k in range(4):
        x = 0.2 - k * 0.115
        m.block((x - 0.1, -L, 0.45), (x, L, 0.49))
    for k in range(3):
        z = 0.55 + k * 0.11
        m.block((-0.25 + 0.015 * k, -L, z), (-0.21 + 0.015 * k, L, z + 0.08))
    return m, [((0, 0, 0.43, 0), (0.5, 1.8, 0.86))]


def litter_bin():
    """A green bin on a post, open top with a dark inside."""
    m = Mesh()
    m.begin("post", "anthracite").smooth(60)
    m.tube((-0.24, 0, 0), (-0.24, 0, 1.05), 0.035, n=8, cap_a=False)
    m.begin("bin", "bin_green").smooth(50)
    c0, c1 = (0.0, 0, 0.45), (0.0, 0, 0.98)
    m.tube(c0, c1, 0.19, 0.21, n=14, cap_b=False)
    m.tube(c1, (0.0, 0, 1.0), 0.225, 0.225, n=14, cap_a=True, cap_b=False)  # the rim
    m.begin("inside", "black").flat()
    ring = [(0.2 * math.cos(2 * math.pi * k / 14), 0.2 * math.sin(2 * math.pi * k / 14), 0.99) for k in range(14)]
    m.poly(ring)
    m.begin("bracket", "anthracite").flat()
    m.block((-0.24, -0.04, 0.8), (-0.18, 0.04, 0.9))
    return m, [((-0.02, 0, 0.52, 0), (0.5, 0.45, 1.05))]


def bus_stop():
    """A shelter 4 m long and 1.5 m deep: roof, glass back and side panels on posts, a bench,
    a timetable case and the stop's sign (a yellow disc with a green H) on a pole at its side."""
    m = Mesh()
    W, D, H = 2.0, 0.75, 2.5
    m.begin("frame", "anthracite").flat()
    for x in (-D + 0.04, D - 0.04):
        for y in (-W + 0.04, W - 0.04):
            m.block((x - 0.04, y - 0.04, 0), (x + 0.04, y + 0.04, H), skip=("-z", "+z"))
    m.block((-D - 0.05, -W - 0.05, H), (D + 0.15, W + 0.05, H + 0.12))  # roof
    m.begin("roof", "glass").flat()
    m.block((-D + 0.05, -W + 0.05, H + 0.12), (D + 0.1, W - 0.05, H + 0.13), skip=("-z",))
    m.begin("glass", "glass").flat()
    m.block((-D + 0.01, -W + 0.08, 0.15), (-D + 0.03, W - 0.08, H - 0.1))  # back
    m.block((-D + 0.08, W - 0.05, 0.15), (D - 0.08, W - 0.03, H - 0.1))  # side (left)
    m.begin("frame", "anthracite").flat()
    m.block((-D, -W, 0.1), (-D + 0.04, W, 0.15), skip=("-z",))  # rails under and over the glass
    m.block((-D, -W, H - 0.1), (-D + 0.04, W, H - 0.06))
    m.begin("bench", "wood").flat()
    m.block((-D + 0.05, -1.3, 0.44), (-D + 0.42, 1.3, 0.48))
    m.begin("frame", "anthracite").flat()
    for y in (-1.1, 1.1):
        m.block((-D + 0.05, y - 0.03, 0), (-D + 0.12, y + 0.03, 0.44), skip=("-z",))
        m.block((-D + 0.12, y - 0.02, 0.4), (-D + 0.4, y + 0.02, 0.44))
    m.begin("timetable", "timetable").flat()
    m.block((-D + 0.03, -1.85, 1.0), (-D + 0.06, -1.45, 1.7))
    # the sign on its own pole at the open end
    sx, sy = D - 0.1, -W - 0.35
    m.begin("pole", "galvanised").smooth(60)
    m.tube((sx, sy, 0), (sx, sy, 2.75), 0.035, n=8, cap_a=False)
    centre = (sy, 2.45)
    mark = m.mark()
    make_signals.add_plate(m, "disc", centre, half=0.22)
    make_signals.add_face(m, "disc", "face", centre, half=0.22)
    m.transform(mark, move=(sx + 0.055, 0, 0))
    return m, [((0, 0, (H + 0.13) / 2, 0), (2 * D + 0.2, 2 * W + 0.1, H + 0.13)),
               ((sx, sy, 1.4, 0), (0.1, 0.1, 2.8))]


def bollard():
    """A steel bollard 0.9 m tall with a domed cap and a reflective band."""
    m = Mesh()
    m.begin("body", "anthracite").smooth(50)
    m.tube((0, 0, 0), (0, 0, 0.74), 0.075, n=10, cap_a=False, cap_b=False)
    m.begin("band", "white").smooth(50)
    m.tube((0, 0, 0.74), (0, 0, 0.82), 0.076, n=10, cap_a=False, cap_b=False)
    m.begin("body", "anthracite").smooth(50)
    m.tube((0, 0, 0.82), (0, 0, 0.86), 0.075, n=10, cap_a=False, cap_b=False)
    m.ellipsoid((0, 0, 0.86), (0.075, 0.075, 0.04), stacks=2, slices=10, zcut=0.0)
    return m, [((0, 0, 0.45, 0), (0.15, 0.15, 0.9))]


def guide_post():
    """A German guide post (Leitpfosten): a white post of trapezoid section, 1.0 m above the
    ground, a black band with a reflector facing the road (+x)."""
    m = Mesh()
    sec = [(0.06, -0.05), (0.06, 0.05), (-0.06, 0.03), (-0.06, -0.03)]  # counter-clockwise (x, y)
    top = 1.0
    for z0, z1, mat in ((0, 0.62, "white"), (0.62, 0.9, "black"), (0.9, top, "white")):
        m.begin("post", mat).flat()
        m.loft([[(x, y, z0) for x, y in sec], [(x, y, z1) for x, y in sec]], cap_end=(z1 == top))
    m.begin("reflector", "reflector").flat()
    m.block((0.06, -0.02, 0.72), (0.065, 0.02, 0.84), skip=("-x",))
    return m, [((0, 0, 0.5, 0), (0.12, 0.1, 1.0))]


def guard_rail():
    """A 4 m segment of W-beam guard rail (along y) on two sigma posts with spacers, the beam's
    face towards +x at 0.45-0.75 m."""
    m = Mesh()
    L = 2.0
    m.begin("posts", "galvanised").flat()
    for y in (-1.0, 1.0):
        m.block((-0.2, y - 0.05, 0), (-0.1, y + 0.05, 0.72), skip=("-z",))
        m.block((-0.1, y - 0.04, 0.48), (0.0, y + 0.04, 0.68))  # spacer
    # the W profile in (x, z): two ridges, 3 mm thick (front line, then back line reversed)
    front = [(0.0, 0.45), (0.04, 0.47), (0.085, 0.52), (0.085, 0.55), (0.04, 0.6), (0.085, 0.65),
             (0.085, 0.68), (0.04, 0.73), (0.0, 0.75)]
    back = [(x - 0.004, z) for x, z in reversed(front)]
    prof = front + back
    m.begin("beam", "galvanised").smooth(35)
    # counter-clockwise about -y in (x, z) is clockwise about +y: sweep from +y to -y
    m.sweep([(x, L, z) for x, z in prof], (0, -2 * L, 0))
    return m, [((-0.05, 0, 0.375, 0), (0.3, 4.0, 0.75))]


def concrete_barrier():
    """A 4 m New Jersey concrete barrier segment (along y), 0.81 m tall, 0.6 m at the foot."""
    m = Mesh()
    L = 2.0
    levels = [(0.0, 0.3), (0.075, 0.3), (0.33, 0.18), (0.81, 0.075)]  # (z, half width): the profile
    prof = [(w, z) for z, w in levels] + [(-w, z) for z, w in reversed(levels)]  # counter-clockwise in (x, z)
    m.begin("barrier", "concrete").flat()
    m.sweep([(x, -L, z) for x, z in reversed(prof)], (0, 2 * L, 0))
    for y, s in ((-L, 1), (L, -1)):  # the ends, a trapezoid per step of the profile (it is not convex)
        for (z0, w0), (z1, w1) in zip(levels, levels[1:]):
            q = [(-w0 * s, y, z0), (w0 * s, y, z0), (w1 * s, y, z1), (-w1 * s, y, z1)]
            m.quad(*q)
    m.begin("marks", "black").flat()  # the lifting slots near the foot, both sides
    for y in (-1.2, 1.2):
        for s in (1, -1):
            x = s * 0.3005
            m.poly([(x, y - 0.2 * s, 0.0), (x, y + 0.2 * s, 0.0), (x, y + 0.2 * s, 0.06), (x, y - 0.2 * s, 0.06)])
    return m, [((0, 0, 0.405, 0), (0.6, 4.0, 0.81))]


BUILDERS = [("street_light", "street_light", street_light), ("bench", "bench", bench),
            ("litter_bin", "bin", litter_bin), ("bus_stop", "bus_stop", bus_stop),
            ("bollard", "bollard", bollard), ("guide_post", "bollard", guide_post),
            ("guard_rail", "guard_rail", guard_rail), ("concrete_barrier", "barrier", concrete_barrier)]


def build_all():
    """[(name, kind, mesh, collisions [((x, y, z, yaw), (sx, sy, sz))])]"""
    return [(name, kind) + f() for name, kind, f in BUILDERS]
