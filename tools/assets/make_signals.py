"""Road signs and traffic lights for the scenery (see make_scenery.py), each on its own pole.

Signs (Vienna-convention shapes, German sizes): stop (red octagon, "STOP"), yield (inverted
triangle, red border), no entry (red disc, white bar), speed limits 5..130 km/h (white disc,
red ring, black number), a general warning triangle ("!") and priority road (yellow diamond). A sign is two meshes: its body
(pole, back and rim, shared by the signs of one shape) and its face, a polygon textured with a
small PNG painted here (texkit.py). The face looks along +x, the sign's bottom edge 2.0 m up.

Traffic lights: a pole with a housing of three lamps (red, yellow, green) behind visors on a
black contrast board; a pedestrian light with two lamps (a standing red and a walking green
figure). Each lamp is a mesh of its own in the model's frame (<model>_lamp_<colour>.obj), so
that the world engine can light it; its material is the unlit lens. Lamps look along +x."""
import math

import texkit
from meshkit import Mesh

RED, WHITE, BLACK = (196, 18, 28), (240, 240, 236), (18, 18, 18)
YELLOW = (245, 196, 20)
FACE = {"kd": (0.85, 0.85, 0.85), "ks": (0.15, 0.15, 0.15), "ns": 20}
MATERIALS = {
    "pole": {"kd": (0.58, 0.59, 0.6), "ks": (0.3, 0.3, 0.3), "ns": 30},
    "sign_back": {"kd": (0.5, 0.51, 0.52), "ks": (0.2, 0.2, 0.2), "ns": 20},
    "pole_dark": {"kd": (0.16, 0.17, 0.18), "ks": (0.2, 0.2, 0.2), "ns": 24},
    "housing": {"kd": (0.05, 0.05, 0.055), "ks": (0.15, 0.15, 0.15), "ns": 20},
    "board": {"kd": (0.025, 0.025, 0.025), "ks": (0.05, 0.05, 0.05), "ns": 8},
    "board_edge": {"kd": (0.85, 0.85, 0.85), "ks": (0.1, 0.1, 0.1), "ns": 10},
    "button": {"kd": (0.85, 0.68, 0.08), "ks": (0.2, 0.2, 0.2), "ns": 20},
    "lamp_red": {"kd": (0.3, 0.04, 0.03), "ks": (0.7, 0.7, 0.7), "ns": 90},
    "lamp_yellow": {"kd": (0.32, 0.22, 0.03), "ks": (0.7, 0.7, 0.7), "ns": 90},
    "lamp_green": {"kd": (0.03, 0.24, 0.14), "ks": (0.7, 0.7, 0.7), "ns": 90},
}
SPEEDS = [5, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120, 130]
TEXTURE = 128  # px, square
BOTTOM = 2.0  # m, the sign's lower edge above the ground
POLE_X, POLE_R = -0.05, 0.032  # the pole behind the sign


# ---------------------------------------------------------------- faces (shape, texture)
SHAPES = {  # unit outline (texture coordinates -1..1, counter-clockwise) and half-size in m
    "disc": (texkit.regular(32, 1.0, 0.0), 0.375),
    "octagon": (texkit.regular(8, 1.0 / math.cos(math.pi / 8), math.pi / 8), 0.375),
    "triangle_down": ([(0.0, -0.866), (1.0, 0.866), (-1.0, 0.866)], 0.45),
    "triangle_up": ([(-1.0, -0.866), (1.0, -0.866), (0.0, 0.866)], 0.45),
    "diamond": ([(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)], 0.42),
}


