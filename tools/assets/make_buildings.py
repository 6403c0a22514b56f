"""Buildings for the scenery (see make_scenery.py): urban apartment blocks of 3 to 6 storeys, a
corner shop, a terraced house, a detached house and an office block. The façade towards the
road (+x) has recessed windows with frames, mullions and sills, the entrance door and the shop
windows; the other walls have flat windows; cornices, plinths, flat or pitched roofs and
chimneys finish them (buildkit.py). Each building is two meshes: <type>_walls.obj (the wall
surfaces, coloured per variant by the catalog: plaster, brick, beige, grey) and <type>.obj
(everything else). Frame: origin at the centre of the footprint on the ground, z up, metres;
D is the depth along x, W the width along y."""
import math

from buildkit import chimney, columns, faces, flat_roof, pitched_roof, rot_mesh
from meshkit import Mesh

MATERIALS = {
    "walls": {"kd": (0.86, 0.84, 0.78), "ks": (0.04, 0.04, 0.04), "ns": 6},
    "trim": {"kd": (0.9, 0.89, 0.86), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "plinth": {"kd": (0.34, 0.34, 0.35), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "glass": {"kd": (0.08, 0.1, 0.13), "ks": (0.6, 0.6, 0.6), "ns": 90},
    "frame": {"kd": (0.9, 0.9, 0.88), "ks": (0.15, 0.15, 0.15), "ns": 20},
    "frame_dark": {"kd": (0.18, 0.19, 0.2), "ks": (0.25, 0.25, 0.25), "ns": 30},
    "door": {"kd": (0.33, 0.19, 0.1), "ks": (0.1, 0.1, 0.1), "ns": 12},
    "roof_flat": {"kd": (0.28, 0.28, 0.29), "ks": (0.03, 0.03, 0.03), "ns": 6},
    "roof_tiles": {"kd": (0.47, 0.19, 0.12), "ks": (0.06, 0.06, 0.06), "ns": 8},
    "roof_slate": {"kd": (0.2, 0.21, 0.24), "ks": (0.12, 0.12, 0.12), "ns": 16},
    "chimney": {"kd": (0.5, 0.24, 0.17), "ks": (0.04, 0.04, 0.04), "ns": 6},
    "slab": {"kd": (0.7, 0.7, 0.68), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "railing": {"kd": (0.78, 0.78, 0.76), "ks": (0.15, 0.15, 0.15), "ns": 20},
    "awning": {"kd": (0.6, 0.1, 0.08), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "fascia": {"kd": (0.07, 0.25, 0.16), "ks": (0.1, 0.1, 0.1), "ns": 12},
    "sign_shop": {"kd": (0.85, 0.85, 0.85), "ks": (0.1, 0.1, 0.1), "ns": 12, "map": "shop_sign.png"},
    "plant": {"kd": (0.55, 0.56, 0.57), "ks": (0.2, 0.2, 0.2), "ns": 20},
}

# Façade colours of the variants (the wall mesh's diffuse colour).
COLOURS = {"plaster": (0.86, 0.84, 0.78), "brick": (0.55, 0.24, 0.17), "beige": (0.83, 0.72, 0.54),
           "grey": (0.56, 0.57, 0.58), "white": (0.9, 0.9, 0.88)}


def floor_rows(face, wins, bases, win_h=1.45, sill=0.9):
    """The rows of windows of the upper floors (their floor heights `bases`)."""
    return [(b + sill, b + sill + win_h, [(s0, s1, b + sill, b + sill + win_h) for s0, s1 in wins]) for b in bases]


def flat_grid(face, cols, bases, win=1.2, win_h=1.4, sill=0.9, mullion=False):
    for b in bases:
        for s0, s1 in columns(face.w, cols, win):
            face.flat_window(s0, b + sill, s1, b + sill + win_h, mullion=mullion)


def front_plinth(face, gaps, height=0.45, material="plinth"):
    """A plinth along a face, broken where doors reach the ground (gaps: s ranges)."""
    s = -0.03
    for g0, g1 in sorted(gaps) + [(face.w + 0.03, face.w + 0.03)]:
        if g0 > s:
            face.block(s, 0, 0, g0, height, 0.03, material)
        s = g1


def apartment(storeys, D, W, cols, roof="flat", balconies=(), bands=False, back_mullions=True,
              mullions=True):
    """An apartment block: a 3.3 m ground floor, 3.0 m floors, the entrance in the middle."""
    m = Mesh()
    g, st = 3.3, 3.0
    H = g + st * (storeys - 1)
    f = faces(m, D, W, H)
    front = f["front"]
    wins = columns(W, cols, 1.3)
    dc = cols // 2
    ds = ((wins[dc][0] + wins[dc][1]) / 2 - 0.65, (wins[dc][0] + wins[dc][1]) / 2 + 0.65)
    ground = [(s0, s1, 1.0, 2.5) for k, (s0, s1) in enumerate(wins) if k != dc] + [(ds[0], ds[1], 0.0, 2.6)]
    bases = [g + st * k for k in range(storeys - 1)]
    uppers = []
    for b in bases:  # a balcony's door reaches its floor
        uppers.append((b + 0.05, b + 2.35, [(s0, s1, b + (0.05 if k in balconies else 0.9), b + 2.35)
                                            for k, (s0, s1) in enumerate(wins)]))
    front.wall([(0.0, 2.6, ground)] + uppers)
    for s0, s1, ta, tb in ground:
        if ta == 0.0:
            front.door(s0, s1, tb)
        else:
            front.window(s0, ta, s1, tb, mullion=mullions)
    for b, (_, _, holes) in zip(bases, uppers):
        for k, (s0, s1, ta, tb) in enumerate(holes):
            front.window(s0, ta, s1, tb, sill=None if k in balconies else "trim", mullion=mullions)
            if k in balconies:
                front.block(s0 - 0.5, b - 0.1, 0, s1 + 0.5, b + 0.05, 1.3, "slab", back=False)
                front.block(s0 - 0.5, b + 0.05, 1.25, s1 + 0.5, b + 1.05, 1.3, "railing", back=True)
                for e in (s0 - 0.5, s1 + 0.45):
                    front.block(e, b + 0.05, 0, e + 0.05, b + 1.05, 1.25, "railing")
    if bands:
        for b in bases:
            front.block(-0.02, b - 0.12, 0, W + 0.02, b, 0.06, "trim")
    front_plinth(front, [ds])
    f["back"].wall([])
    flat_grid(f["back"], cols, [0.0] + bases, mullion=back_mullions)
    for side in ("left", "right"):
        f[side].wall([])
        flat_grid(f[side], max(1, int(D / 4.5)), [0.0] + bases)
        front_plinth(f[side], [])
    front_plinth(f["back"], [])
    if roof == "flat":
        flat_roof(m, D, W, H)
    else:
        ridge = H + D / 2 * math.tan(math.radians(33))
        pitched_roof(m, D, W, H, ridge, roof="roof_slate")
        for side in ("left", "right"):
            f[side].gable(H, ridge)
        chimney(m, -D * 0.2, W * 0.25, ridge - 1.5, ridge + 0.9)
    return m


def corner_shop():
    """A three-storey corner house: shop windows, door and a fascia ('SHOP') on the ground
    floor's front and left side, an awning over the front, flats above, a flat roof."""
    m = Mesh()
    D, W, g, st = 10.0, 12.0, 4.0, 3.0
    H = g + 2 * st
    f = faces(m, D, W, H)
    front, left = f["front"], f["left"]
    bases = [g, g + st]
    fw = columns(W, 4, 1.3)
    shop = [(0.6, 5.4, 0.5, 3.2), (8.2, 11.4, 0.5, 3.2), (6.2, 7.6, 0.0, 3.2)]  # windows, door
    front.wall([(0.0, 3.2, shop)] + floor_rows(front, fw, bases))
    front.band(0.6, 0.5, 5.4, 3.2, 1.6)
    front.band(8.2, 0.5, 11.4, 3.2, 1.6)
    front.door(6.2, 7.6, 3.2, leaf="frame_dark", frame="frame_dark", canopy=None, depth=0.12)
    for _, _, holes in floor_rows(front, fw, bases):
        for s0, s1, ta, tb in holes:
            front.window(s0, ta, s1, tb)
    lw = columns(D, 3, 1.3)
    left.wall([(0.5, 3.2, [(0.6, 6.2, 0.5, 3.2)])] + floor_rows(left, lw, bases))
    left.band(0.6, 0.5, 6.2, 3.2, 1.4)
    for _, _, holes in floor_rows(left, lw, bases):
        for s0, s1, ta, tb in holes:
            left.window(s0, ta, s1, tb)
    for face, w in ((front, W), (left, D)):  # the fascia, its sign centred on the front
        face.block(-0.05, 3.3, 0, w + 0.05, 3.95, 0.14, "fascia")
    front.rect_uv(W / 2 - 2.4 - 0.6, 3.37, W / 2 + 2.4 - 0.6, 3.88, 0.145, "sign_shop")
    m.begin("awning", "awning").flat()
    for s0, s1 in ((0.4, 5.6), (8.0, 11.6)):  # a sloping cloth with a valance, seen from above and below
        for dt, want in ((0.0, "up"), (-0.03, "down")):
            front.facing([(s0, 3.25 + dt, 0.0), (s1, 3.25 + dt, 0.0), (s1, 2.75 + dt, 1.3), (s0, 2.75 + dt, 1.3)],
                         want, "awning")
        front.facing([(s0, 2.5, 1.3), (s1, 2.5, 1.3), (s1, 2.75, 1.3), (s0, 2.75, 1.3)], "out", "awning")
        front.facing([(s0, 2.5, 1.29), (s1, 2.5, 1.29), (s1, 2.72, 1.29), (s0, 2.72, 1.29)], "in", "awning")
    front_plinth(front, [(6.2, 7.6)], height=0.5)
    front_plinth(left, [], height=0.5)
    for side in ("back", "right"):
        f[side].wall([])
        flat_grid(f[side], 3, bases)
        front_plinth(f[side], [], height=0.5)
    flat_roof(m, D, W, H, over=0.2, depth=0.45)
    return m


def terraced_house():
    """A two-storey terraced house, 6 m wide: door and bay window, gables to the neighbours."""
    m = Mesh()
    D, W, g, st = 9.0, 6.0, 2.9, 2.8
    H = g + st
    f = faces(m, D, W, H)
    front = f["front"]
    ground = [(0.7, 1.8, 0.0, 2.3), (2.8, 5.2, 0.9, 2.3)]
    up = [(0.7, 2.1, 3.6, 5.0), (3.4, 4.8, 3.6, 5.0)]
    front.wall([(0.0, 2.3, ground), (3.6, 5.0, up)])
    front.door(0.7, 1.8, 2.3, leaf="door")
    front.window(2.8, 0.9, 5.2, 2.3)
    for s0, s1, ta, tb in up:
        front.window(s0, ta, s1, tb)
    front.block(-0.02, g - 0.1, 0, W + 0.02, g + 0.05, 0.05, "trim")
    front_plinth(front, [(0.7, 1.8)])
    f["back"].wall([])
    flat_grid(f["back"], 2, [0.0, g], mullion=True)
    front_plinth(f["back"], [])
    ridge = H + D / 2 * math.tan(math.radians(40))
    for side in ("left", "right"):
        f[side].wall([])
        f[side].gable(H, ridge)
        front_plinth(f[side], [])
    pitched_roof(m, D, W, H, ridge, over=0.3)
    chimney(m, -1.0, W / 2 - 0.6, ridge - 1.3, ridge + 0.8)
    # a dormer over the front
    m.begin("dormer", "roof_tiles").flat()
    slope = (ridge - H) / (D / 2)
    z0 = H + 1.2 * slope
    xf = D / 2 - 1.2
    m.block((xf - 1.6, -1.0, z0), (xf, 1.0, z0 + 1.5), skip=("-z", "+x"))
    dorm = faces(m, 0, 0, 0)["front"]
    dorm.o, dorm.w, dorm.h = (xf, -1.0, z0), 2.0, 1.5
    dorm.rect(0, 0, 2.0, 1.5, 0, "trim")
    dorm.rect(0.2, 0.15, 1.8, 1.35, 0.01, "frame")
    dorm.rect(0.28, 0.23, 1.72, 1.27, 0.02, "glass")
    return m


def detached_house():
    """A detached two-storey house, its gable (with a window in it) towards the road; built
    with the gable on +y and turned."""
    m = Mesh()
    D, W, g, st = 10.0, 9.0, 2.9, 2.8  # D: along the gable (the road), W: depth
    H = g + st
    f = faces(m, D, W, H)
    front = f["left"]
    ground = [(1.2, 3.0, 0.9, 2.3), (4.4, 5.5, 0.0, 2.3), (6.9, 8.7, 0.9, 2.3)]
    up = [(1.5, 3.0, 3.7, 5.0), (4.3, 5.7, 3.7, 5.0), (7.0, 8.5, 3.7, 5.0)]
    front.wall([(0.0, 2.3, ground), (3.7, 5.0, up)])
    for s0, s1, ta, tb in ground + up:
        if ta == 0.0:
            front.door(s0, s1, tb)
        else:
            front.window(s0, ta, s1, tb)
    ridge = H + D / 2 * math.tan(math.radians(38))
    front.gable(H, ridge)
    front.flat_window(D / 2 - 0.6, H + 0.9, D / 2 + 0.6, H + 2.0, mullion=True)
    front_plinth(front, [(4.4, 5.5)])
    back = f["right"]
    back.wall([])
    back.gable(H, ridge)
    flat_grid(back, 3, [0.0, g], mullion=True)
    front_plinth(back, [])
    for side in ("front", "back"):  # the long sides under the eaves
        f[side].wall([])
        flat_grid(f[side], 2, [0.0, g])
        front_plinth(f[side], [])
    pitched_roof(m, D, W, H, ridge, roof="roof_tiles", over=0.45)
    chimney(m, -1.6, -W * 0.2, ridge - 1.2, ridge + 0.7)
    rot_mesh(m, -math.pi / 2)
    return m


def office_block():
    """A five-storey office block: window bands with mullions on every side, a glazed lobby
    under a canopy, a metal coping and a plant room on the roof."""
    m = Mesh()
    D, W, g, st = 14.0, 22.0, 4.2, 3.6
    H = g + 4 * st
    f = faces(m, D, W, H)
    front = f["front"]
    bases = [g + st * k for k in range(4)]
    lobby = (W / 2 - 3.5, W / 2 + 3.5)
    ground = [(0.6, lobby[0] - 1.0, 0.8, 3.4), (lobby[0], lobby[1], 0.0, 3.6), (lobby[1] + 1.0, W - 0.6, 0.8, 3.4)]
    rows = [(0.0, 3.6, ground)] + [(b + 0.9, b + 3.0, [(0.5, W - 0.5, b + 0.9, b + 3.0)]) for b in bases]
    front.wall(rows)
    for s0, s1, ta, tb in ground:
        front.band(s0, ta, s1, tb, 1.5, depth=0.25 if ta == 0.0 else 0.1)
    front.rect(W / 2 - 0.9, 0.0, W / 2 + 0.9, 2.4, -0.2, "frame_dark")  # the doors
    front.rect(W / 2 - 0.8, 0.0, W / 2 + 0.8, 2.3, -0.19, "glass")
    for b in bases:
        front.band(0.5, b + 0.9, W - 0.5, b + 3.0, 1.5)
    front.block(lobby[0] - 0.5, 3.75, 0, lobby[1] + 0.5, 3.95, 2.2, "frame_dark")
    for side, n in (("back", W), ("left", D), ("right", D)):
        face = f[side]
        face.wall([])
        for b in [0.0] + bases:
            face.rect(0.5, b + 0.9, n - 0.5, b + 3.0, 0.012, "frame_dark")
            face.rect(0.56, b + 0.96, n - 0.56, b + 2.94, 0.02, "glass")
            for k in range(1, int(round((n - 1) / 3.0))):
                s = 0.5 + (n - 1) * k / int(round((n - 1) / 3.0))
                face.rect(s - 0.04, b + 0.96, s + 0.04, b + 2.94, 0.028, "frame_dark")
    flat_roof(m, D, W, H, cornice="frame_dark", over=0.08, depth=0.25, lift=0.9)
    m.begin("plant", "plant").flat()
    m.block((-3.5, -5.0, H + 0.9), (2.5, 1.0, H + 3.0), skip=("-z",))
    return m


# name: (builder, colour variants, the first the MTL's)
BUILDINGS = {
    "apartment_3": (lambda: apartment(3, 11.0, 16.0, 5, roof="pitched"), ["plaster", "brick", "beige", "grey"]),
    "apartment_4": (lambda: apartment(4, 12.0, 18.0, 6, balconies=(1, 4)), ["beige", "plaster", "grey", "brick"]),
    "apartment_5": (lambda: apartment(5, 12.0, 20.0, 6, bands=True), ["brick", "plaster", "beige", "grey"]),
    "apartment_6": (lambda: apartment(6, 13.0, 21.0, 6, balconies=(1, 4), back_mullions=False,
                                              mullions=False), ["grey", "plaster", "beige"]),
    "corner_shop": (corner_shop, ["plaster", "brick", "beige"]),
    "terraced_house": (terraced_house, ["brick", "plaster", "beige"]),
    "detached_house": (detached_house, ["plaster", "beige", "grey", "brick"]),
    "office_block": (office_block, ["grey", "beige", "white"]),
}


def shop_sign_png(path):
    import texkit
    rows = texkit.paint(256, [((240, 236, 220), texkit.text("SHOP", 0, 0, 0.16, stroke=0.17))],
                        background=(18, 64, 41), height=32)
    texkit.write_png(path, rows)


def build_all():
    """[(name, mesh, colour variants)]"""
    return [(name, builder(), colours) for name, (builder, colours) in BUILDINGS.items()]

