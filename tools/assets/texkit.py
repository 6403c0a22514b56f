"""Small textures for the asset generators (make_signals.py): an RGB PNG writer (zlib +
struct), a painter of shapes in layers with anti-aliased edges, and a stroke font (digits and
a few capitals, drawn as thick polylines like DIN 1451 lettering). Stdlib only; output
deterministic.

Coordinates of a picture: x to the right and y up, both -1..1 over the whole image."""
import math
import struct
import zlib


def write_png(path, rows):
    """rows: the image's rows, top first, each a list of (r, g, b) in 0..255."""
    h, w = len(rows), len(rows[0])
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def paint(size, layers, background=(255, 255, 255), ss=4, height=None):
    """Paints `layers` [(rgb, inside(x, y) -> bool)] in order (the last on top) on an image
    of size x size pixels (size x height: then y runs over -height/size..height/size). A pixel
    whose centre and corners fall in the same layer takes its colour; others are averaged over
    ss x ss samples (anti-aliased edges). Returns rows."""
    def colour_at(x, y):
        c = background
        for rgb, inside in layers:
            if inside(x, y):
                c = rgb
        return c

    px = 2.0 / size
    rows = []
    height = height or size
    for j in range(height):
        y = height / size - (j + 0.5) * px
        row = []
        for i in range(size):
            x = -1 + (i + 0.5) * px
            probes = [colour_at(x + dx * px, y + dy * px) for dx, dy in
                      ((0, 0), (-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5))]
            if all(p == probes[0] for p in probes):
                row.append(probes[0])
                continue
            acc = [0, 0, 0]
            for a in range(ss):
                for b in range(ss):
                    c = colour_at(x + ((a + 0.5) / ss - 0.5) * px, y + ((b + 0.5) / ss - 0.5) * px)
                    for k in range(3):
                        acc[k] += c[k]
            row.append(tuple(int(round(v / (ss * ss))) for v in acc))
        rows.append(row)
    return rows


# ---------------------------------------------------------------- shapes
def disc(r, cx=0.0, cy=0.0):
    return lambda x, y: (x - cx) ** 2 + (y - cy) ** 2 <= r * r


def rect(x0, y0, x1, y1):
    return lambda x, y: x0 <= x <= x1 and y0 <= y <= y1


def polygon(pts):
    """A convex polygon, points counter-clockwise."""
    edges = list(zip(pts, pts[1:] + pts[:1]))
    return lambda x, y: all((bx - ax) * (y - ay) - (by - ay) * (x - ax) >= 0 for (ax, ay), (bx, by) in edges)


def regular(n, r, start):
    """The points of a regular n-gon of circumradius r, the first at angle `start` (radians)."""
    return [(r * math.cos(start + 2 * math.pi * k / n), r * math.sin(start + 2 * math.pi * k / n)) for k in range(n)]


def inset(pts, d):
    """A convex polygon (counter-clockwise) moved inwards by d on every side."""
    n = len(pts)
    lines = []
    for k in range(n):
        (ax, ay), (bx, by) = pts[k], pts[(k + 1) % n]
        ex, ey = bx - ax, by - ay
        le = math.hypot(ex, ey)
        nx, ny = -ey / le, ex / le  # inward normal of a counter-clockwise polygon
        lines.append(((ax + nx * d, ay + ny * d), (ex, ey)))
    out = []
    for k in range(n):
        (p, e), (q, f) = lines[k - 1], lines[k]
        den = e[0] * f[1] - e[1] * f[0]
        t = ((q[0] - p[0]) * f[1] - (q[1] - p[1]) * f[0]) / den
        out.append((p[0] + e[0] * t, p[1] + e[1] * t))
    return out


# ---------------------------------------------------------------- the stroke font
def _arc(cx, cy, rx, ry, a0, a1, n=10):
    return [(cx + rx * math.cos(math.radians(a0 + (a1 - a0) * k / n)),
             cy + ry * math.sin(math.radians(a0 + (a1 - a0) * k / n))) for k in range(n + 1)]