def face_layers(kind, value=None):
    """(background, layers) of a sign's face picture."""
    if kind == "stop":
        octagon = SHAPES["octagon"][0]
        return RED, [(WHITE, texkit.polygon(texkit.inset(octagon, 0.05))),
                     (RED, texkit.polygon(texkit.inset(octagon, 0.1))),
                     (WHITE, texkit.text("STOP", 0, 0, 0.5, stroke=0.19, squeeze=0.8))]
    if kind == "yield":
        tri = SHAPES["triangle_down"][0]
        return RED, [(WHITE, texkit.polygon(texkit.inset(tri, 0.22)))]
    if kind == "warning":
        tri = SHAPES["triangle_up"][0]
        return RED, [(WHITE, texkit.polygon(texkit.inset(tri, 0.22))),
                     (BLACK, texkit.text("!", 0, -0.12, 0.62, stroke=0.17))]
    if kind == "priority":  # priority road: a yellow square on its corner, white and black edges
        diamond = SHAPES["diamond"][0]
        return WHITE, [(BLACK, texkit.polygon(texkit.inset(diamond, 0.2))),
                       (YELLOW, texkit.polygon(texkit.inset(diamond, 0.25)))]
    if kind == "no_entry":
        return RED, [(RED, texkit.disc(1.0)), (WHITE, texkit.rect(-0.72, -0.18, 0.72, 0.18))]
    if kind == "speed_limit":
        digits = str(value)
        squeeze = {1: 0.8, 2: 0.66, 3: 0.46}[len(digits)]
        return RED, [(WHITE, texkit.disc(0.76)),
                     (BLACK, texkit.text(digits, 0, 0, 0.74 if len(digits) < 3 else 0.64, stroke=0.15,
                                         squeeze=squeeze))]
    if kind == "bus_stop":  # German "Haltestelle": a green H on a yellow disc, green ring
        green = (16, 122, 64)
        return green, [(YELLOW, texkit.disc(0.86)), (green, texkit.text("H", 0, 0, 0.95, stroke=0.2, squeeze=1.0))]
    raise ValueError(kind)


def face_png(path, kind, value=None, size=TEXTURE):
    background, layers = face_layers(kind, value)
    texkit.write_png(path, texkit.paint(size, layers, background=background))


def add_face(m, shape, material, centre, half=None, x=0.0):
    """The textured face of a sign: the shape's outline, looking along +x, at `centre` (y, z)."""
    outline, h = SHAPES[shape]
    h = half or h
    m.begin("face", material).flat()
    pts = [(x, centre[0] + u * h, centre[1] + v * h) for u, v in outline]
    m.poly_uv(pts, [((u + 1) / 2, (v + 1) / 2) for u, v in outline])


def add_plate(m, shape, centre, half=None, depth=0.02):
    """The sign's back (grey, looking along -x) and rim, behind its face."""
    outline, h = SHAPES[shape]
    h = half or h
    m.begin("back", "sign_back").flat()
    front = [(-0.001, centre[0] + u * h, centre[1] + v * h) for u, v in outline]
    back = [(-depth, y, z) for _, y, z in front]
    m.loft([back, front])
    m.poly(list(reversed(back)))


def add_pole(m, top, x=POLE_X, r=POLE_R, material="pole", sides=8):
    m.begin("pole", material).smooth(60)
    m.tube((x, 0, 0), (x, 0, top), r, n=sides, cap_a=False)


def sign(shape, kind, value=None):
    """A sign model's mesh: body (pole, plate) and face (material 'face')."""
    m = Mesh()
    half = SHAPES[shape][1]
    centre = (0.0, BOTTOM + half * (0.866 if shape.startswith("triangle") else 1.0))
    add_pole(m, centre[1] + half * 0.6)
    # clamps holding the plate to the pole
    m.begin("clamps", "sign_back").flat()
    for dz in (-0.5 * half, 0.5 * half):
        m.block((POLE_X - POLE_R - 0.008, -0.04, centre[1] + dz - 0.025),
                (-0.02, 0.04, centre[1] + dz + 0.025), skip=("+x",))
    add_plate(m, shape, centre)
    add_face(m, shape, "face", centre)
    return m


def signs():
    """[(model name, shape, sign type, value, texture name)]."""
    out = [("sign_stop", "octagon", "stop", None, "sign_stop"),
           ("sign_yield", "triangle_down", "yield", None, "sign_yield"),
           ("sign_no_entry", "disc", "no_entry", None, "sign_no_entry"),
           ("sign_warning", "triangle_up", "warning", None, "sign_warning"),
           ("sign_priority", "diamond", "priority", None, "sign_priority")]
    out += [("sign_speed_%d" % v, "disc", "speed_limit", v, "sign_speed_%d" % v) for v in SPEEDS]
    return out


# ---------------------------------------------------------------- traffic lights
def add_board(m, y_half, z0, z1, x):
    """The black contrast board with its white edge, behind a housing at x."""
    m.begin("board", "board_edge").flat()
    m.block((x - 0.025, -y_half - 0.03, z0 - 0.03), (x - 0.015, y_half + 0.03, z1 + 0.03))
    m.begin("board", "board").flat()
    m.block((x - 0.015, -y_half, z0), (x, y_half, z1), skip=("-x",))


