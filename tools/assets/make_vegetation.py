"""Trees and shrubs for the scenery (see make_scenery.py). A deciduous tree is a tapering
trunk, a few branches and a crown of lumpy ellipsoid leaf clusters in two greens; the conifer
is a trunk under stacked cones with ragged edges; a shrub is a few leaf clusters on the
ground. Frame: origin at the trunk's foot, z up, metres. Deterministic (a fixed seed each)."""
import math
import random

from meshkit import Mesh, add, mul

MATERIALS = {
    "bark": {"kd": (0.3, 0.23, 0.17), "ks": (0.03, 0.03, 0.03), "ns": 6},
    "bark_birch": {"kd": (0.78, 0.76, 0.7), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "leaf_dark": {"kd": (0.13, 0.29, 0.08), "ks": (0.05, 0.06, 0.04), "ns": 10},
    "leaf_light": {"kd": (0.27, 0.45, 0.13), "ks": (0.05, 0.06, 0.04), "ns": 10},
    "needle_dark": {"kd": (0.06, 0.19, 0.09), "ks": (0.03, 0.04, 0.03), "ns": 8},
    "needle": {"kd": (0.1, 0.27, 0.12), "ks": (0.03, 0.04, 0.03), "ns": 8},
}

# Deciduous trees: crown centre height, crown radii, trunk (foot radius, fork height), the
# number of leaf clusters and of branches, bark, seed.
DECIDUOUS = {
    "tree_lime": dict(crown=(5.4, (2.7, 2.6, 2.7)), trunk=(0.2, 2.9), clusters=11, branches=4,
                      bark="bark", seed=11),
    "tree_birch": dict(crown=(6.2, (1.7, 1.6, 3.3)), trunk=(0.15, 2.6), clusters=10, branches=3,
                       bark="bark_birch", seed=12),
    "tree_plane": dict(crown=(5.0, (3.4, 3.2, 2.3)), trunk=(0.24, 2.4), clusters=12, branches=5,
                       bark="bark", seed=13),
}


def shell_points(n, rng):
    """n directions spread over the upper three quarters of a sphere (a golden spiral, jittered)."""
    out = []
    for k in range(n):
        z = 0.95 - 1.45 * (k + 0.5) / n
        r = math.sqrt(max(0.0, 1 - z * z))
        t = k * 2.39996 + rng.uniform(-0.3, 0.3)
        out.append((r * math.cos(t), r * math.sin(t), z))
    return out


def deciduous(name):
    t = DECIDUOUS[name]
    rng = random.Random(t["seed"])
    zc, (rx, ry, rz) = t["crown"]
    r0, fork = t["trunk"]
    m = Mesh()
    # trunk: a slightly leaning taper up into the crown
    m.begin("trunk", t["bark"]).smooth(70)
    lean = (rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1))
    top = (lean[0], lean[1], zc + 0.3 * rz)
    fork_p = (lean[0] * fork / top[2], lean[1] * fork / top[2], fork)
    m.tube((0, 0, 0), fork_p, r0 * 1.15, r0 * 0.8, n=8, cap_a=False, cap_b=False)
    m.tube(fork_p, top, r0 * 0.8, r0 * 0.3, n=7, cap_a=False)
    # branches from the fork out to the lower clusters
    dirs = shell_points(t["clusters"], rng)
    centres = [(top[0] + 0.62 * rx * d[0], top[1] + 0.62 * ry * d[1], zc + 0.6 * rz * d[2]) for d in dirs]
    low = sorted(range(len(centres)), key=lambda k: centres[k][2])[:t["branches"]]
    m.begin("branches", t["bark"]).smooth(70)
    for k in low:
        end = add(fork_p, mul(add(centres[k], mul(fork_p, -1)), 0.85))
        m.tube(fork_p, end, r0 * 0.42, r0 * 0.15, n=5, cap_a=False)
    # leaf clusters, alternately dark and light; a central one fills the crown
    m.begin("leaves").smooth(75)
    for k, c in enumerate(centres + [(top[0], top[1], zc)]):
        m.use("leaf_dark" if k % 3 != 1 else "leaf_light")
        s = 0.55 if k < len(centres) else 0.75
        m.lumpy_ellipsoid(c, (rx * s * rng.uniform(0.85, 1.1), ry * s * rng.uniform(0.85, 1.1),
                              rz * s * rng.uniform(0.75, 0.95)), rng, lumps=0.2, stacks=5, slices=9)
    return m, [((0, 0, fork / 2, 0), (2 * r0 + 0.1, 2 * r0 + 0.1, fork))]


