"""People for the road-user actors (see make_road_users.py): pedestrians (four figures,
standing, in a walking mid-stride pose, and in the WALK_FRAMES poses of a walking cycle that
the world engine shows by the walker's walk_phase) and a cyclist on a bicycle.

A figure is a skeleton (joint positions in a standing rest pose, scaled to its height) and
one mesh part per bone: pelvis, torso, neck, head (+ hair), upper_arm_l/r, lower_arm_l/r,
hand_l/r, upper_leg_l/r, lower_leg_l/r, foot_l/r. Limbs are lofts of elliptical rings with
domed ends, so that they stay closed at bent joints. A pose moves each part rigidly: its
pivot joint to the posed joint, its bone turned onto the posed bone. Each part is an OBJ
group of that name; the rest-pose skeleton is written next to the standing meshes
(<figure>_stand_skeleton.json: joints, and each part's pivot and end joint) for a later
step that articulates them. Materials are slots (skin, hair, top, bottom, shoes; the
cyclist's frame) whose colours the SDF variants set. The poses are people_poses.py's, the
bicycle bicycle.py's.
Frame: x forward, y left, z up; the origin at the centre of the bounding box's base."""
import math

from bicycle import bicycle
from meshkit import Mesh, add, cross, dot, lerp, mat_vec, mul, norm, sub
from people_poses import WALK_FRAMES, pose_cycle, pose_cyclist, pose_stand, pose_walk, rotation_between

SLOTS = ["skin", "hair", "top", "bottom", "shoes"]