def add_visor(m, c, r, length, n=6):
    """A half-tube hood over a round lamp at c (x, y, z), open below, reaching `length` out."""
    m.begin("visors", "housing").flat()
    outer = [(c[0], c[1] + (r + 0.006) * math.cos(math.pi * k / n), c[2] + (r + 0.006) * math.sin(math.pi * k / n))
             for k in range(n + 1)]
    inner = [(c[0], c[1] + r * math.cos(math.pi * k / n), c[2] + r * math.sin(math.pi * k / n))
             for k in reversed(range(n + 1))]
    m.sweep(outer + inner, (length, 0, 0))


def add_round_lamp(m, colour, c, r, n=14):
    m.begin("lamp_" + colour, "lamp_" + colour).smooth(50)
    ring = [(c[0], c[1] + r * math.cos(2 * math.pi * k / n), c[2] + r * math.sin(2 * math.pi * k / n))
            for k in range(n)]
    tip = (c[0] + 0.025, c[1], c[2])
    for k in range(n):
        m.tri(ring[k], ring[(k + 1) % n], tip)


def traffic_light():
    """Pole, housing (front at x = 0.33), three lamps 0.3 m apart, the red one on top."""
    m = Mesh()
    add_pole(m, 3.5, x=0.0, r=0.07, material="pole_dark", sides=12)
    x0, x1, z0, z1 = 0.1, 0.33, 2.3, 3.26
    add_board(m, 0.27, z0 - 0.1, z1 + 0.1, x0)
    m.begin("housing", "housing").flat()
    m.block((x0, -0.16, z0), (x1, 0.16, z1), skip=("-x",))
    m.block((0.07, -0.05, z0 + 0.2), (x0 - 0.025, 0.05, z1 - 0.2))  # the bracket to the pole
    for k, colour in enumerate(("red", "yellow", "green")):
        c = (x1 + 0.002, 0.0, z1 - 0.18 - 0.3 * k)
        add_visor(m, c, 0.125, 0.2)
        add_round_lamp(m, colour, c, 0.1)
    return m


def pedestrian_light():
    """Pole, a housing of two square lamps (red standing figure on top, green walking below)
    and the push-button box."""
    m = Mesh()
    add_pole(m, 2.9, x=0.0, r=0.06, material="pole_dark", sides=12)
    x0, x1, z0, z1 = 0.09, 0.28, 2.1, 2.74
    add_board(m, 0.21, z0 - 0.06, z1 + 0.06, x0)
    m.begin("housing", "housing").flat()
    m.block((x0, -0.15, z0), (x1, 0.15, z1), skip=("-x",))
    m.block((0.055, -0.04, z0 + 0.15), (x0 - 0.025, 0.04, z1 - 0.15))
    for k, colour in enumerate(("red", "green")):
        zc = z1 - 0.16 - 0.32 * k
        m.begin("visors", "housing").flat()
        m.block((x1, -0.14, zc + 0.125), (x1 + 0.12, 0.14, zc + 0.135))
        m.begin("lamp_" + colour, "ped_" + colour).flat()
        h = 0.125
        pts = [(x1 + 0.002, -h, zc - h), (x1 + 0.002, h, zc - h), (x1 + 0.002, h, zc + h), (x1 + 0.002, -h, zc + h)]
        m.poly_uv(pts, [(0, 0), (1, 0), (1, 1), (0, 1)])
    m.begin("button", "button").flat()
    m.block((0.06, -0.07, 0.95), (0.15, 0.07, 1.25))
    return m


def pictogram(path, walking, size=64):
    """A pedestrian lamp's lens picture: a light figure on dark (the MTL's lens colour tints it)."""
    if walking:
        lines = [[(-0.05, 0.32), (0.02, -0.2)], [(0.02, -0.2), (-0.28, -0.78)], [(0.02, -0.2), (0.3, -0.78)],
                 [(-0.05, 0.28), (-0.35, -0.05)], [(-0.03, 0.28), (0.3, 0.0)]]
        head = (-0.02, 0.56)
    else:
        lines = [[(0.0, 0.32), (0.0, -0.2)], [(-0.1, -0.2), (-0.12, -0.8)], [(0.1, -0.2), (0.12, -0.8)],
                 [(-0.14, 0.3), (-0.22, -0.25)], [(0.14, 0.3), (0.22, -0.25)]]
        head = (0.0, 0.56)
    body = texkit.strokes(lines, 0.2)
    layers = [((255, 255, 255), lambda x, y: body(x, y) or texkit.disc(0.15, *head)(x, y))]
    texkit.write_png(path, texkit.paint(size, layers, background=(40, 40, 40)))
