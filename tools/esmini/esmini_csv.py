"""Reading esmini's output files and writing compact reference tracks.

esmini's CSV_Logger file (`--csv_logger`): 6 information lines, a header, then one row per
step: `Index, TimeStamp` and 31 fields per entity (name, id, speed, wheel angle, wheel
rotation, bounding box x y z length width height, world X Y Z, velocity X Y Z, acceleration
X Y Z, road s, lateral distance, lane id, lane offset, heading, heading rate, relative heading,
relative heading in driving direction, pitch, road curvature, collision ids). Entities spawned
during a run add blocks beyond the header's count, so rows are read in blocks of 31.

The CSV has no road id; dat2csv's extended form of a `--record` file has one (roadId), joined
on (time, entity) when available.

The reference format is Convoy's tracks.csv (python/convoy_scenario/tracks.py):
`t,entity,x,y,z,heading,speed,road,lane,s`, gzip'd deterministically.
"""

import gzip
import io
import math

BLOCK = 31
F_NAME, F_SPEED, F_X, F_Y, F_Z, F_S, F_LANE, F_HEADING = 0, 2, 11, 12, 13, 20, 22, 24
HEADER = "t,entity,x,y,z,heading,speed,road,lane,s\n"


def _fields(line):
    parts = [p.strip() for p in line.rstrip("\n").split(",")]
    if parts and parts[-1] == "":
        parts.pop()
    return parts


def read_csv_logger(path):
    """[(t, entity, x, y, z, heading, speed, lane, s)] in file order (heading in esmini's
    range), from a CSV_Logger file."""
    rows = []
    with open(path) as f:
        lines = f.readlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Index")) + 1
    for lineno, line in enumerate(lines[start:], start + 1):
        parts = _fields(line)
        if not parts:
            continue
        if (len(parts) - 2) % BLOCK:
            raise ValueError("%s:%d: %d fields, not 2 + a multiple of %d" % (
                path, lineno, len(parts), BLOCK))
        t = float(parts[1])
        for k in range(2, len(parts), BLOCK):
            b = parts[k:k + BLOCK]
            rows.append((t, b[F_NAME], float(b[F_X]), float(b[F_Y]), float(b[F_Z]),
                         float(b[F_HEADING]), float(b[F_SPEED]), int(float(b[F_LANE])),
                         float(b[F_S])))
    return rows


def read_dat2csv_roads(path):
    """(round(t, 2), entity) -> road id, from dat2csv's `--extended` CSV."""
    roads = {}
    with open(path) as f:
        header = _fields(f.readline())
        try:
            ti, ni, ri = header.index("time"), header.index("name"), header.index("roadId")
        except ValueError:
            return roads
        for line in f:
            parts = _fields(line)
            if len(parts) > max(ti, ni, ri):
                roads[(round(float(parts[ti]), 2), parts[ni])] = parts[ri]
    return roads


def wrap(angle):
    """Angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def _num(value, digits):
    text = "%.*f" % (digits, value)
    return "0" if float(text) == 0.0 else text.rstrip("0").rstrip(".") if "." in text else text


def format_rows(rows, roads, every):
    """Reference CSV text: rows of steps whose index (t / 0.05) is a multiple of `every`;
    positions and s in cm, heading in mrad (wrapped to [-pi, pi)), speed in cm/s."""
    out = [HEADER]
    for t, name, x, y, z, heading, speed, lane, s in rows:
        step = int(round(t / 0.05))
        if step % every:
            continue
        road = roads.get((round(t, 2), name), "")
        out.append("%s,%s,%s,%s,%s,%s,%s,%s,%d,%s\n" % (
            _num(t, 2), name, _num(x, 2), _num(y, 2), _num(z, 2), _num(wrap(heading), 3),
            _num(speed, 2), road, lane, _num(s, 2)))
    return "".join(out)


def gzip_bytes(text):
    """gzip of text, byte-identical for identical text (no name, mtime 0)."""
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, compresslevel=9, mtime=0) as f:
        f.write(text.encode())
    return buf.getvalue()


def entities_in_order(rows):
    seen = {}
    for row in rows:
        seen.setdefault(row[1], None)
    return list(seen)
