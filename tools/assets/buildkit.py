"""Façades and roofs for the building generator (make_buildings.py). A Face is one wall of a
box-shaped building seen from outside: s runs along it to the right, t up, d outwards (d < 0
into the wall). Its wall is tessellated around rectangular openings (rows of openings of the
same height band), each opening a recessed window, door, shop window or window band with its
reveals, frame and glass; the other walls get flat windows (frame and glass just proud of the
wall). The wall quads and reveals are material "walls" (the building's colour, a mesh of its
own); the rest are detail materials."""
import math

from meshkit import add, cross, dot, mul, sub

RECESS = 0.14  # m, windows behind the wall's face


class Face:
    def __init__(self, m, origin, u, width, height):
        self.m, self.o, self.u, self.w, self.h = m, origin, u, width, height
        self.n = cross(u, (0, 0, 1))  # outward

    def p(self, s, t, d=0.0):
        return add(add(self.o, mul(self.u, s)), (self.n[0] * d, self.n[1] * d, t + self.n[2] * d))

    def facing(self, pts, want, material):
        """A quad (or triangle) of local points (s, t, d) turned to face `want` (local: 'out',
        'in', 'up', 'down', 'right', 'left')."""
        vec = {"out": self.n, "in": mul(self.n, -1), "up": (0, 0, 1), "down": (0, 0, -1),
               "right": self.u, "left": mul(self.u, -1)}[want]
        w = [self.p(*q) for q in pts]
        if dot(cross(sub(w[1], w[0]), sub(w[2], w[0])), vec) < 0:
            w.reverse()
        self.m.use(material)
        if len(w) == 4:
            self.m.quad(*w)
        else:
            self.m.poly(w)

    def rect(self, s0, t0, s1, t1, d, material):
        if s1 > s0 + 1e-6 and t1 > t0 + 1e-6:
            self.facing([(s0, t0, d), (s1, t0, d), (s1, t1, d), (s0, t1, d)], "out", material)

    def rect_uv(self, s0, t0, s1, t1, d, material):
        self.m.use(material)
        pts = [self.p(s0, t0, d), self.p(s1, t0, d), self.p(s1, t1, d), self.p(s0, t1, d)]
        self.m.poly_uv(pts, [(0, 0), (1, 0), (1, 1), (0, 1)])

    def block(self, s0, t0, d0, s1, t1, d1, material, back=False):
        """A box in local coordinates; its face against the wall (d0) left out unless `back`."""
        a, b = self.p(s0, t0, d0), self.p(s1, t1, d1)
        lo = tuple(min(a[k], b[k]) for k in range(3))
        hi = tuple(max(a[k], b[k]) for k in range(3))
        inner = self.p(0, 0, -1)
        axis = max(range(3), key=lambda k: abs(self.n[k]))
        skip = () if back else (("+" if inner[axis] > self.o[axis] else "-") + "xyz"[axis],)
        self.m.use(material)
        self.m.block(lo, hi, skip=skip)

    # -- walls
    def wall(self, rows, top=None, material="walls"):
        """The wall from the ground to `top` around the openings. rows: [(t0, t1, [(s0, s1, ta,
        tb)])], by height: a band t0..t1 whose openings span s0..s1 and ta..tb within it."""
        top = self.h if top is None else top
        t = 0.0
        self.m.begin("walls", material).flat()
        for t0, t1, holes in rows:
            self.rect(0, t, self.w, t0, 0, material)
            s = 0.0
            for s0, s1, ta, tb in sorted(holes):
                self.rect(s, t0, s0, t1, 0, material)
                self.rect(s0, t0, s1, ta, 0, material)
                self.rect(s0, tb, s1, t1, 0, material)
                s = s1
            self.rect(s, t0, self.w, t1, 0, material)
            t = t1
        self.rect(0, t, self.w, top, 0, material)

    def gable(self, t0, t1, material="walls"):
        """The triangle of wall under a pitched roof, eaves at t0, ridge t1 over the middle."""
        self.m.begin("walls", material).flat()
        self.facing([(0, t0, 0), (self.w, t0, 0), (self.w / 2, t1, 0)], "out", material)

    def reveal(self, s0, t0, s1, t1, depth, material="walls"):
        self.m.begin("walls", material).flat()
        self.facing([(s0, t0, 0), (s1, t0, 0), (s1, t0, -depth), (s0, t0, -depth)], "up", material)
        self.facing([(s0, t1, 0), (s1, t1, 0), (s1, t1, -depth), (s0, t1, -depth)], "down", material)
        self.facing([(s0, t0, 0), (s0, t1, 0), (s0, t1, -depth), (s0, t0, -depth)], "right", material)
        self.facing([(s1, t0, 0), (s1, t1, 0), (s1, t1, -depth), (s1, t0, -depth)], "left", material)

    # -- openings (each fills the hole s0..s1 x t0..t1 that wall() left)
    def window(self, s0, t0, s1, t1, frame="frame", mullion=True, sill="trim", depth=RECESS):
        self.reveal(s0, t0, s1, t1, depth)
        self.m.begin("windows")
        fw = 0.065
        self.rect(s0, t0, s1, t1, -depth, frame)
        self.rect(s0 + fw, t0 + fw, s1 - fw, t1 - fw, -depth + 0.01, "glass")
        if mullion:
            sm = (s0 + s1) / 2
            self.rect(sm - 0.03, t0 + fw, sm + 0.03, t1 - fw, -depth + 0.02, frame)
        if sill:
            self.m.begin("sills")
            self.facing([(s0 - 0.05, t0, 0), (s1 + 0.05, t0, 0), (s1 + 0.05, t0, 0.06), (s0 - 0.05, t0, 0.06)],
                        "up", sill)
            self.rect(s0 - 0.05, t0 - 0.05, s1 + 0.05, t0, 0.06, sill)

    def door(self, s0, s1, t1, leaf="door", frame="frame", canopy="trim", depth=0.22):
        self.reveal(s0, 0.0, s1, t1, depth)
        self.m.begin("doors")
        self.rect(s0, 0.0, s1, t1, -depth, frame)
        self.rect(s0 + 0.07, 0.0, s1 - 0.07, t1 - 0.07, -depth + 0.01, leaf)
        self.rect(s0 + 0.25, 1.1, s1 - 0.25, t1 - 0.3, -depth + 0.02, "glass")
        if canopy:
            self.block(s0 - 0.3, t1 + 0.15, 0, s1 + 0.3, t1 + 0.27, 0.8, canopy)

    def band(self, s0, t0, s1, t1, pitch, frame="frame_dark", depth=0.1):
        """A window band (office storey, shop window): glass behind mullions every ~pitch m."""
        self.reveal(s0, t0, s1, t1, depth)
        self.m.begin("windows")
        self.rect(s0, t0, s1, t1, -depth, frame)
        self.rect(s0 + 0.06, t0 + 0.06, s1 - 0.06, t1 - 0.06, -depth + 0.01, "glass")
        n = max(1, int(round((s1 - s0) / pitch)))
        for k in range(1, n):
            s = s0 + (s1 - s0) * k / n
            self.rect(s - 0.035, t0 + 0.06, s + 0.035, t1 - 0.06, -depth + 0.02, frame)

    def flat_window(self, s0, t0, s1, t1, frame="frame", mullion=False):
        """A window drawn on the wall: frame and glass just proud of it (no hole)."""
        self.m.begin("windows")
        self.rect(s0, t0, s1, t1, 0.012, frame)
        self.rect(s0 + 0.065, t0 + 0.065, s1 - 0.065, t1 - 0.065, 0.02, "glass")
        if mullion:
            sm = (s0 + s1) / 2
            self.rect(sm - 0.03, t0 + 0.065, sm + 0.03, t1 - 0.065, 0.028, frame)