# Fixed materials (the bicycle's).
MATERIALS = {
    "tyre": {"kd": (0.04, 0.04, 0.04), "ks": (0.05, 0.05, 0.05), "ns": 6},
    "metal": {"kd": (0.62, 0.63, 0.65), "ks": (0.5, 0.5, 0.5), "ns": 60},
    "saddle": {"kd": (0.05, 0.05, 0.05), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "reflector": {"kd": (0.7, 0.05, 0.03), "ks": (0.4, 0.4, 0.4), "ns": 60, "ke": (0.2, 0.0, 0.0)},
}

SKIN = [(0.93, 0.76, 0.64), (0.8, 0.6, 0.45), (0.56, 0.38, 0.26), (0.36, 0.24, 0.17)]
HAIR = {"black": (0.04, 0.035, 0.03), "brown": (0.24, 0.14, 0.07), "blonde": (0.74, 0.58, 0.33),
        "grey": (0.58, 0.58, 0.58), "auburn": (0.42, 0.16, 0.07)}
CLOTH = {"red": (0.7, 0.08, 0.08), "navy": (0.08, 0.1, 0.28), "white": (0.88, 0.88, 0.86),
         "green": (0.12, 0.42, 0.2), "yellow": (0.9, 0.72, 0.12), "grey": (0.45, 0.45, 0.47),
         "black": (0.06, 0.06, 0.07), "lightblue": (0.45, 0.62, 0.85), "orange": (0.9, 0.42, 0.08),
         "jeans": (0.14, 0.2, 0.36), "khaki": (0.55, 0.48, 0.33), "brown": (0.3, 0.2, 0.12),
         "beige": (0.76, 0.68, 0.52), "purple": (0.38, 0.15, 0.45), "teal": (0.08, 0.45, 0.48)}
SHOES = {"black": (0.05, 0.05, 0.05), "white": (0.85, 0.85, 0.85), "brown": (0.28, 0.17, 0.09)}

# Figures: height (m), shoulder and hip half-widths, build (girth factor), chest (bust),
# hair style, sleeves (long or short), legwear (trousers, shorts or skirt), coat (top down
# over the hips).
FIGURES = {
    "man": dict(h=1.78, shoulder=0.195, hip=0.088, build=1.0, bust=0.0, hair="short",
                sleeves="long", legs="trousers", coat=False),
    "woman": dict(h=1.66, shoulder=0.172, hip=0.092, build=0.92, bust=0.025, hair="long",
                  sleeves="short", legs="trousers", coat=False),
    "tall_man": dict(h=1.88, shoulder=0.205, hip=0.09, build=1.05, bust=0.0, hair="short",
                     sleeves="short", legs="shorts", coat=False),
    "woman_coat": dict(h=1.62, shoulder=0.17, hip=0.092, build=0.95, bust=0.02, hair="bun",
                       sleeves="long", legs="skirt", coat=True),
}

# Colour variants per figure: (skin, hair, top, bottom, shoes).
VARIANTS = {
    "man": [(0, "brown", "navy", "jeans", "black"), (2, "black", "red", "khaki", "brown"),
            (1, "grey", "grey", "black", "black")],
    "woman": [(0, "blonde", "red", "jeans", "white"), (3, "black", "yellow", "black", "black"),
              (1, "auburn", "teal", "beige", "brown")],
    "tall_man": [(1, "black", "white", "khaki", "white"), (0, "blonde", "green", "navy", "black"),
                 (2, "black", "orange", "jeans", "white")],
    "woman_coat": [(0, "brown", "beige", "black", "black"), (2, "black", "purple", "grey", "black"),
                   (1, "grey", "lightblue", "navy", "brown")],
}

# Proportions as seen in the street: clothes make limbs and trunk fuller than the body's
# measures (girth factor), and a head a little larger reads as a head a few pixels tall.
CLOTHES = 1.14
HEAD = 1.06

DEFAULT_WALKER = "walker_man_1"
DEFAULT_PEDESTRIAN = "pedestrian_woman_1"
DEFAULT_CYCLIST = "cyclist_1"


# ---------------------------------------------------------------- skeleton
def skeleton(f):
    """Joint positions of the standing rest pose (feet on z = 0, facing +x)."""
    H = f["h"]
    s = H / 1.75
    sh, hh = f["shoulder"], f["hip"]
    j = {"hip_c": (0.0, 0.0, 0.52 * H), "waist": (0.0, 0.0, 0.6 * H),
         "neck_base": (0.0, 0.0, 0.822 * H), "head_base": (0.008, 0.0, 0.868 * H),
         "head_top": (0.0, 0.0, H)}
    for side, k in ((1, "l"), (-1, "r")):
        j["shoulder_" + k] = (-0.005, side * (sh - 0.008 * s), 0.8 * H)
        j["elbow_" + k] = (-0.015, side * (sh + 0.02 * s), 0.628 * H)
        j["wrist_" + k] = (0.005, side * (sh + 0.022 * s), 0.483 * H)
        j["fingertip_" + k] = (0.02, side * (sh + 0.02 * s), 0.375 * H)
        j["hip_" + k] = (0.0, side * hh, 0.515 * H)
        j["knee_" + k] = (0.012, side * hh * 0.95, 0.285 * H)
        j["ankle_" + k] = (-0.01, side * hh * 0.92, 0.047 * H)
        j["toe_" + k] = (0.155 * H * 0.92, side * (hh * 0.92 + 0.012), 0.02 * H)
    return j


# part: (pivot joint, end joint, slot of the rings... decided per figure)
BONES = {
    "pelvis": ("hip_c", "waist"), "torso": ("waist", "neck_base"), "neck": ("neck_base", "head_base"),
    "head": ("head_base", "head_top"), "hair": ("head_base", "head_top"),
}
for _k in ("l", "r"):
    BONES.update({"upper_arm_" + _k: ("shoulder_" + _k, "elbow_" + _k),
                  "lower_arm_" + _k: ("elbow_" + _k, "wrist_" + _k),
                  "hand_" + _k: ("wrist_" + _k, "fingertip_" + _k),
                  "upper_leg_" + _k: ("hip_" + _k, "knee_" + _k),
                  "lower_leg_" + _k: ("knee_" + _k, "ankle_" + _k),
                  "foot_" + _k: ("ankle_" + _k, "toe_" + _k)})


def limb(m, a, b, radii, slices=8, materials=None, dome=(0.5, 0.5), flatten=1.0, forward=(1, 0, 0)):
    """A limb from a to b: rings of radii [(t, rx, ry)] (rx along `forward`), domed ends.
    materials: [(t_max, material)] per span, by the span's mid t."""
    axis = sub(b, a)
    length = math.sqrt(dot(axis, axis))
    z = norm(axis)
    x = norm(sub(forward, mul(z, dot(forward, z))))
    y = cross(z, x)

    def ring(t, rx, ry, off=0.0):
        c = add(a, mul(z, t * length + off))
        return [add(c, add(mul(x, rx * math.cos(2 * math.pi * k / slices)),
                           mul(y, ry * flatten * math.sin(2 * math.pi * k / slices))))
                for k in range(slices)]

    t0, rx0, ry0 = radii[0]
    t1, rx1, ry1 = radii[-1]
    rings, ts = [], []
    if dome[0]:
        d = dome[0] * min(rx0, ry0)
        rings += [[add(a, mul(z, t0 * length - d))] * slices, ring(t0, 0.7 * rx0, 0.7 * ry0, -0.7 * d)]
        ts += [t0, t0]
    for t, rx, ry in radii:
        rings.append(ring(t, rx, ry))
        ts.append(t)
    if dome[1]:
        d = dome[1] * min(rx1, ry1)
        rings += [ring(t1, 0.7 * rx1, 0.7 * ry1, 0.7 * d), [add(a, mul(z, t1 * length + d))] * slices]
        ts += [t1, t1]

    def material_of(i, j):
        if not materials:
            return None
        tm = 0.5 * (ts[i] + ts[i + 1])
        for t_max, mat in materials:
            if tm <= t_max + 1e-9:
                return mat
        return materials[-1][1]

    m.loft(rings, material_of=material_of)


def build_figure(f):
    """The rest-pose figure: a Mesh whose parts are the bones (materials = slots)."""
    j = skeleton(f)
    H, g = f["h"], f["build"] * CLOTHES
    s = s0 = H / 1.75
    m = Mesh()
    top, bottom = "top", "bottom"
    # pelvis (hips to waist); a coat covers it
    m.begin("pelvis", top if f["coat"] else bottom).smooth(60)
    a, b = (0.0, 0.0, 0.455 * H), j["waist"]
    hip_r = 0.165 * g * s + 0.01 * (f["hip"] - 0.088) / 0.01
    limb(m, a, b, [(0.0, 0.085 * g * s, 0.1 * g * s), (0.3, 0.1 * g * s, hip_r),
                   (0.65, 0.1 * g * s, 0.155 * g * s), (1.0, 0.098 * g * s, 0.142 * g * s)],
         slices=12, dome=(0.4, 0))
    if f["coat"]:  # the coat's skirt, flared so that the legs stay inside when walking
        m.begin("pelvis", top).smooth(50)
        limb(m, j["waist"], (0.0, 0.0, 0.34 * H),
             [(0.0, 0.1 * g * s, 0.146 * g * s), (0.35, 0.135 * g * s, 0.19 * g * s),
              (1.0, 0.22 * g * s, 0.225 * g * s)], slices=12, dome=(0, 0))
    # torso (waist to the base of the neck), closed over the shoulders
    m.begin("torso", top).smooth(60)
    bust = f["bust"]
    limb(m, j["waist"], j["neck_base"],
         [(0.0, 0.098 * g * s, 0.142 * g * s), (0.25, 0.102 * g * s, 0.148 * g * s),
          (0.52, (0.118 + bust) * g * s, 0.162 * g * s), (0.78, 0.112 * g * s, f["shoulder"] * 0.92),
          (0.93, 0.095 * g * s, f["shoulder"] * 0.9), (1.0, 0.06 * s, f["shoulder"] * 0.55)],
         slices=12, dome=(0, 0.3))
    # neck, head
    m.begin("neck", "skin").smooth(60)
    limb(m, j["neck_base"], j["head_base"], [(-0.3, 0.052 * s, 0.052 * s), (1.2, 0.048 * s, 0.048 * s)],
         slices=8, dome=(0, 0))
    m.begin("head", "skin").smooth(70)
    s = s0 * HEAD  # the head a little larger than life, its top where it was
    hc = (0.012 * s, 0.0, 0.935 * H + 0.118 * (s0 - s))
    m.ellipsoid(hc, (0.098 * s, 0.077 * s, 0.118 * s), stacks=7, slices=10)
    # a nose, so that the face has a front
    m.begin("head", "skin").flat()
    nz = hc[2] - 0.01 * s
    tip = (hc[0] + 0.108 * s, 0, nz - 0.012 * s)
    p1, p2, p3 = (hc[0] + 0.088 * s, 0.014 * s, nz - 0.03 * s), (hc[0] + 0.088 * s, -0.014 * s, nz - 0.03 * s), (hc[0] + 0.09 * s, 0, nz + 0.025 * s)
    m.tri(tip, p3, p1)
    m.tri(tip, p2, p3)
    m.tri(tip, p1, p2)
    brows(m, hc, s)
    # hair (or a helmet)
    m.begin("hair", "hair").smooth(60)
    hs = f["hair"]
    if hs == "helmet":
        m.ellipsoid((hc[0] - 0.02 * s, 0.0, hc[2] + 0.03 * s), (0.125 * s, 0.098 * s, 0.118 * s),
                    stacks=4, slices=10, zcut=0.05)
    else:
        m.ellipsoid((hc[0] - 0.016 * s, 0.0, hc[2] + 0.014 * s), (0.102 * s, 0.083 * s, 0.118 * s),
                    stacks=5, slices=10, zcut=-0.05)
    if hs == "long":
        m.ellipsoid((hc[0] - 0.055 * s, 0.0, hc[2] - 0.085 * s), (0.06 * s, 0.088 * s, 0.13 * s), stacks=4, slices=8)
    elif hs == "bun":
        m.ellipsoid((hc[0] - 0.1 * s, 0.0, hc[2] + 0.03 * s), (0.045 * s, 0.045 * s, 0.045 * s), stacks=4, slices=8)
    s = s0
    # arms
    for k in ("l", "r"):
        lower_arm = top if f["sleeves"] == "long" else "skin"
        m.begin("upper_arm_" + k, top).smooth(60)
        mats = [(1.0, top)] if f["sleeves"] == "long" else [(0.55, top), (1.0, "skin")]
        limb(m, j["shoulder_" + k], j["elbow_" + k],
             [(0.0, 0.052 * g * s, 0.05 * g * s), (0.5, 0.046 * g * s, 0.044 * g * s), (1.0, 0.039 * g * s, 0.038 * g * s)],
             materials=mats, dome=(0.35, 0.5))
        m.begin("lower_arm_" + k, lower_arm).smooth(60)
        limb(m, j["elbow_" + k], j["wrist_" + k],
             [(0.0, 0.039 * g * s, 0.038 * g * s), (0.35, 0.038 * g * s, 0.036 * g * s), (1.0, 0.027 * s, 0.024 * s)],
             dome=(0.5, 0.3))
        m.begin("hand_" + k, "skin").smooth(60)
        w, t = j["wrist_" + k], j["fingertip_" + k]
        c = lerp(w, t, 0.45)
        m.ellipsoid(c, (0.045 * s, 0.022 * s, 0.058 * s), stacks=4, slices=6)
    # legs
    for k in ("l", "r"):
        legs = f["legs"]
        m.begin("upper_leg_" + k, bottom).smooth(60)
        if legs == "skirt":  # a skirt over bare legs, or a coat over trousers
            mats = [(1.0, bottom)] if f["coat"] else [(0.45, bottom), (1.0, "skin")]
        elif legs == "shorts":
            mats = [(0.6, bottom), (1.0, "skin")]
        else:
            mats = [(1.0, bottom)]
        coat_r = 1.0
        limb(m, j["hip_" + k], j["knee_" + k],
             [(-0.05, 0.085 * g * s * coat_r, 0.08 * g * s * coat_r), (0.4, 0.075 * g * s * coat_r, 0.07 * g * s * coat_r),
              (1.0, 0.052 * g * s, 0.05 * g * s)], materials=mats, dome=(0.4, 0.5))
        m.begin("lower_leg_" + k, bottom if legs == "trousers" or f["coat"] else "skin").smooth(60)
        limb(m, j["knee_" + k], j["ankle_" + k],
             [(0.0, 0.052 * g * s, 0.05 * g * s), (0.3, 0.056 * g * s, 0.048 * g * s), (1.0, 0.036 * s, 0.034 * s)],
             dome=(0.5, 0.4))
        m.begin("foot_" + k, "shoes").smooth(50)
        foot(m, j["ankle_" + k], j["toe_" + k], s)
    return m, j


def brows(m, hc, s):
    """Eyebrows in the hair's colour and the eyes' shadow under them: thin dark wedges on the
    face's front, so that a face reads as a face from a few metres."""
    m.begin("hair", "hair").flat()
    rx, ry, rz = 0.098 * s, 0.077 * s, 0.118 * s
    for side in (1, -1):
        for y0, y1, z0, z1 in ((0.012, 0.05, 0.036, 0.046), (0.018, 0.044, 0.012, 0.022)):
            pts = []
            for y, z in ((y0, z0), (y1, z0), (y1, z1), (y0, z1)):
                u = 1 - (y / ry) ** 2 - (z / rz) ** 2
                pts.append((hc[0] + rx * math.sqrt(max(u, 0.0)) + 0.002 * s, side * y, hc[2] + z))
            if cross(sub(pts[1], pts[0]), sub(pts[2], pts[0]))[0] < 0:  # facing forward
                pts = pts[::-1]
            m.quad(*pts)


def foot(m, ankle, toe, s):
    """A shoe: a loft along the foot from heel to toe, the ankle on top of the heel."""
    d = norm((toe[0] - ankle[0], toe[1] - ankle[1], 0.0))
    side = (-d[1], d[0], 0.0)
    heel = add(ankle, mul(d, -0.05 * s))
    length = 0.26 * s
    rings = []
    for t, hgt, w in ((0.0, 0.075, 0.036), (0.02, 0.09, 0.045), (0.35, 0.085, 0.05), (0.7, 0.05, 0.052),
                      (0.95, 0.035, 0.04), (1.0, 0.02, 0.02)):
        c = add((heel[0], heel[1], 0.0), mul(d, t * length))
        h, ww = hgt * s, w * s
        # section: bottom-left, bottom-right, top-right, top-left... counter-clockwise about d
        pts = [(-ww, 0.0), (ww, 0.0), (ww * 0.95, h * 0.8), (ww * 0.5, h), (-ww * 0.5, h), (-ww * 0.95, h * 0.8)]
        ring = [add(c, add(mul(side, u), (0, 0, v))) for u, v in pts]
        rings.append(ring)
    m.loft(rings, cap_start=True, cap_end=True)


# ---------------------------------------------------------------- posing


def apply_pose(m, rest, posed):
    """Moves each part rigidly: its pivot onto the posed pivot, its bone onto the posed bone."""
    for i, (part, mat, st, tri) in enumerate(m.tris):
        base = part.split(":")[0]
        if base not in BONES:
            continue
        p, e = BONES[base]
        r = rotation_between(sub(rest[e], rest[p]), sub(posed[e], posed[p]))
        m.tris[i] = (part, mat, st, tuple(add(posed[p], mat_vec(r, sub(v, rest[p]))) for v in tri))


def walk_cycle(f):
    """The walking cycle's meshes: [(phase, Mesh)] for phase k / WALK_FRAMES, each in the frame
    of the figure's mid-stride walker (the pelvis where the walker has it), its lowest point
    on the ground, so that the figure bobs as it walks but does not slide."""
    m, rest = build_figure(f)
    apply_pose(m, rest, pose_walk(rest, f))
    lo, hi = m.bounds()
    centre = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2)
    frames = []
    for k in range(WALK_FRAMES):
        m, rest = build_figure(f)
        apply_pose(m, rest, pose_cycle(rest, f, k / WALK_FRAMES))
        lo, _ = m.bounds()
        m.transform(0, move=(-centre[0], -centre[1], -lo[2]))
        frames.append((k / WALK_FRAMES, m))
    return frames


