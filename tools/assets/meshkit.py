"""Small procedural-mesh toolkit for the asset generators (make_road_users.py, make_scenery.py):
triangles in named parts (OBJ groups) with a material each, optional texture coordinates,
crease-angle normals, lofts, and an OBJ + MTL writer with shared vertices, normals and texture
coordinates. Stdlib only; output deterministic."""
import math
import os


# ---------------------------------------------------------------- small vector helpers
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    n = math.sqrt(dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n) if n > 0 else (0.0, 0.0, 1.0)


def lerp(a, b, t):
    return tuple(x + (y - x) * t for x, y in zip(a, b))


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return ((1, 0, 0), (0, c, -s), (0, s, c))


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, 0, s), (0, 1, 0), (-s, 0, c))


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, -s, 0), (s, c, 0), (0, 0, 1))


def mat_mul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


def mat_vec(m, v):
    return (dot(m[0], v), dot(m[1], v), dot(m[2], v))


IDENTITY = ((1, 0, 0), (0, 1, 0), (0, 0, 1))


def frame_along(axis):
    """A rotation whose z column is `axis` (unit), x column as close to world +x as possible."""
    z = norm(axis)
    ref = (1, 0, 0) if abs(z[0]) < 0.9 else (0, 0, 1)
    y = norm(cross(z, ref))
    x = cross(y, z)
    return ((x[0], y[0], z[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2]))