def columns(width, n, win, margin=None):
    """The s ranges of n windows `win` wide spread evenly over a wall `width` wide."""
    margin = (width / n - win) / 2 if margin is None else margin
    pitch = (width - 2 * margin) / n
    return [(margin + pitch * (k + 0.5) - win / 2, margin + pitch * (k + 0.5) + win / 2) for k in range(n)]


def faces(m, D, W, H):
    """The four walls of a D x W x H box centred on the origin: front (+x), back, left (+y), right."""
    return {"front": Face(m, (D / 2, -W / 2, 0), (0, 1, 0), W, H),
            "back": Face(m, (-D / 2, W / 2, 0), (0, -1, 0), W, H),
            "left": Face(m, (D / 2, W / 2, 0), (-1, 0, 0), D, H),
            "right": Face(m, (-D / 2, -W / 2, 0), (1, 0, 0), D, H)}


# ---------------------------------------------------------------- roofs and trims
def flat_roof(m, D, W, H, cornice="trim", roof="roof_flat", over=0.14, depth=0.35, lift=0.18):
    """A cornice band round the top of the walls and the flat roof on it."""
    m.begin("cornice", cornice).flat()
    m.block((-D / 2 - over, -W / 2 - over, H - depth), (D / 2 + over, W / 2 + over, H + lift), skip=("+z",))
    m.begin("roof", roof).flat()
    m.block((-D / 2 - over, -W / 2 - over, H + lift), (D / 2 + over, W / 2 + over, H + lift + 0.01), skip=("-z",))


