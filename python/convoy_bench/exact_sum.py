"""An exact running sum: math.fsum of a stream, in bounded memory (live.py)."""

import math


class ExactSum:
    """math.fsum of a stream of finite floats in bounded memory: Shewchuk's non-overlapping
    partials hold the exact sum, and math.fsum, correctly rounded, gives of them the same bits
    as of all the values."""
    __slots__ = ("partials",)

    def __init__(self):
        self.partials = []

    def add(self, x):
        p, i = self.partials, 0
        for y in p:
            if abs(x) < abs(y):
                x, y = y, x
            hi = x + y
            lo = y - (hi - x)
            if lo:
                p[i] = lo
                i += 1
            x = hi
        p[i:] = [x]

    def value(self):
        return math.fsum(self.partials)