# Glyphs in a box 0..0.6 wide, 0..1 tall (stroke centre lines), as lists of polylines.
GLYPHS = {
    "0": [_arc(0.3, 0.5, 0.3, 0.5, 0, 360, 28)],
    "1": [[(0.08, 0.76), (0.36, 1.0), (0.36, 0.0)]],
    "2": [_arc(0.3, 0.7, 0.28, 0.3, 160, 0, 8)[:-1] + _arc(0.3, 0.7, 0.28, 0.3, 0, -40, 4)
          + [(0.0, 0.0), (0.6, 0.0)]],
    "3": [_arc(0.3, 0.74, 0.26, 0.26, 150, -90, 12), _arc(0.3, 0.27, 0.3, 0.27, 90, -150, 12)],
    "4": [[(0.46, 0.0), (0.46, 1.0), (0.0, 0.3), (0.6, 0.3)]],
    "5": [[(0.56, 1.0), (0.08, 1.0), (0.04, 0.55)] + _arc(0.3, 0.33, 0.3, 0.33, 120, -150, 14)],
    "6": [_arc(0.3, 0.3, 0.3, 0.3, 0, 360, 20), _arc(0.95, 0.3, 0.95, 0.7, 180, 118, 8)],
    "7": [[(0.0, 1.0), (0.6, 1.0), (0.18, 0.0)]],
    "8": [_arc(0.3, 0.76, 0.25, 0.24, 0, 360, 20), _arc(0.3, 0.27, 0.3, 0.27, 0, 360, 20)],
    "9": [_arc(0.3, 0.7, 0.3, 0.3, 0, 360, 20), _arc(-0.35, 0.7, 0.95, 0.7, 0, -62, 8)],
    "S": [_arc(0.3, 0.75, 0.27, 0.25, 20, 270, 12) + _arc(0.3, 0.25, 0.3, 0.25, 90, -160, 12)],
    "T": [[(0.0, 1.0), (0.6, 1.0)], [(0.3, 1.0), (0.3, 0.0)]],
    "O": [_arc(0.3, 0.5, 0.3, 0.5, 0, 360, 28)],
    "P": [[(0.04, 0.0), (0.04, 1.0), (0.3, 1.0)] + _arc(0.3, 0.73, 0.27, 0.27, 90, -90, 10) + [(0.04, 0.46)]],
    "H": [[(0.04, 0.0), (0.04, 1.0)], [(0.56, 0.0), (0.56, 1.0)], [(0.04, 0.5), (0.56, 0.5)]],
    "B": [[(0.04, 0.5), (0.3, 0.5)] + _arc(0.3, 0.75, 0.24, 0.25, -90, 90, 8) + [(0.04, 1.0), (0.04, 0.0), (0.3, 0.0)]
          + _arc(0.3, 0.25, 0.28, 0.25, -90, 90, 8)],
    "U": [[(0.04, 1.0)] + _arc(0.3, 0.3, 0.26, 0.3, 180, 360, 12) + [(0.56, 1.0)]],
    "!": [[(0.3, 1.0), (0.3, 0.3)], [(0.3, 0.02), (0.3, 0.0)]],
}
ADVANCE = 0.78  # glyph width plus spacing, in glyph heights


def text(s, cx, cy, height, stroke=0.16, squeeze=1.0):
    """inside(x, y) of the string s centred on (cx, cy), glyphs `height` tall, strokes
    stroke * height wide, squeezed horizontally by `squeeze` (condensed lettering)."""
    w = (len(s) - 1) * ADVANCE + 0.6
    sx, sy = height * squeeze, height
    half = stroke * height / 2
    top = (height - 2 * half) / height  # keep the strokes inside the box
    lines = []
    for k, ch in enumerate(s):
        ox = k * ADVANCE
        for line in GLYPHS[ch]:
            lines.append([(cx + (ox + (px - 0.3) * top + 0.3 - w / 2) * sx, cy + ((py - 0.5) * top) * sy)
                          for px, py in line])
    return strokes(lines, 2 * half)


def strokes(lines, width):
    """inside(x, y) of polylines drawn `width` wide with round ends."""
    half = width / 2
    r2 = half * half
    groups = []  # (bounding box, segments) per polyline
    for pts in lines:
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]
        groups.append(((min(xs) - half, min(ys) - half, max(xs) + half, max(ys) + half), list(zip(pts, pts[1:]))))

    def inside(x, y):
        for (x0, y0, x1, y1), segs in groups:
            if not (x0 <= x <= x1 and y0 <= y <= y1):
                continue
            for (ax, ay), (bx, by) in segs:
                ex, ey = bx - ax, by - ay
                ll = ex * ex + ey * ey
                t = 0.0 if ll == 0 else max(0.0, min(1.0, ((x - ax) * ex + (y - ay) * ey) / ll))
                dx, dy = x - ax - t * ex, y - ay - t * ey
                if dx * dx + dy * dy <= r2:
                    return True
        return False
    return inside