def interp(points, x):
    """Piecewise-linear y(x) through sorted (x, y) points, clamped at the ends."""
    if x <= points[0][0]:
        return points[0][1]
    for (x0, y0), (x1, y1) in zip(points, points[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0) if x1 > x0 else y1
    return points[-1][1]


# ---------------------------------------------------------------- the mesh
class Mesh:
    """Triangles in parts (OBJ groups `g name`), each part one material. Normals come from
    the triangles: averaged over triangles of the same smoothing set that share a corner
    position and bend less than `crease` degrees; a new set starts with every `smooth()`."""

    def __init__(self):
        self.tris = []  # (part, material, set, (a, b, c))
        self.uvs = {}  # index in tris: (uv a, uv b, uv c), for the textured triangles only
        self.part, self.material, self.set = "body", "default", 0
        self.crease = {}

    def begin(self, part, material=None):
        self.part = part
        if material:
            self.material = material
        return self

    def use(self, material):
        self.material = material
        return self

    def smooth(self, crease=40.0):
        self.set += 1
        self.crease[self.set] = crease
        return self

    def flat(self):
        return self.smooth(0.0)

    def tri(self, a, b, c):
        n = cross(sub(b, a), sub(c, a))
        if dot(n, n) < 1e-14:  # degenerate: skip
            return
        self.tris.append((self.part, self.material, self.set, (tuple(a), tuple(b), tuple(c))))

    def quad(self, a, b, c, d):
        # split along the shorter diagonal
        if dot(sub(a, c), sub(a, c)) <= dot(sub(b, d), sub(b, d)):
            self.tri(a, b, c)
            self.tri(a, c, d)
        else:
            self.tri(a, b, d)
            self.tri(b, c, d)

    def poly(self, pts):
        """A convex polygon as a fan (counter-clockwise seen from the front)."""
        for i in range(1, len(pts) - 1):
            self.tri(pts[0], pts[i], pts[i + 1])

    # -- textured triangles (uv: (u, v), v = 0 at the bottom of the image, as in OBJ)
    def tri_uv(self, a, b, c, ta, tb, tc):
        n = len(self.tris)
        self.tri(a, b, c)
        if len(self.tris) > n:
            self.uvs[n] = (tuple(ta), tuple(tb), tuple(tc))

    def poly_uv(self, pts, uvs):
        """A textured convex polygon as a fan; uvs: one (u, v) per point."""
        for i in range(1, len(pts) - 1):
            self.tri_uv(pts[0], pts[i], pts[i + 1], uvs[0], uvs[i], uvs[i + 1])

    # -- transforms of what was added since `mark`
    def mark(self):
        return len(self.tris)

    def transform(self, since, rot=IDENTITY, move=(0, 0, 0)):
        for i in range(since, len(self.tris)):
            p, m, s, t = self.tris[i]
            self.tris[i] = (p, m, s, tuple(add(mat_vec(rot, v), move) for v in t))

    def mirror_y(self, since):
        """Adds the mirror image (y -> -y) of the triangles added since `since`, winding fixed."""
        for i in range(since, self.mark()):
            p, m, s, (a, b, c) = self.tris[i]
            f = lambda v: (v[0], -v[1], v[2])
            self.tris.append((p, m, s, (f(a), f(c), f(b))))

    def rename(self, since, part):
        for i in range(since, len(self.tris)):
            p, m, s, t = self.tris[i]
            self.tris[i] = (part, m, s, t)

    # -- primitives
    def loft(self, rings, closed=True, material_of=None, cap_start=False, cap_end=False):
        """Quads between consecutive rings (equal-length point lists). Rings go counter-clockwise
        seen from the end the loft runs towards... i.e. outward normals when the ring order is
        counter-clockwise about the direction from ring 0 to ring 1. material_of(i, j) may
        give the material of the quad between ring i, i+1 and points j, j+1."""
        n = len(rings[0])
        span = n if closed else n - 1
        base = self.material
        for i in range(len(rings) - 1):
            r0, r1 = rings[i], rings[i + 1]
            for j in range(span):
                k = (j + 1) % n
                if material_of:
                    self.material = material_of(i, j) or base
                self.quad(r0[j], r0[k], r1[k], r1[j])
        self.material = base
        if cap_start:
            self.poly(list(reversed(rings[0])))
        if cap_end:
            self.poly(list(rings[-1]))

    def tube(self, a, b, ra, rb=None, n=8, cap_a=True, cap_b=True, squash=1.0):
        """A truncated cone from a to b (radii ra, rb), n sides, optional flat caps."""
        rb = ra if rb is None else rb
        f = frame_along(sub(b, a))
        rings = []
        for c, r in ((a, ra), (b, rb)):
            ring = []
            for i in range(n):
                t = 2 * math.pi * i / n
                ring.append(add(c, mat_vec(f, (r * math.cos(t), r * squash * math.sin(t), 0))))
            rings.append(ring)
        self.loft(rings, cap_start=cap_a, cap_end=cap_b)

    def ellipsoid(self, c, r, rot=IDENTITY, stacks=6, slices=8, zcut=None):
        """An ellipsoid of radii r = (rx, ry, rz) about centre c; zcut (in -1..1) keeps only
        the part above that fraction of rz (then open at the bottom)."""
        rings = []
        lo = -math.pi / 2 if zcut is None else math.asin(max(-1.0, min(1.0, zcut)))
        for i in range(stacks + 1):
            phi = lo + (math.pi / 2 - lo) * i / stacks
            ring = []
            for j in range(slices):
                t = 2 * math.pi * j / slices
                p = (r[0] * math.cos(phi) * math.cos(t), r[1] * math.cos(phi) * math.sin(t),
                     r[2] * math.sin(phi))
                ring.append(add(c, mat_vec(rot, p)))
            rings.append(ring)
        self.loft(rings)

    def box(self, c, s, rot=IDENTITY):
        x, y, z = s[0] / 2, s[1] / 2, s[2] / 2
        corners = [add(c, mat_vec(rot, (sx * x, sy * y, sz * z)))
                   for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
        q = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        for a, b, cc, d in q:
            self.quad(corners[a], corners[b], corners[cc], corners[d])

    def block(self, lo, hi, skip=()):
        """An axis-aligned box from corner lo to corner hi, leaving out the faces named in
        `skip` ("-x", "+x", "-y", "+y", "-z", "+z"): those that stand against something."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        faces = {"-z": ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
                 "+z": ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
                 "-y": ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
                 "+y": ((x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)),
                 "-x": ((x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)),
                 "+x": ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))}
        for name in ("-z", "+z", "-y", "+y", "-x", "+x"):
            if name not in skip:
                self.quad(*faces[name])

    def cone(self, base, apex, r, n=8, cap=True):
        """A cone from a disc of radius r about `base` to `apex`, n sides, optionally closed below."""
        f = frame_along(sub(apex, base))
        ring = [add(base, mat_vec(f, (r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), 0)))
                for i in range(n)]
        for i in range(n):
            self.tri(ring[i], ring[(i + 1) % n], apex)
        if cap:
            self.poly(list(reversed(ring)))

    def sweep(self, outline, offset, cap_start=False, cap_end=False):
        """A prism: the closed outline (points) moved by `offset`. Outward normals when the
        outline runs counter-clockwise about `offset`; caps only for convex outlines."""
        self.loft([list(outline), [add(p, offset) for p in outline]], cap_start=cap_start, cap_end=cap_end)

    def lumpy_ellipsoid(self, c, r, rng, lumps=0.15, stacks=5, slices=8, zcut=None):
        """An ellipsoid whose radius varies smoothly with direction by up to about `lumps`
        (a fraction): a leaf cluster, a shrub. rng (random.Random) draws the lumps."""
        waves = [(norm((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))), rng.uniform(2.0, 3.5),
                  rng.uniform(0, 2 * math.pi)) for _ in range(3)]
        twist = rng.uniform(0, 2 * math.pi)
        lo = -math.pi / 2 if zcut is None else math.asin(max(-1.0, min(1.0, zcut)))
        rings = []
        for i in range(stacks + 1):
            phi = lo + (math.pi / 2 - lo) * i / stacks
            ring = []
            for j in range(slices):
                t = twist + 2 * math.pi * (j + 0.5 * (i % 2)) / slices
                d = (math.cos(phi) * math.cos(t), math.cos(phi) * math.sin(t), math.sin(phi))
                if abs(d[2]) > 0.9999:
                    d = (0.0, 0.0, 1.0 if d[2] > 0 else -1.0)
                k = 1 + lumps / 1.6 * sum(math.sin(f * dot(d, w) + ph) for w, f, ph in waves)
                ring.append(add(c, (r[0] * d[0] * k, r[1] * d[1] * k, r[2] * d[2] * k)))
            rings.append(ring)
        self.loft(rings)
        if zcut is not None:
            self.poly(list(reversed(rings[0])))

    # -- output
    def count(self, select=None):
        return sum(1 for t in self.tris if select is None or select(t[0], t[1]))

    def fit(self, size=None, select=None):
        """Moves the mesh so that the bounding box's base centre is the origin and, given
        `size`, scales each axis to that size exactly (a fraction of a percent for decals
        that stand out of the body). The box is that of the triangles `select` (part,
        material) picks, or of all. Returns the size of that box."""
        lo, hi = self.bounds(select)
        move = (-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2])
        self.transform(0, move=move)
        if size:
            s = [size[k] / (hi[k] - lo[k]) for k in range(3)]
            self.transform(0, rot=((s[0], 0, 0), (0, s[1], 0), (0, 0, s[2])))
        lo, hi = self.bounds(select)
        return tuple(hi[k] - lo[k] for k in range(3))

    def bounds(self, select=None):
        lo, hi = [1e9] * 3, [-1e9] * 3
        for p, mat, _, t in self.tris:
            if select is not None and not select(p, mat):
                continue
            for v in t:
                for k in range(3):
                    lo[k], hi[k] = min(lo[k], v[k]), max(hi[k], v[k])
        return lo, hi

    def normals(self):
        """Per-triangle corner normals (crease-angle smoothing within each set)."""
        faces = []
        for _, _, _, (a, b, c) in self.tris:
            faces.append(cross(sub(b, a), sub(c, a)))  # area-weighted
        units = [norm(f) for f in faces]
        key = lambda v: (round(v[0], 4), round(v[1], 4), round(v[2], 4))
        corners = {}
        for i, (_, _, s, t) in enumerate(self.tris):
            for v in t:
                corners.setdefault((s, key(v)), []).append(i)
        out = []
        for i, (_, _, s, t) in enumerate(self.tris):
            limit = math.cos(math.radians(self.crease.get(s, 0.0)))
            ns = []
            for v in t:
                acc = (0.0, 0.0, 0.0)
                for j in corners[(s, key(v))]:
                    if j == i or dot(units[i], units[j]) >= limit - 1e-9:
                        acc = add(acc, faces[j])
                ns.append(norm(acc))
            out.append(ns)
        return out

    def write_obj(self, path, materials=None, header="", select=None, mtl_name=None):
        """Writes the mesh (or the triangles for which select(part, material) is true) as OBJ;
        with `materials` ({name: dict}) also an MTL next to it (named mtl_name or like the
        OBJ) that the OBJ references. Returns the number of triangles written."""
        ns = self.normals()
        vidx, nidx, vs, vns = {}, {}, [], []
        tidx, vts = {}, []
        groups = {}
        order = []
        for i, (part, mat, _, t) in enumerate(self.tris):
            if select is not None and not select(part, mat):
                continue
            face = []
            uv = self.uvs.get(i)
            for corner, (v, n) in enumerate(zip(t, ns[i])):
                kv = "%.4f %.4f %.4f" % v
                kn = "%.3f %.3f %.3f" % n
                if kv not in vidx:
                    vidx[kv] = len(vs) + 1
                    vs.append(kv)
                if kn not in nidx:
                    nidx[kn] = len(vns) + 1
                    vns.append(kn)
                if uv is None:
                    face.append("%d//%d" % (vidx[kv], nidx[kn]))
                else:
                    kt = "%.4f %.4f" % uv[corner]
                    if kt not in tidx:
                        tidx[kt] = len(vts) + 1
                        vts.append(kt)
                    face.append("%d/%d/%d" % (vidx[kv], tidx[kt], nidx[kn]))
            k = (part, mat)
            if k not in groups:
                groups[k] = []
                order.append(k)
            groups[k].append(" ".join(face))
        base = os.path.splitext(os.path.basename(path))[0]
        lines = ["# " + line for line in header.splitlines()]
        if materials is not None:
            mtl = (mtl_name or base) + ".mtl"
            lines.append("mtllib " + mtl)
        lines += ["v " + v for v in vs] + ["vt " + t for t in vts] + ["vn " + n for n in vns]
        for part, mat in order:
            lines.append("g %s" % part)
            if materials is not None:
                lines.append("usemtl %s" % mat)
            lines += ["f " + f for f in groups[(part, mat)]]
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        if materials is not None:
            used = sorted({m for _, m in order})
            write_mtl(os.path.join(os.path.dirname(path), (mtl_name or base) + ".mtl"),
                      {m: materials[m] for m in used}, header)
        return sum(len(g) for g in groups.values())


def write_mtl(path, materials, header=""):
    """materials: {name: {"kd": rgb, "ks": rgb (optional), "ns": float, "ke": rgb (optional),
    "map": diffuse texture file relative to the MTL (optional)}}."""
    lines = ["# " + line for line in header.splitlines()]
    for name in sorted(materials):
        m = materials[name]
        kd = m["kd"]
        lines.append("newmtl %s" % name)
        lines.append("Ka %.3f %.3f %.3f" % tuple(kd))
        lines.append("Kd %.3f %.3f %.3f" % tuple(kd))
        lines.append("Ks %.3f %.3f %.3f" % tuple(m.get("ks", (0.1, 0.1, 0.1))))
        lines.append("Ns %g" % m.get("ns", 16))
        if "ke" in m:
            lines.append("Ke %.3f %.3f %.3f" % tuple(m["ke"]))
        if "map" in m:
            lines.append("map_Kd %s" % m["map"])
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
