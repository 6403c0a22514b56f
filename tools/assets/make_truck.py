"""The truck for the road-user actors (make_road_users.py): a cab lofted as the cars are
(make_vehicles.py's body), a box body with rear doors, a stripe in the cab's colour and a
tandem. Frame: x forward, y left, z up; the origin at the centre of the bounding box's base."""
import math

from make_vehicles import _facing, body, cap_half_width, face_rect, half_width_at, plate, wheel
from meshkit import Mesh


def build_truck():
    L, W, H = 9.0, 2.5, 3.4
    m = Mesh()
    cab_dx = L / 2 - 1.15  # the cab's centre x in the truck's frame
    front_axle = L / 2 - 1.0
    cab = dict(size=(2.3, W - 0.12, 3.0), mirror=0.0, wheel=(0.5, 0.3), axles=(), axles_all=[front_axle - cab_dx],
               top=[(-1.15, 2.95), (0.85, 2.95), (1.07, 2.78), (1.15, 2.55)],
               belt=1.78, zb=0.62, roof_h=0.3, tumble=0.06, windscreen=None, rear_window=None,
               side_glass=(-0.15, 1.12), pillars=[], plan=((0.22, 0.05), (0.05, 0.01)), corner=0.12)
    # the cab loft, in its own frame, then moved forward
    k = m.mark()
    xs, secs = body(m, cab)
    m.transform(k, move=(cab_dx, 0, 0))
    sf = secs[-1]
    xf = L / 2
    hw = cap_half_width(sf, 2.0)
    face_rect(m, xf + 0.004, -hw + 0.1, hw - 0.1, 1.85, 2.5, 1, "glass")
    face_rect(m, xf + 0.006, -hw + 0.25, hw - 0.25, 0.95, 1.6, 1, "trim")  # grille
    for zz in (1.1, 1.25, 1.4):
        face_rect(m, xf + 0.008, -hw + 0.3, hw - 0.3, zz, zz + 0.035, 1, "chrome")
    face_rect(m, xf + 0.004, -hw + 0.02, hw - 0.02, 0.62, 0.9, 1, "trim")  # bumper
    for side in (1, -1):
        a, b = sorted((side * (hw - 0.04), side * (hw - 0.32)))
        face_rect(m, xf + 0.008, a, b, 0.7, 0.84, 1, "headlight")
        a, b = sorted((side * (hw - 0.04), side * (hw - 0.2)))
        face_rect(m, xf + 0.006, a, b, 0.95, 1.05, 1, "indicator")
    plate(m, xf, 0.0, 0.76, 1)
    face_rect(m, xf + 0.004, -hw + 0.35, hw - 0.35, 2.6, 2.8, 1, "trim")  # sun visor band
    tcab = dict(cab)

    def cab_hw(x, z):
        return half_width_at(tcab, x - cab_dx, z)

    for side in (1, -1):
        # door seam, handle, step, mirror
        m.begin("details", "trim").flat()
        y = cab_hw(L / 2 - 1.2, 1.2)
        m.box((L / 2 - 1.22, side * (y + 0.003), 1.2), (0.012, 0.012, 1.1))
        m.box((L / 2 - 0.75, side * (y + 0.005), 1.62), (0.16, 0.012, 0.03))
        m.box((L / 2 - 0.7, side * (y - 0.05), 0.5), (0.5, 0.14, 0.05))
        m.begin("mirrors", "trim")
        m.box((L / 2 - 0.12, side * (W / 2 - 0.04), 2.15), (0.06, 0.08, 0.38))
        m.begin("details", "metal")
    # the box body
    bx0, bx1, bz0, bz1, bhw = -L / 2, L / 2 - 2.4, 1.18, H, W / 2
    rad = 0.06
    rings = []
    prof = []
    for (cy, cz, a0) in ((bhw - rad, bz0 + rad, -90), (bhw - rad, bz1 - rad, 0), (-bhw + rad, bz1 - rad, 90),
                         (-bhw + rad, bz0 + rad, 180)):
        for k in range(3):
            a = math.radians(a0 + 45 * k)
            prof.append((cy + rad * math.cos(a), cz + rad * math.sin(a)))
    # ring order: counter-clockwise about +x means y -> z, so go (y, z) with increasing angle
    for x in (bx0, bx0 + 0.03, bx1 - 0.03, bx1):
        inset = 0.02 if x in (bx0, bx1) else 0.0
        rings.append([(x, y * (1 - inset / bhw), z + (inset if z < 2 else -inset)) for y, z in prof])
    m.begin("cargo", "cargo").smooth(50)
    m.loft(rings, cap_start=True, cap_end=True)
    # rear doors: a dark frame, the seam, lock rods, hinges; a stripe in the cab's colour
    xb = bx0 - 0.004
    e = bhw - 0.03
    for y0, y1, z0, z1 in ((-e, e, bz0 + 0.03, bz0 + 0.1), (-e, e, bz1 - 0.1, bz1 - 0.03),
                           (-e, -e + 0.07, bz0 + 0.03, bz1 - 0.03), (e - 0.07, e, bz0 + 0.03, bz1 - 0.03),
                           (-0.012, 0.012, bz0 + 0.1, bz1 - 0.1)):
        face_rect(m, xb, y0, y1, z0, z1, -1, "trim")
    for yy in (-0.75, -0.3, 0.3, 0.75):
        face_rect(m, xb - 0.003, yy - 0.018, yy + 0.018, bz0 + 0.12, bz1 - 0.12, -1, "chrome")
        face_rect(m, xb - 0.005, yy - 0.012, yy + 0.012, 1.75, 1.95, -1, "trim")  # its handle
    for zz in (1.45, 2.3, 3.15):
        for yy in (-e + 0.07, e - 0.15):
            face_rect(m, xb - 0.003, yy, yy + 0.08, zz, zz + 0.07, -1, "metal")
    face_rect(m, xb - 0.002, -e + 0.07, e - 0.07, 2.75, 3.0, -1, "paint")
    for side in (1, -1):  # the stripe along the sides, panel lines
        m.begin("cargo", "paint").flat()
        y = side * (bhw + 0.004)
        q = [(bx0 + 0.1, y, 2.75), (bx1 - 0.1, y, 2.75), (bx1 - 0.1, y, 3.0), (bx0 + 0.1, y, 3.0)]
        m.quad(*q) if _facing(q, (0, side, 0)) else m.quad(*q[::-1])
        m.use("trim")
        for px in [bx0 + 0.9 * k for k in range(1, 8)]:
            q = [(px - 0.01, y, bz0 + 0.05), (px + 0.01, y, bz0 + 0.05), (px + 0.01, y, bz1 - 0.05), (px - 0.01, y, bz1 - 0.05)]
            m.quad(*q) if _facing(q, (0, side, 0)) else m.quad(*q[::-1])
        q = [(bx0 + 0.05, y, bz0 + 0.02), (bx1 - 0.05, y, bz0 + 0.02), (bx1 - 0.05, y, bz0 + 0.12), (bx0 + 0.05, y, bz0 + 0.12)]
        m.quad(*q) if _facing(q, (0, side, 0)) else m.quad(*q[::-1])
        m.begin("chassis", "trim")
        m.box((-4.05, side * 1.0, 0.55), (0.02, 0.42, 0.5))  # mud flaps
    # chassis: rails, rear under-run bar with lights, side guards, fuel tank, mudguards
    m.begin("chassis", "trim").flat()
    m.box((-0.6, 0.5, 0.95), (7.4, 0.12, 0.3))
    m.box((-0.6, -0.5, 0.95), (7.4, 0.12, 0.3))
    m.box((bx0 + 0.1, 0, 0.62), (0.12, 2.3, 0.16))
    m.box((bx0 + 0.3, 0, 0.9), (0.5, 2.2, 0.45))
    for side in (1, -1):
        m.use("metal")
        m.box((-0.9, side * 1.17, 0.72), (2.2, 0.03, 0.08))
        m.box((-0.9, side * 1.17, 0.9), (2.2, 0.03, 0.08))
        m.use("trim")
        m.box((-2.97, side * 1.05, 1.1), (2.25, 0.4, 0.06))  # mudguard over the tandem
        a, b = sorted((side * 1.12, side * 0.75))
        face_rect(m, bx0 + 0.036, a, b, 0.56, 0.68, -1, "taillight")
        a, b = sorted((side * 0.74, side * 0.6))
        face_rect(m, bx0 + 0.036, a, b, 0.56, 0.68, -1, "indicator")
    m.use("metal")
    m.tube((0.3, 0.92, 0.8), (1.3, 0.92, 0.8), 0.24, n=10)  # fuel tank
    plate(m, bx0 + 0.04, 0.0, 0.62, -1)
    # wheels: front axle under the cab, a tandem at the back (twin tyres: wider)
    for ax, w in ((front_axle, 0.3), (-2.3, 0.5), (-3.65, 0.5)):
        for side in (1, -1):
            wheel(m, ax, side * (W / 2 - 0.03), 0.5, 0.5, w, side, n=16)
    t = dict(size=(L, W, H), cls="truck", colours=["white", "red", "blue", "orange"],
             cargo_colours=["white", "silver", "white", "white"], axles=(3.5, -2.98), wheel=(0.5, 0.5))
    return m, t