def conifer():
    """A spruce: trunk, nine stacked cones with ragged skirts, darker towards the bottom."""
    rng = random.Random(21)
    m = Mesh()
    m.begin("trunk", "bark").smooth(70)
    m.tube((0, 0, 0), (0, 0, 2.0), 0.2, 0.15, n=8, cap_a=False)
    layers, z0, height, r_base = 9, 1.3, 11.0, 2.4
    for k in range(layers):
        f = k / (layers - 1)
        zb = z0 + (height - z0 - 1.6) * f ** 0.9
        r = r_base * (1 - 0.85 * f)
        apex_z = zb + 1.6 + 1.2 * (1 - f)
        n = 14 if k < 6 else 10
        m.begin("needles", "needle_dark" if k % 2 == 0 else "needle").smooth(50)
        ring = []
        for i in range(n):
            a = 2 * math.pi * (i + rng.uniform(-0.2, 0.2)) / n + k * 0.37
            rr = r * (1.08 if i % 2 == 0 else 0.88) * rng.uniform(0.94, 1.04)
            ring.append((rr * math.cos(a), rr * math.sin(a), zb - (0.18 if i % 2 == 0 else 0.0) * r / r_base * 2))
        apex = (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), apex_z)
        for i in range(n):
            m.tri(ring[i], ring[(i + 1) % n], apex)
        hub = (0, 0, zb + 0.35)  # the underside rises to the trunk
        for i in range(n):
            m.tri(ring[(i + 1) % n], ring[i], hub)
    return m, [((0, 0, 1.0, 0), (0.5, 0.5, 2.0))]


SHRUBS = {
    "shrub_round": dict(clusters=[((0, 0, 0.5), (0.75, 0.7, 0.6)), ((0.3, 0.25, 0.75), (0.45, 0.45, 0.4)),
                                  ((-0.3, -0.2, 0.7), (0.45, 0.45, 0.42))], seed=31),
    "shrub_hedge": dict(clusters=[((0, -0.6, 0.48), (0.6, 0.55, 0.55)), ((0.05, 0.05, 0.52), (0.62, 0.6, 0.58)),
                                  ((-0.05, 0.7, 0.46), (0.58, 0.55, 0.52)), ((0.1, 0.2, 0.85), (0.4, 0.5, 0.3))],
                        seed=32),
}


def shrub(name):
    t = SHRUBS[name]
    rng = random.Random(t["seed"])
    m = Mesh()
    m.begin("leaves").smooth(75)
    for k, (c, r) in enumerate(t["clusters"]):
        m.use("leaf_dark" if k % 2 == 0 else "leaf_light")
        cut = -0.55 if c[2] < 0.6 else None  # the lower clusters stand on the ground
        cz = c[2] if cut is None else r[2] * 0.55
        m.lumpy_ellipsoid((c[0], c[1], cz), r, rng, lumps=0.18, stacks=4, slices=9, zcut=cut)
    lo, hi = m.bounds()
    size = [hi[k] - lo[k] for k in range(3)]
    return m, [((0, 0, size[2] * 0.35, 0), (size[0] * 0.7, size[1] * 0.7, size[2] * 0.7))]


def build_all():
    """[(name, kind, mesh, collisions [((x, y, z, yaw), (sx, sy, sz))])]"""
    out = [(name, "tree") + deciduous(name) for name in DECIDUOUS]
    out.append(("tree_spruce", "tree") + conifer())
    out += [(name, "shrub") + shrub(name) for name in SHRUBS]
    return out