def plinth(m, D, W, height=0.45, material="plinth", out=0.03):
    m.begin("plinth", material).flat()
    m.block((-D / 2 - out, -W / 2 - out, 0), (D / 2 + out, W / 2 + out, height), skip=("-z",))


def pitched_roof(m, D, W, eaves, ridge, roof="roof_tiles", over=0.35, thick=0.16, soffit="trim"):
    """A gable roof over a D x W box, ridge along y at `ridge`, eaves at `eaves` (the walls'
    top), overhanging by `over` all round; the gable triangles are the Faces' business."""
    slope = (ridge - eaves) / (D / 2)
    y0, y1 = -W / 2 - over, W / 2 + over
    for s in (1, -1):
        xe = s * (D / 2 + over)
        ze = eaves - over * slope
        top = [(xe, y0, ze + thick), (xe, y1, ze + thick), (0, y1, ridge + thick), (0, y0, ridge + thick)]
        bot = [(xe, y0, ze), (xe, y1, ze), (0, y1, ridge), (0, y0, ridge)]
        m.begin("roof", roof).flat()
        _quad_facing(m, top, (s * slope, 0, 1))
        _quad_facing(m, [top[0], top[1], bot[1], bot[0]], (s, 0, -0.2))  # eave edge
        _quad_facing(m, [top[0], top[3], bot[3], bot[0]], (0, -1, 0))  # verge edges
        _quad_facing(m, [top[1], top[2], bot[2], bot[1]], (0, 1, 0))
        m.begin("soffit", soffit).flat()
        _quad_facing(m, bot, (-s * slope, 0, -1))
    m.begin("roof", roof).flat()  # ridge cap
    m.block((-0.1, y0, ridge + thick - 0.02), (0.1, y1, ridge + thick + 0.08), skip=("-z",))


def _quad_facing(m, pts, want):
    if dot(cross(sub(pts[1], pts[0]), sub(pts[2], pts[0])), want) < 0:
        pts = list(reversed(pts))
    m.quad(*pts)


def chimney(m, x, y, z0, z1, material="chimney"):
    m.begin("chimney", material).flat()
    m.block((x - 0.3, y - 0.25, z0), (x + 0.3, y + 0.25, z1), skip=("-z",))
    m.block((x - 0.35, y - 0.3, z1), (x + 0.35, y + 0.3, z1 + 0.08), skip=())


def rot_mesh(m, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    m.transform(0, rot=((c, -s, 0), (s, c, 0), (0, 0, 1)))
