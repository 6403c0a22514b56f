"""Vehicle meshes for the road-user actors (see make_road_users.py): hatchback, sedan, SUV, van,
bus and truck. Each body is a loft of cross-sections along x (rear to front) whose side
profile (bonnet, windscreen, roof, rear window, boot) and plan (rounded nose and tail) come
from a few key points; glass, pillars and the underbody are bands of that loft, wheel arches
are the underbody rising over the wheels. Lights, number plates, grille, mirrors and door
seams are thin shapes on the surface (the truck: make_truck.py). Frame: x forward, y left,
z up; the origin at the centre of the bounding box's base.

Two meshes per type: <type>_paint.obj (the body colour; its colour comes from the SDF so
that colour variants share it; the truck's box body likewise truck_cargo.obj) and <type>.obj +
.mtl (glass, tyres, rims, lights, plate...).
"""
import math

from meshkit import Mesh, cross, dot, interp, sub

# The materials of the detail meshes (Kd, Ks, Ns, Ke: the renderer adds Ke unlit).
MATERIALS = {
    "glass": {"kd": (0.08, 0.1, 0.125), "ks": (0.55, 0.55, 0.55), "ns": 90},
    "trim": {"kd": (0.035, 0.035, 0.04), "ks": (0.08, 0.08, 0.08), "ns": 12},
    "tyre": {"kd": (0.045, 0.045, 0.045), "ks": (0.03, 0.03, 0.03), "ns": 6},
    "rim": {"kd": (0.62, 0.63, 0.65), "ks": (0.5, 0.5, 0.5), "ns": 60},
    "rim_dark": {"kd": (0.12, 0.12, 0.13), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "headlight": {"kd": (0.92, 0.92, 0.88), "ks": (0.8, 0.8, 0.8), "ns": 100, "ke": (0.35, 0.35, 0.32)},
    "taillight": {"kd": (0.85, 0.06, 0.05), "ks": (0.5, 0.5, 0.5), "ns": 80, "ke": (0.45, 0.02, 0.02)},
    "indicator": {"kd": (0.95, 0.5, 0.05), "ks": (0.5, 0.5, 0.5), "ns": 80, "ke": (0.2, 0.08, 0.0)},
    "plate": {"kd": (0.93, 0.93, 0.9), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "plate_blue": {"kd": (0.05, 0.15, 0.6), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "plate_text": {"kd": (0.02, 0.02, 0.02), "ks": (0.0, 0.0, 0.0), "ns": 4},
    "chrome": {"kd": (0.7, 0.7, 0.72), "ks": (0.8, 0.8, 0.8), "ns": 120},
    "sign": {"kd": (0.1, 0.08, 0.02), "ks": (0.1, 0.1, 0.1), "ns": 10, "ke": (0.85, 0.55, 0.05)},
    "metal": {"kd": (0.5, 0.51, 0.53), "ks": (0.4, 0.4, 0.4), "ns": 40},
}

# Body colours (diffuse RGB) of the colour variants; specular comes with the paint.
PAINTS = {
    "red": (0.62, 0.04, 0.04), "white": (0.86, 0.86, 0.84), "blue": (0.07, 0.18, 0.48),
    "silver": (0.6, 0.61, 0.63), "black": (0.05, 0.05, 0.06), "grey": (0.33, 0.34, 0.36),
    "green": (0.1, 0.3, 0.18), "yellow": (0.9, 0.68, 0.06), "orange": (0.85, 0.35, 0.05),
}

# Each type: size (the body's box L W H; as in makers' figures, the mirrors stand out of it,
# by `mirror` each side), wheels (radius, width, axle x positions), the body's side profile
# `top` (centre height at x, rear to front), belt line, underbody height, glass ranges along
# x, black pillars, and the shapes of the section and plan.
TYPES = {
    "hatchback": dict(
        size=(4.0, 1.75, 1.5), mirror=0.075, wheel=(0.31, 0.2), axles=(1.27, -1.26),
        top=[(-2.0, 0.86), (-1.97, 1.0), (-1.9, 1.06), (-1.55, 1.44), (-1.25, 1.49), (0.0, 1.5),
             (0.28, 1.47), (1.02, 0.99), (1.6, 0.9), (1.88, 0.82), (2.0, 0.68)],
        belt=0.97, zb=0.2, roof_h=0.1, tumble=0.32, windscreen=(0.28, 1.02),
        rear_window=(-1.9, -1.55), side_glass=(-1.42, 1.02), pillars=[(-0.22, -0.14)],
        plan=((0.45, 0.1), (0.25, 0.06)), lights=dict(head_z=(0.6, 0.7), tail_z=(0.86, 0.98)),
        colours=["red", "white", "blue", "silver", "black"], cls="car"),
    "sedan": dict(
        size=(4.65, 1.84, 1.45), mirror=0.08, wheel=(0.32, 0.22), axles=(1.42, -1.33),
        top=[(-2.325, 0.86), (-2.29, 0.94), (-2.2, 0.98), (-1.6, 1.02), (-0.95, 1.38), (-0.65, 1.44),
             (0.1, 1.45), (0.42, 1.42), (1.22, 0.97), (1.9, 0.87), (2.22, 0.79), (2.325, 0.68)],
        belt=0.94, zb=0.2, roof_h=0.1, tumble=0.3, windscreen=(0.42, 1.22),
        rear_window=(-1.6, -0.95), side_glass=(-1.22, 1.22), pillars=[(-0.1, -0.02)],
        plan=((0.5, 0.1), (0.35, 0.07)), lights=dict(head_z=(0.6, 0.7), tail_z=(0.72, 0.83)),
        colours=["silver", "red", "white", "blue", "black"], cls="car"),
    "suv": dict(
        size=(4.6, 1.9, 1.75), mirror=0.08, wheel=(0.37, 0.24), axles=(1.4, -1.38),
        top=[(-2.3, 1.0), (-2.27, 1.12), (-2.22, 1.18), (-2.12, 1.66), (-1.85, 1.73), (0.3, 1.75),
             (0.55, 1.72), (1.25, 1.15), (1.95, 1.08), (2.22, 1.0), (2.3, 0.86)],
        belt=1.12, zb=0.3, roof_h=0.1, tumble=0.22, windscreen=(0.55, 1.25),
        rear_window=(-2.22, -2.12), side_glass=(-2.0, 1.25), pillars=[(-0.12, -0.02), (-1.38, -1.22)],
        plan=((0.45, 0.08), (0.2, 0.05)), lights=dict(head_z=(0.82, 0.94), tail_z=(1.0, 1.14)),
        colours=["black", "white", "grey", "blue", "green"], cls="car"),
    "van": dict(
        size=(5.2, 2.0, 2.2), mirror=0.1, wheel=(0.35, 0.22), axles=(1.75, -1.55),
        top=[(-2.6, 2.0), (-2.57, 2.14), (-2.47, 2.2), (0.95, 2.2), (1.12, 2.12), (1.78, 1.24),
             (2.3, 1.12), (2.53, 1.02), (2.6, 0.86)],
        belt=1.2, zb=0.32, roof_h=0.1, tumble=0.1, windscreen=(1.12, 1.78),
        rear_window=None, side_glass=(0.72, 1.78), pillars=[],
        plan=((0.35, 0.07), (0.1, 0.03)), lights=dict(head_z=(0.84, 0.98), tail_z=(0.7, 1.1), tail_w=0.14),
        rear_glass=(1.32, 1.85), colours=["white", "silver", "blue", "red"], cls="car"),
    "bus": dict(
        size=(12.0, 2.55, 3.1), mirror=0.0, wheel=(0.5, 0.34), axles=(3.35, -2.45),
        top=[(-6.0, 2.86), (-5.96, 2.96), (-5.85, 3.0), (5.85, 3.0), (5.96, 2.96), (6.0, 2.86)],
        belt=1.1, zb=0.32, roof_h=0.34, tumble=0.02, windscreen=None, rear_window=None,
        side_glass=(-5.7, 5.75), pillars=[(x - 0.06, x + 0.06) for x in (-4.3, -2.9, -1.5, -0.1, 1.3, 2.7, 4.1)],
        plan=((0.2, 0.04), (0.15, 0.03)), lights=dict(head_z=(0.55, 0.72), tail_z=(0.55, 0.9)),
        corner=0.14, pillar_material="paint", colours=["red", "blue", "yellow", "white"], cls="bus",
        paints={"red": (0.78, 0.09, 0.07), "blue": (0.13, 0.32, 0.7)}),
}


def section(t, x):
    """The left (y >= 0) half of the cross-section at x: nine (y, z) points from the bottom
    centre round the side to the top centre."""
    L, W, H = t["size"]
    hw = W / 2
    zt = interp(t["top"], x)
    # plan: nose and tail drawn in
    (df, cf), (dr, cr) = t["plan"]
    e_f, e_r = L / 2 - x, x + L / 2
    pf = 1.0
    if e_f < df:
        pf -= cf * (1 - e_f / df) ** 2
    if e_r < dr:
        pf -= cr * (1 - e_r / dr) ** 2
    hw *= pf
    # underbody: lifted at the ends, arched over the wheels
    zb = t["zb"]
    for end in (e_f, e_r):
        if end < 0.4:
            zb += 0.08 * (1 - end / 0.4)
    r, _ = t["wheel"]
    ra = r + 0.045
    for ax in t["axles_all"]:
        dx = abs(x - ax)
        if dx < ra:
            zb = max(zb, r + math.sqrt(ra * ra - dx * dx))
    z4 = min(t["belt"], zt - 0.05)
    zb = min(zb, z4 - 0.08)
    z5 = max(z4, zt - t["roof_h"])
    z6 = z5 + min(0.05, 0.6 * (zt - z5))
    corner = t.get("corner", 0.1)
    y1, z1 = hw - corner, zb
    y2, z2 = hw - 0.025, zb + min(0.07, 0.3 * (z4 - zb))
    y3, z3 = hw, zb + 0.45 * (z4 - zb)
    y4 = hw - 0.025
    y5 = y4 - t["tumble"] * (z5 - z4)
    y6 = y5 - min(corner, 0.4 * y5)
    y7, z7 = 0.55 * y6, zt - 0.15 * (zt - z6)
    return [(0.0, zb), (y1, z1), (y2, z2), (y3, z3), (y4, z4), (y5, z5), (y6, z6), (y7, z7), (0.0, zt)]


def half_width_at(t, x, z):
    """The body's half-width at (x, z) (on the side band, z between sill and roof edge)."""
    s = section(t, x)
    pts = s[1:6]
    if z <= pts[0][1]:
        return pts[0][0]
    for (y0, z0), (y1, z1) in zip(pts, pts[1:]):
        if z <= z1:
            return y0 + (y1 - y0) * (z - z0) / (z1 - z0) if z1 > z0 else max(y0, y1)
    return pts[-1][0]


def stations(t):
    L = t["size"][0]
    xs = {-L / 2, L / 2, -L / 2 + 0.04, L / 2 - 0.04}
    xs.update(x for x, _ in t["top"])
    for rng in (t["windscreen"], t["rear_window"], t["side_glass"]):
        if rng:
            xs.update(rng)
    for a, b in t["pillars"]:
        xs.update((a, b))
    for d in (0.12, 0.25, 0.4):  # rounding of the plan at the ends
        xs.update((L / 2 - d, -L / 2 + d))
    r = t["wheel"][0] + 0.045
    for ax in t["axles_all"]:
        for k in range(9):
            xs.add(ax + r * math.cos(math.pi * k / 8))
        xs.update((ax - r - 0.02, ax + r + 0.02))
    xs = sorted(x for x in xs if -L / 2 <= x <= L / 2)
    # no gap wider than 0.45 m (1.2 m for long bodies), no two closer than 1 cm
    out = []
    gap = 0.45 if L < 7 else 1.2
    for x in xs:
        if out and x - out[-1] < 0.01:
            continue
        if out and x - out[-1] > gap:
            n = int(math.ceil((x - out[-1]) / gap))
            out += [out[-1] + (x - out[-1]) * k / n for k in range(1, n)]
        out.append(x)
    return out


def band_material(t, band, xm, s0, s1):
    """The material of a loft band between two stations (mid x `xm`)."""
    in_range = lambda rng: rng is not None and rng[0] - 1e-6 <= xm <= rng[1] + 1e-6
    if band == 0:
        return "trim"
    if band == 4:
        tall = max(s0[5][1] - s0[4][1], s1[5][1] - s1[4][1]) > 0.03
        if tall and in_range(t["side_glass"]):
            return t.get("pillar_material", "trim") if any(in_range(p) for p in t["pillars"]) else "glass"
    if band in (6, 7) and (in_range(t["windscreen"]) or in_range(t["rear_window"])):
        return "glass"
    return "paint"


def body(m, t):
    xs = stations(t)
    secs = [section(t, x) for x in xs]
    rings = []
    for x, s in zip(xs, secs):
        left = [(x, y, z) for y, z in s]
        right = [(x, -y, z) for y, z in reversed(s[1:-1])]
        rings.append(left + right)

    def material_of(i, j):
        band = j if j < 8 else 15 - j
        return band_material(t, band, 0.5 * (xs[i] + xs[i + 1]), secs[i], secs[i + 1])

    m.begin("body", "paint").smooth(38)
    m.loft(rings, material_of=material_of)
    # end caps: strips between the two sides
    for x, s, sign in ((xs[0], secs[0], -1), (xs[-1], secs[-1], 1)):
        m.flat()
        for b in range(8):
            (ya, za), (yb, zb) = s[b], s[b + 1]
            m.use("trim" if b <= 1 else "paint")
            q = [(x, ya, za), (x, -ya, za), (x, -yb, zb), (x, yb, zb)]
            if sign > 0:  # as listed it faces -x
                q = q[::-1]
            m.quad(*q)
    return xs, secs


def face_rect(m, x, y0, y1, z0, z1, sign, material, part="details"):
    """A rectangle on the plane x = const, facing sign * x."""
    m.begin(part, material).flat()
    q = [(x, y0, z0), (x, y1, z0), (x, y1, z1), (x, y0, z1)]
    m.quad(*q) if _facing(q, (sign, 0, 0)) else m.quad(*q[::-1])


def _facing(q, d):
    n = cross(sub(q[1], q[0]), sub(q[2], q[0]))
    return dot(n, d) > 0


def side_rect(m, t, x0, x1, z0, z1, side, material, out=0.004, rows=3, part="details"):
    """A rectangle on the body side (side +1 left, -1 right), following its curvature."""
    m.begin(part, material).flat()
    zs = [z0 + (z1 - z0) * k / rows for k in range(rows + 1)]
    for za, zb in zip(zs, zs[1:]):
        q = [(x0, side * (half_width_at(t, x0, za) + out), za), (x1, side * (half_width_at(t, x1, za) + out), za),
             (x1, side * (half_width_at(t, x1, zb) + out), zb), (x0, side * (half_width_at(t, x0, zb) + out), zb)]
        m.quad(*q) if _facing(q, (0, side, 0)) else m.quad(*q[::-1])


def cap_half_width(sec, z):
    pts = sec[1:]
    for (y0, z0), (y1, z1) in zip(pts, pts[1:]):
        if z0 <= z <= z1 and z1 > z0:
            return y0 + (y1 - y0) * (z - z0) / (z1 - z0)
    return 0.0


def plate(m, x, yc, zc, sign, w=0.52, h=0.115):
    """An EU-style number plate on the plane x facing sign*x: white, blue strip, characters."""
    d = sign * 0.004
    face_rect(m, x + d, yc - w / 2, yc + w / 2, zc - h / 2, zc + h / 2, sign, "plate")
    # the blue strip is on the plate's left as seen from outside: +y at the front, -y at the back
    edge = yc + sign * (w / 2)
    face_rect(m, x + 2 * d, min(edge, edge - sign * 0.045), max(edge, edge - sign * 0.045),
              zc - h / 2, zc + h / 2, sign, "plate_blue")
    cw, gap = 0.042, 0.014
    n = 7
    start = -sign * (w / 2 - 0.07)
    for k in range(n):
        if k == 2:
            continue
        y = yc + start + sign * k * (cw + gap) * 1.0
        y0, y1 = sorted((y, y + sign * cw))
        # each character: two strokes, so that it reads as text, not a block
        face_rect(m, x + 2 * d, y0, y1, zc + 0.025, zc + 0.038, sign, "plate_text")
        face_rect(m, x + 2 * d, y0, y1, zc - 0.038, zc - 0.025, sign, "plate_text")
        if k % 2:
            face_rect(m, x + 2 * d, y0, y0 + 0.01, zc - 0.038, zc + 0.038, sign, "plate_text")
        else:
            face_rect(m, x + 2 * d, y1 - 0.01, y1, zc - 0.038, zc + 0.038, sign, "plate_text")


def wheel(m, x, y_out, z, r, w, side, n=14):
    """A wheel: axis along y; outer face at y_out (side: +1 left, -1 right)."""
    m.begin("wheels", "tyre")
    yo, yi = y_out, y_out - side * w
    ang = [2 * math.pi * k / n - math.pi / 2 for k in range(n)]  # a corner at the bottom
    pt = lambda rad, a, y: (x + rad * math.cos(a), y, z + rad * math.sin(a))

    def ring_loft(specs, material):
        m.use(material)
        rings = [[pt(rad, a, y) for a in ang] for rad, y in specs]
        if side > 0:  # counter-clockwise about the loft's direction (+y here)
            rings = [rr[::-1] for rr in rings]
        m.loft(rings)

    # tread and shoulder (from the inside out), outer sidewall down to the rim
    m.smooth(50)
    ring_loft([(r * 0.9, yi), (r, yi + side * 0.03), (r, yo - side * 0.03), (r * 0.92, yo),
               (r * 0.68, yo + side * 0.004)], "tyre")
    # rim: a recessed disc with spokes (alternating light and dark sectors)
    m.flat()
    yr = yo - side * 0.025
    ring_loft([(r * 0.68, yo + side * 0.004), (r * 0.64, yr)], "rim")
    c = (x, yr, z)
    for k in range(n):
        a0, a1 = ang[k], ang[(k + 1) % n]
        m.use("rim" if k % 2 == 0 else "rim_dark")
        p0, p1 = pt(r * 0.64, a0, yr), pt(r * 0.64, a1, yr)
        m.tri(c, p0, p1) if side < 0 else m.tri(c, p1, p0)
    # inner face (seen from under the car)
    m.use("tyre")
    ci = (x, yi, z)
    for k in range(n):
        p0, p1 = pt(r * 0.9, ang[k], yi), pt(r * 0.9, ang[(k + 1) % n], yi)
        m.tri(ci, p1, p0) if side < 0 else m.tri(ci, p0, p1)


def mirrors(m, t):
    if t["mirror"] <= 0 or not t["windscreen"]:
        return
    W = t["size"][1]
    x = t["windscreen"][1] - 0.2
    z = t["belt"] - 0.02
    for side in (1, -1):
        y_in = half_width_at(t, x, z + 0.06) - 0.02
        y_out = W / 2 + t["mirror"]
        m.begin("mirrors", "paint").smooth(50)
        m.box((x, side * (y_in + y_out) / 2, z + 0.065), (0.08, y_out - y_in, 0.11))


def car_details(m, t, xs, secs):
    L, W, H = t["size"]
    lights = t["lights"]
    xf, xr = xs[-1], xs[0]
    sf, sr = secs[-1], secs[0]
    # headlights: outer corners of the front face, below its shoulder
    z0, z1 = lights["head_z"]
    z1 = min(z1, sf[4][1] - 0.02)
    z0 = z1 - (lights["head_z"][1] - lights["head_z"][0])
    hwf = min(cap_half_width(sf, z0), cap_half_width(sf, z1)) - 0.03
    for side in (1, -1):
        a, b = sorted((side * hwf * 0.55, side * hwf))
        face_rect(m, xf + 0.004, a, b, z0, z1, 1, "headlight")
        a, b = sorted((side * hwf * 0.48, side * hwf * 0.55))
        face_rect(m, xf + 0.005, a, b, z0 + 0.01, z1 - 0.01, 1, "indicator")
    # grille between them, intake below, plate on the bumper
    face_rect(m, xf + 0.004, -hwf * 0.46, hwf * 0.46, z0 - 0.005, z1 - 0.01, 1, "trim")
    face_rect(m, xf + 0.003, -hwf * 0.7, hwf * 0.7, sf[2][1] + 0.02, sf[2][1] + 0.14, 1, "trim")
    plate(m, xf, 0.0, 0.5 * (z0 + sf[2][1] + 0.14), 1)
    # tail lights, plate, reflector strip at the back
    z0, z1 = lights["tail_z"]
    z1 = min(z1, sr[4][1] - 0.02)
    z0 = z1 - (lights["tail_z"][1] - lights["tail_z"][0])
    hwr = min(cap_half_width(sr, z0), cap_half_width(sr, z1)) - 0.025
    for side in (1, -1):
        a, b = sorted((side * hwr * (1 - lights.get("tail_w", 0.38)), side * hwr))
        face_rect(m, xr - 0.004, a, b, z0, z1, -1, "taillight")
    plate(m, xr, 0.0, z0 - 0.12, -1)
    face_rect(m, xr - 0.003, -hwr * 0.9, hwr * 0.9, sr[2][1] + 0.02, sr[2][1] + 0.1, -1, "trim")
    if t.get("rear_glass"):
        g0, g1 = t["rear_glass"]
        hwg = cap_half_width(sr, g0) - 0.06
        face_rect(m, xr - 0.004, -hwg, hwg, g0, g1, -1, "glass")
        face_rect(m, xr - 0.006, -0.012, 0.012, sr[2][1] + 0.1, g1 + 0.05, -1, "trim")
    # door seams and handles on both sides
    belt = t["belt"]
    zlo = t["zb"] + 0.12
    seams = []
    if t["pillars"] and t["side_glass"]:
        bx = 0.5 * sum(t["pillars"][0])
        seams = [t["side_glass"][1] - 0.05, bx, t["side_glass"][0] + 0.08]
    elif t["side_glass"]:
        seams = [t["side_glass"][1] - 0.05, t["side_glass"][0]]
    for side in (1, -1):
        for sx in seams:
            lo = zlo
            for ax in t["axles_all"]:
                if abs(sx - ax) < t["wheel"][0] + 0.06:
                    lo = max(lo, t["wheel"][0] * 2 + 0.08)
            side_rect(m, t, sx - 0.006, sx + 0.006, lo, belt - 0.02, side, "trim", rows=2)
        for a, b in zip(seams[1:], seams):
            hx = b - 0.22
            if hx - 0.14 > a:
                side_rect(m, t, hx - 0.14, hx, belt - 0.11, belt - 0.08, side, "trim", out=0.006, rows=1)
        # side indicator behind the front wheel arch
        fx = t["axles"][0] + t["wheel"][0] + 0.15
        if seams and fx + 0.07 < seams[0]:
            side_rect(m, t, fx, fx + 0.07, belt - 0.1, belt - 0.07, side, "indicator", rows=1)


def bus_details(m, t, xs, secs):
    L, W, H = t["size"]
    xf, xr = xs[-1], xs[0]
    hw = cap_half_width(secs[-1], 1.5)
    # windscreen, destination sign, headlights, plate; rear window, lights, plate
    face_rect(m, xf + 0.004, -hw + 0.09, hw - 0.09, 0.95, 2.62, 1, "glass")
    face_rect(m, xf + 0.006, -0.012, 0.012, 0.95, 2.62, 1, "trim")
    face_rect(m, xf + 0.004, -hw + 0.2, hw - 0.2, 2.68, 2.9, 1, "sign")
    for side in (1, -1):
        a, b = sorted((side * (hw - 0.08), side * (hw - 0.42)))
        face_rect(m, xf + 0.004, a, b, 0.55, 0.72, 1, "headlight")
        a, b = sorted((side * (hw - 0.08), side * (hw - 0.2)))
        face_rect(m, xf + 0.004, a, b, 0.76, 0.84, 1, "indicator")
        a, b = sorted((side * (hw - 0.06), side * (hw - 0.22)))
        face_rect(m, xr - 0.004, a, b, 0.55, 1.2, -1, "taillight")
        face_rect(m, xr - 0.004, a, b, 1.23, 1.36, -1, "indicator")
    face_rect(m, xf + 0.003, -hw + 0.05, hw - 0.05, 0.36, 0.5, 1, "trim")
    plate(m, xf, 0.0, 0.62, 1)
    face_rect(m, xr - 0.004, -hw + 0.2, hw - 0.2, 1.9, 2.62, -1, "glass")
    face_rect(m, xr - 0.004, -0.45, 0.45, 2.68, 2.86, -1, "sign")  # the route number
    for k in range(6):  # the engine compartment's louvres
        z = 0.75 + 0.12 * k
        face_rect(m, xr - 0.004, -hw + 0.45, hw - 0.45, z, z + 0.05, -1, "trim")
    face_rect(m, xr - 0.004, -hw + 0.25, hw - 0.25, 1.62, 1.68, -1, "trim")
    plate(m, xr, 0.0, 0.45, -1)
    face_rect(m, xr - 0.003, -hw + 0.05, hw - 0.05, 0.34, 0.4, -1, "trim")
    # doors on the right (-y): front (ahead of the front axle), middle, rear
    for x0, x1 in ((L / 2 - 1.45, L / 2 - 0.3), (-0.75, 0.55), (-4.85, -3.7)):
        side_rect(m, t, x0, x1, 0.38, 2.68, -1, "trim", out=0.004, rows=2)
        side_rect(m, t, x0 + 0.06, 0.5 * (x0 + x1) - 0.02, 0.45, 2.6, -1, "glass", out=0.007, rows=2)
        side_rect(m, t, 0.5 * (x0 + x1) + 0.02, x1 - 0.06, 0.45, 2.6, -1, "glass", out=0.007, rows=2)
    # a black band under the windows, the roof's air-conditioning pod
    for side in (1, -1):
        side_rect(m, t, -L / 2 + 0.3, L / 2 - 0.3, 0.36, 0.44, side, "trim", out=0.003, rows=1)
    m.begin("roof", "paint").smooth(40)
    m.box((-1.0, 0.0, 3.05), (3.2, 1.7, 0.1))


def build_vehicle(name):
    t = dict(TYPES[name])
    t["axles_all"] = list(t["axles"])
    m = Mesh()
    xs, secs = body(m, t)
    r, w = t["wheel"]
    for ax in t["axles"]:
        for side in (1, -1):
            yo = half_width_at(t, ax, t["zb"] + 0.1) - 0.012
            wheel(m, ax, side * yo, r, r, w, side, n=16 if r > 0.4 else 14)
    if name == "bus":
        bus_details(m, t, xs, secs)
    else:
        car_details(m, t, xs, secs)
        mirrors(m, t)
    return m, t
