"""The city bus's details (make_vehicles.py builds its body): windscreen, a destination display
(black, amber lettering), lights and plates; side windows in black frames
with the inside seen through them (seat backs, the ceiling's light strip, passengers' heads
and shoulders), black wheel arches, three doors on the right (-y) with their glass panes.
Flat shapes a few millimetres off the body, in the detail mesh's materials (bus.obj + .mtl)."""
import math
import random

# Materials of the bus's inside as seen through its windows, and of its display.
MATERIALS = {
    # (through lightly tinted glass: a little dimmer than outside)
    "interior": {"kd": (0.35, 0.37, 0.40), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "ceiling_light": {"kd": (0.75, 0.76, 0.72), "ks": (0.1, 0.1, 0.1), "ns": 10, "ke": (0.12, 0.12, 0.11)},
    "seat": {"kd": (0.11, 0.14, 0.32), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "pax_skin": {"kd": (0.67, 0.50, 0.38), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "pax_skin_dark": {"kd": (0.38, 0.26, 0.19), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "pax_hair": {"kd": (0.08, 0.06, 0.05), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "pax_red": {"kd": (0.51, 0.10, 0.08), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "pax_blue": {"kd": (0.13, 0.21, 0.48), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "pax_light": {"kd": (0.64, 0.64, 0.61), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "livery": {"kd": (0.72, 0.1, 0.07), "ks": (0.45, 0.45, 0.45), "ns": 40},
    "pole": {"kd": (0.9, 0.72, 0.08), "ks": (0.4, 0.4, 0.4), "ns": 40},
    "display": {"kd": (0.02, 0.02, 0.02), "ks": (0.3, 0.3, 0.3), "ns": 40},
    "display_text": {"kd": (1.0, 0.65, 0.1), "ks": (0.1, 0.1, 0.1), "ns": 10, "ke": (0.95, 0.6, 0.08)},
}

# The glyphs of the display: strokes on a 2 x 4 grid (x 0..2, y 0..4), enough to read as text.
GLYPHS = {
    "0": [(0, 0, 2, 0), (2, 0, 2, 4), (2, 4, 0, 4), (0, 4, 0, 0)],
    "1": [(1, 0, 1, 4), (0, 3, 1, 4)],
    "2": [(0, 4, 2, 4), (2, 4, 2, 2), (2, 2, 0, 2), (0, 2, 0, 0), (0, 0, 2, 0)],
    "3": [(0, 4, 2, 4), (2, 4, 2, 0), (2, 0, 0, 0), (0, 2, 2, 2)],
    "H": [(0, 0, 0, 4), (2, 0, 2, 4), (0, 2, 2, 2)],
    "B": [(0, 0, 0, 4), (0, 4, 2, 3.2), (2, 3.2, 0, 2), (0, 2, 2, 1), (2, 1, 0, 0)],
    "F": [(0, 0, 0, 4), (0, 4, 2, 4), (0, 2, 1.5, 2)],
    "A": [(0, 0, 1, 4), (1, 4, 2, 0), (0.5, 2, 1.5, 2)],
    "P": [(0, 0, 0, 4), (0, 4, 2, 4), (2, 4, 2, 2), (2, 2, 0, 2)],
    "R": [(0, 0, 0, 4), (0, 4, 2, 4), (2, 4, 2, 2), (2, 2, 0, 2), (0.7, 2, 2, 0)],
    "K": [(0, 0, 0, 4), (0, 2, 2, 4), (0.6, 2.6, 2, 0)],
    "N": [(0, 0, 0, 4), (0, 4, 2, 0), (2, 0, 2, 4)],
    "G": [(2, 4, 0, 4), (0, 4, 0, 0), (0, 0, 2, 0), (2, 0, 2, 2), (2, 2, 1, 2)],
    " ": [],
}


def display(vs, m, x, yc, zc, height, text, sign):
    """Amber lettering centred at (yc, zc) on the plane x, facing sign * x (characters
    `height` tall, strokes as thin rectangles)."""
    w = 0.5 * height
    step = 0.78 * height
    stroke = 0.16 * height
    y = yc - sign * 0.5 * step * (len(text) - 1)  # the first character on the viewer's left
    for ch in text:
        for x0, z0, x1, z1 in GLYPHS[ch]:
            a = (y + sign * (x0 / 2 - 0.5) * w, zc + (z0 / 4 - 0.5) * height)
            b = (y + sign * (x1 / 2 - 0.5) * w, zc + (z1 / 4 - 0.5) * height)
            d = (b[0] - a[0], b[1] - a[1])
            n = math.hypot(*d) or 1.0
            ny, nz = -d[1] / n * stroke / 2, d[0] / n * stroke / 2
            q = [(x, a[0] + ny, a[1] + nz), (x, b[0] + ny, b[1] + nz), (x, b[0] - ny, b[1] - nz),
                 (x, a[0] - ny, a[1] - nz)]
            m.begin("details", "display_text").flat()
            m.quad(*q) if vs._facing(q, (sign, 0, 0)) else m.quad(*q[::-1])
        y += sign * step


def side_poly(vs, m, t, pts, side, material, out):
    """A convex polygon [(x, z)] on the body side (side +1 left, -1 right), facing out."""
    m.begin("details", material).flat()
    q = [(x, side * (vs.half_width_at(t, x, z) + out), z) for x, z in pts]
    if not vs._facing(q[:3], (0, side, 0)):
        q = q[::-1]
    m.poly(q)


def face_poly(vs, m, x, pts, sign, material):
    """A convex polygon [(y, z)] on the plane x, facing sign * x."""
    m.begin("details", material).flat()
    q = [(x, y, z) for y, z in pts]
    if not vs._facing(q[:3], (sign, 0, 0)):
        q = q[::-1]
    m.poly(q)


def cabin(vs, m, xf, hw):
    """What the windscreen shows: the ceiling's light strip, the driver (on the left, +y),
    the yellow grab poles behind the door."""
    x = xf + 0.006
    vs.face_rect(m, x, -hw + 0.1, hw - 0.1, 2.3, 2.42, 1, "ceiling_light")
    vs.face_rect(m, x, -hw + 0.1, hw - 0.1, 2.42, 2.58, 1, "interior")
    for y, z0, z1 in ((-0.3, 0.85, 2.3), (0.15, 0.85, 2.3)):
        vs.face_rect(m, x, y - 0.025, y + 0.025, z0, z1, 1, "pole")
    y, zs = 0.62, 1.3  # the driver: shoulders, head, hair
    face_poly(vs, m, x + 0.002, [(y - 0.2, 0.85), (y + 0.2, 0.85), (y + 0.2, zs + 0.1), (y + 0.12, zs + 0.18),
                                 (y - 0.12, zs + 0.18), (y - 0.2, zs + 0.1)], 1, "pax_light")
    face_poly(vs, m, x + 0.004, ellipse(y, zs + 0.38, 0.09, 0.12), 1, "pax_skin")
    face_poly(vs, m, x + 0.006, [(y - 0.095, zs + 0.42), (y - 0.075, zs + 0.49), (y, zs + 0.515),
                                 (y + 0.075, zs + 0.49), (y + 0.095, zs + 0.42)], 1, "pax_hair")
    vs.face_rect(m, x + 0.002, 0.3, 0.9, 0.85, 1.2, 1, "interior")  # the dashboard


def back_seats(vs, m, x, hw):
    """What the back window shows: the ceiling, the back row's seat backs, two passengers."""
    vs.face_rect(m, x, -hw + 0.17, hw - 0.17, 2.3, 2.57, -1, "interior")
    vs.face_rect(m, x, -hw + 0.17, hw - 0.17, 2.24, 2.3, -1, "ceiling_light")
    vs.face_rect(m, x, -hw + 0.2, hw - 0.2, 1.43, 1.75, -1, "seat")
    for y, cloth, skin in ((-0.55, "pax_blue", "pax_skin"), (0.35, "pax_red", "pax_skin_dark")):
        face_poly(vs, m, x - 0.002, [(y - 0.2, 1.43), (y + 0.2, 1.43), (y + 0.2, 1.72), (y + 0.12, 1.8),
                                     (y - 0.12, 1.8), (y - 0.2, 1.72)], -1, cloth)
        face_poly(vs, m, x - 0.004, ellipse(y, 1.97, 0.085, 0.115), -1, skin)
        face_poly(vs, m, x - 0.006, [(y - 0.09, 1.93), (y - 0.09, 2.02), (y - 0.05, 2.08), (y + 0.05, 2.08),
                                     (y + 0.09, 2.02), (y + 0.09, 1.93)], -1, "pax_hair")


def ellipse(cx, cz, rx, rz, n=8):
    return [(cx + rx * math.cos(2 * math.pi * k / n), cz + rz * math.sin(2 * math.pi * k / n)) for k in range(n)]


def windows(vs, m, t, doors):
    """Black frames round the side windows and the inside seen through them."""
    g0, g1 = t["side_glass"]
    edges = [g0] + [v for p in t["pillars"] for v in p] + [g1]
    panes = [(edges[i], edges[i + 1]) for i in range(0, len(edges), 2)]
    z0, z1 = t["belt"], t["top"][-3][1] - t["roof_h"]  # the glass band
    rng = random.Random(7)
    skins = ["pax_skin", "pax_skin", "pax_skin_dark"]
    clothes = ["pax_red", "pax_blue", "pax_light", "seat"]
    for side in (1, -1):
        for a, b in panes:
            # the frame: black strips along the top and bottom of the pane
            vs.side_rect(m, t, a, b, z0, z0 + 0.07, side, "trim", out=0.006, rows=1)
            vs.side_rect(m, t, a, b, z1 - 0.09, z1, side, "trim", out=0.006, rows=1)
            for x0, x1 in ((a, a + 0.05), (b - 0.05, b)):
                vs.side_rect(m, t, x0, x1, z0, z1, side, "trim", out=0.006, rows=1)
            segs = [(a + 0.05, b - 0.05)]
            if side < 0:  # not where a door is
                for d0, d1 in doors:
                    segs = [piece for s0, s1 in segs for piece in ((s0, min(s1, d0)), (max(s0, d1), s1))
                            if piece[1] - piece[0] > 0.3]
            for s0, s1 in segs:
                interior(vs, m, t, s0, s1, z0 + 0.07, z1 - 0.09, side, rng, skins, clothes)


def interior(vs, m, t, a, b, zlo, zhi, side, rng, skins, clothes):
    """What a window pane from a to b (x) shows: the ceiling's light strip, seat backs, and
    passengers (a head and shoulders) on some of the seats."""
    vs.side_rect(m, t, a, b, zhi - 0.2, zhi, side, "interior", out=0.008, rows=1)
    n = max(1, int((b - a) / 0.8))
    w = (b - a) / n
    for k in range(n):
        cx = a + (k + 0.5) * w
        # the seat back: a rounded block, its top 0.45 m above the window's bottom
        top = zlo + 0.42
        side_poly(vs, m, t, [(cx - 0.3 * w, zlo), (cx + 0.3 * w, zlo), (cx + 0.3 * w, top - 0.06),
                             (cx + 0.22 * w, top), (cx - 0.22 * w, top), (cx - 0.3 * w, top - 0.06)],
                  side, "seat", 0.008)
        if rng.random() < 0.35:  # a passenger: shoulders, neck, head, hair
            sx = cx + rng.uniform(-0.1, 0.1) * w
            cloth = rng.choice(clothes)
            zs = zlo + rng.uniform(0.28, 0.36)
            side_poly(vs, m, t, [(sx - 0.2, zlo), (sx + 0.2, zlo), (sx + 0.2, zs + 0.12), (sx + 0.12, zs + 0.2),
                                 (sx - 0.12, zs + 0.2), (sx - 0.2, zs + 0.12)], side, cloth, 0.01)
            side_poly(vs, m, t, ellipse(sx, zs + 0.36, 0.085, 0.115), side, rng.choice(skins), 0.012)
            side_poly(vs, m, t, [(sx - 0.09, zs + 0.4), (sx - 0.07, zs + 0.47), (sx, zs + 0.49),
                                 (sx + 0.07, zs + 0.47), (sx + 0.09, zs + 0.4)], side, "pax_hair", 0.014)


def wheel_arches(vs, m, t):
    """A black arch round each wheel opening, on both sides."""
    ra, zc = t["wheel"][0] + 0.045, t["wheel"][0]
    for ax in t["axles"]:
        for side in (1, -1):
            n = 8
            for k in range(n):
                a0, a1 = math.pi * k / n, math.pi * (k + 1) / n
                p = [(ax + ra * math.cos(a0), zc + ra * math.sin(a0)),
                     (ax + (ra + 0.1) * math.cos(a0), zc + (ra + 0.1) * math.sin(a0)),
                     (ax + (ra + 0.1) * math.cos(a1), zc + (ra + 0.1) * math.sin(a1)),
                     (ax + ra * math.cos(a1), zc + ra * math.sin(a1))]
                side_poly(vs, m, t, p, side, "trim", 0.005)


def livery(vs, m, t, xf, xr, hw):
    """The operator's colour below the windows, as city buses wear it: along both sides
    (round the wheel arches) and across the front and the back."""
    z0, z1 = 0.46, t["belt"]
    ra = t["wheel"][0] + 0.045 + 0.1
    cuts = sorted((ax - ra, ax + ra) for ax in t["axles"])
    xs = [xr + 0.25]
    for a, b in cuts:
        xs += [a, b]
    xs.append(xf - 0.25)
    for side in (1, -1):
        for a, b in zip(xs[::2], xs[1::2]):
            vs.side_rect(m, t, a, b, z0, z1, side, "livery", out=0.003, rows=6)
        for a, b in cuts:  # above the arches
            vs.side_rect(m, t, a, b, t["wheel"][0] + ra + 0.01, z1, side, "livery", out=0.003, rows=6)
    vs.face_rect(m, xf + 0.002, -hw + 0.05, hw - 0.05, 0.47, 0.82, 1, "livery")
    for side in (1, -1):
        a, b = sorted((side * (hw - 0.05), side * (hw - 0.4)))
        vs.face_rect(m, xr - 0.002, a, b, 0.42, 1.36, -1, "livery")


def details(vs, m, t, xs, secs):
    L, W, H = t["size"]
    xf, xr = xs[-1], xs[0]
    hw = vs.cap_half_width(secs[-1], 1.5)
    face = vs.face_rect
    # windscreen (down low, split by a pillar), wipers, the destination display
    face(m, xf + 0.004, -hw + 0.09, hw - 0.09, 0.82, 2.6, 1, "glass")
    face(m, xf + 0.006, -0.015, 0.015, 0.82, 2.6, 1, "trim")
    for yc in (-0.55, 0.45):
        face(m, xf + 0.007, yc - 0.35, yc + 0.35, 0.86, 0.89, 1, "trim")
    cabin(vs, m, xf, hw)
    face(m, xf + 0.004, -hw + 0.09, hw - 0.09, 2.62, 2.94, 1, "display")
    display(vs, m, xf + 0.007, -0.55, 2.78, 0.18, "23", 1)
    display(vs, m, xf + 0.007, 0.25, 2.78, 0.13, "HBF PARK", 1)
    for side in (1, -1):
        a, b = sorted((side * (hw - 0.08), side * (hw - 0.42)))
        face(m, xf + 0.004, a, b, 0.52, 0.68, 1, "headlight")
        a, b = sorted((side * (hw - 0.08), side * (hw - 0.2)))
        face(m, xf + 0.004, a, b, 0.7, 0.77, 1, "indicator")
        a, b = sorted((side * (hw - 0.06), side * (hw - 0.22)))
        face(m, xr - 0.004, a, b, 0.55, 1.2, -1, "taillight")
        face(m, xr - 0.004, a, b, 1.23, 1.36, -1, "indicator")
    face(m, xf + 0.003, -hw + 0.02, hw - 0.02, 0.3, 0.47, 1, "trim")  # the bumper
    vs.plate(m, xf, 0.0, 0.6, 1)
    # the back: a large window onto the back seats, route number, the engine's grille, plate
    face(m, xr - 0.004, -hw + 0.12, hw - 0.12, 1.38, 2.62, -1, "trim")
    face(m, xr - 0.006, -hw + 0.17, hw - 0.17, 1.43, 2.57, -1, "glass")
    back_seats(vs, m, xr - 0.008, hw)
    face(m, xr - 0.004, -0.5, 0.5, 2.66, 2.9, -1, "display")
    display(vs, m, xr - 0.007, 0.0, 2.78, 0.17, "23", -1)
    face(m, xr - 0.004, -hw + 0.4, hw - 0.4, 0.62, 1.2, -1, "trim")
    for k in range(4):
        z = 0.68 + 0.13 * k
        face(m, xr - 0.006, -hw + 0.46, hw - 0.46, z, z + 0.05, -1, "metal")
    vs.plate(m, xr, 0.0, 0.45, -1)
    face(m, xr - 0.003, -hw + 0.02, hw - 0.02, 0.3, 0.42, -1, "trim")
    # doors on the right (-y): front (ahead of the front axle), middle, rear; two glass leaves
    doors = ((L / 2 - 1.45, L / 2 - 0.3), (-0.75, 0.55), (-4.85, -3.7))
    for x0, x1 in doors:
        vs.side_rect(m, t, x0, x1, 0.34, 2.66, -1, "trim", out=0.004, rows=2)
        for a, b in ((x0 + 0.07, 0.5 * (x0 + x1) - 0.03), (0.5 * (x0 + x1) + 0.03, x1 - 0.07)):
            vs.side_rect(m, t, a, b, 1.2, 2.55, -1, "glass", out=0.007, rows=1)
            vs.side_rect(m, t, a, b, 0.45, 1.1, -1, "glass", out=0.007, rows=1)
            vs.side_rect(m, t, a + 0.04, b - 0.04, 1.55, 1.6, -1, "rim", out=0.009, rows=1)  # grab rails
    windows(vs, m, t, doors)
    wheel_arches(vs, m, t)
    livery(vs, m, t, xf, xr, hw)
    # a black skirt along the bottom, the roof's air-conditioning pod
    for side in (1, -1):
        vs.side_rect(m, t, -L / 2 + 0.3, L / 2 - 0.3, 0.34, 0.46, side, "trim", out=0.003, rows=1)
    m.begin("roof", "paint").smooth(40)
    m.box((-1.0, 0.0, 3.05), (3.2, 1.7, 0.1))