# ---------------------------------------------------------------- all people
def slot_colours(variant):
    skin, hair, top, bottom, shoes = variant
    return {"skin": SKIN[skin], "hair": HAIR[hair], "top": CLOTH[top], "bottom": CLOTH[bottom],
            "shoes": SHOES[shoes]}


def build_all():
    """Yields (model name, Mesh, meta) for every person model; the first model of a mesh
    writes it (meta["write"])."""
    for fig, f in FIGURES.items():
        cycle = [("%s_walk%d" % (fig, k), phase, mesh) for k, (phase, mesh) in enumerate(walk_cycle(f))]
        for pose_name, pose, prefix in (("stand", pose_stand, "pedestrian"), ("walk", pose_walk, "walker")):
            m, rest = build_figure(f)
            posed = pose(rest, f)
            apply_pose(m, rest, posed)
            lo, hi = m.bounds()
            shift = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2])
            m.fit()
            mesh = "%s_%s" % (fig, pose_name)
            skel = None
            if pose_name == "stand":
                skel = {"joints": {k: [round(v[i] - shift[i], 4) for i in range(3)] for k, v in posed.items()},
                        "parts": {p: {"pivot": a, "end": b} for p, (a, b) in BONES.items()}}
            for k, variant in enumerate(VARIANTS[fig]):
                cols = slot_colours(variant)
                yield ("%s_%s_%d" % (prefix, fig, k + 1), m, {
                    "cls": "pedestrian", "mesh": mesh, "write": k == 0, "mesh_slots": SLOTS,
                    "colours": cols, "parts": sorted({t[0] for t in m.tris}), "fixed": False,
                    "length_offset": 0, "skeleton": skel if k == 0 else None,
                    "cycle": cycle if pose_name == "walk" else None,
                    "stand": "pedestrian_%s_%d" % (fig, k + 1),
                    "comment": "A pedestrian actor: %s, %s, %.2f m tall" % (fig.replace("_", " "),
                                                                           "walking (mid-stride)" if pose_name == "walk" else "standing", f["h"])})
    # the cyclist
    f = dict(FIGURES["man"], h=1.76, sleeves="long", legs="trousers", hair="helmet")
    m, rest = build_figure(f)
    bike = bicycle(m)
    posed = pose_cyclist(rest, f, bike)
    apply_pose(m, rest, posed)
    lo, hi = m.bounds()
    rear_x = bike["rear_axle"][0] - (lo[0] + hi[0]) / 2
    m.fit()
    cyclist_variants = [((1, "red", "navy", "jeans", "black"), "blue"), ((0, "white", "yellow", "black", "white"), "black"),
                        ((2, "black", "red", "grey", "black"), "silver"), ((3, "blue", "green", "jeans", "brown"), "red")]
    frame_colours = {"blue": (0.1, 0.25, 0.6), "black": (0.06, 0.06, 0.07), "silver": (0.62, 0.63, 0.65), "red": (0.65, 0.06, 0.05)}
    helmet = {"red": (0.75, 0.08, 0.06), "white": (0.9, 0.9, 0.9), "black": (0.06, 0.06, 0.06), "blue": (0.1, 0.3, 0.75)}
    for k, ((skin, hel, top, bottom, shoes), frame) in enumerate(cyclist_variants):
        cols = {"skin": SKIN[skin], "hair": helmet[hel], "top": CLOTH[top], "bottom": CLOTH[bottom],
                "shoes": SHOES[shoes], "frame": frame_colours[frame]}
        yield ("cyclist_%d" % (k + 1), m, {
            "cls": "cyclist", "mesh": "cyclist", "write": k == 0, "mesh_slots": SLOTS + ["frame"],
            "colours": cols, "parts": sorted({t[0] for t in m.tris}), "fixed": True,
            "length_offset": round(-rear_x, 3), "skeleton": None, "cycle": None,
            "comment": "A cyclist actor: a rider in a helmet on a city bicycle"})
