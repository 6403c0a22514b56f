"""Overlaid histograms as a PNG without matplotlib (not installed here): one coloured line per
source (density per bin), an x axis with a tick every `tick` units and a y axis. No text: the
report names the colours and the range. Samples outside the range are left out of the plot
(the share per bin is still of all samples)."""
import struct
import zlib

import numpy as np

COLOURS = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40)]  # blue orange green red


def _png(path, img):
    h, w, _ = img.shape
    raw = b"".join(b"\x00" + img[y].tobytes() for y in range(h))

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def _line(img, x0, y0, x1, y1, colour, width=2):
    n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
    for k in range(n + 1):
        x = int(round(x0 + (x1 - x0) * k / n))
        y = int(round(y0 + (y1 - y0) * k / n))
        y0, x0 = max(0, y - width // 2), max(0, x - width // 2)
        img[y0:y + (width + 1) // 2, x0:x + (width + 1) // 2] = colour


def histograms(path, series, lo, hi, tick, bins=60, size=(720, 360)):
    """series: list of sample arrays (in COLOURS order); range [lo, hi]."""
    w, h = size
    m = 30  # margin
    img = np.full((h, w, 3), 255, dtype=np.uint8)
    edges = np.linspace(lo, hi, bins + 1)
    dens = [np.histogram(s, edges)[0] / max(1, len(s)) for s in series]  # outside: not drawn
    top = max(float(np.max(d)) for d in dens) if dens else 1.0
    top = top or 1.0
    px = lambda x: m + (x - lo) / (hi - lo) * (w - 2 * m)
    py = lambda d: h - m - d / top * (h - 2 * m)
    _line(img, m, h - m, w - m, h - m, (0, 0, 0), 1)
    _line(img, px(0) if lo <= 0 <= hi else m, m, px(0) if lo <= 0 <= hi else m, h - m, (0, 0, 0), 1)
    for x in np.arange(np.ceil(lo / tick) * tick, hi + 1e-9, tick):
        _line(img, px(x), h - m, px(x), h - m + 6, (0, 0, 0), 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    for d, colour in zip(dens, COLOURS):
        for k in range(len(d) - 1):
            _line(img, px(centres[k]), py(d[k]), px(centres[k + 1]), py(d[k + 1]), colour)
    _png(path, img)
