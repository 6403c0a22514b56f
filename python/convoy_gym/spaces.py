"""Observation and action spaces: gymnasium.spaces when gymnasium is importable, otherwise
small classes with the same attributes and methods (shape, dtype, low, high, n, seed(),
sample(), contains()), so Debian's python3 with numpy alone runs convoy_gym.

Only what DrivingEnv and common RL code use is here: Box, Discrete and Dict."""
import numpy as np

try:  # the real thing when it is installed
    from gymnasium.spaces import Box, Dict, Discrete, Space  # noqa: F401
    USING_GYMNASIUM = True
except ImportError:
    USING_GYMNASIUM = False

__all__ = ["Space", "Box", "Discrete", "Dict", "USING_GYMNASIUM"]

if not USING_GYMNASIUM:
    class Space:  # noqa: F811 - the fallback for gymnasium.spaces
        """A set of values, with a seedable random generator for sample()."""

        def __init__(self, shape=None, dtype=None, seed=None):
            self._shape = None if shape is None else tuple(shape)
            self.dtype = None if dtype is None else np.dtype(dtype)
            self._np_random = None
            if seed is not None:
                self.seed(seed)

        @property
        def shape(self):
            return self._shape

        @property
        def np_random(self):
            """The space's np.random.Generator (seeded from entropy on first use)."""
            if self._np_random is None:
                self.seed()
            return self._np_random

        def seed(self, seed=None):
            """Seeds sample(); returns [seed] as gymnasium does."""
            if seed is not None and not (isinstance(seed, (int, np.integer)) and seed >= 0):
                raise ValueError("seed must be an int >= 0 or None, got %r" % (seed,))
            seq = np.random.SeedSequence(seed)
            self._np_random = np.random.Generator(np.random.PCG64(seq))
            return [int(seq.entropy)]

        def sample(self):
            raise NotImplementedError

        def contains(self, x):
            raise NotImplementedError

        def __contains__(self, x):
            return self.contains(x)

    class Box(Space):  # noqa: F811
        """Arrays of `shape` with low <= x <= high element-wise (bounds may be +-inf)."""

        def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
            dtype = np.dtype(dtype)
            if shape is None:
                shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
            shape = tuple(int(s) for s in shape)
            self.low = np.full(shape, low, dtype=dtype) if np.isscalar(low) else \
                np.broadcast_to(np.asarray(low, dtype=dtype), shape).copy()
            self.high = np.full(shape, high, dtype=dtype) if np.isscalar(high) else \
                np.broadcast_to(np.asarray(high, dtype=dtype), shape).copy()
            if np.any(self.low > self.high):
                raise ValueError("Box: low %s > high %s" % (self.low, self.high))
            self.bounded_below = np.isfinite(self.low)
            self.bounded_above = np.isfinite(self.high)
            super().__init__(shape, dtype, seed)

        def is_bounded(self, manner="both"):
            below, above = bool(np.all(self.bounded_below)), bool(np.all(self.bounded_above))
            return {"both": below and above, "below": below, "above": above}[manner]

        def sample(self):
            """Uniform where bounded on both sides, shifted exponential where bounded on one,
            normal where unbounded (gymnasium's rule)."""
            rng = self.np_random
            high = self.high.astype(np.float64) if self.dtype.kind == "f" else \
                self.high.astype(np.float64) + 1
            out = np.empty(self.shape, dtype=np.float64)
            lo_b, hi_b = self.bounded_below, self.bounded_above
            both, none = lo_b & hi_b, ~lo_b & ~hi_b
            only_lo, only_hi = lo_b & ~hi_b, ~lo_b & hi_b
            out[none] = rng.normal(size=none[none].shape)
            out[only_lo] = rng.exponential(size=only_lo[only_lo].shape) + self.low[only_lo]
            out[only_hi] = high[only_hi] - rng.exponential(size=only_hi[only_hi].shape)
            out[both] = rng.uniform(self.low[both], high[both], size=both[both].shape)
            if self.dtype.kind in "iu":
                out = np.floor(out)
            return np.clip(out, self.low, self.high).astype(self.dtype)

        def contains(self, x):
            if not isinstance(x, np.ndarray):
                try:
                    x = np.asarray(x, dtype=self.dtype)
                except (ValueError, TypeError):
                    return False
            return bool(np.can_cast(x.dtype, self.dtype) and x.shape == self.shape
                        and np.all(x >= self.low) and np.all(x <= self.high))

        def __repr__(self):
            return "Box(%s, %s, %s, %s)" % (self.low.min(), self.high.max(), self.shape,
                                           self.dtype)

        def __eq__(self, other):
            return (isinstance(other, Box) and self.shape == other.shape
                    and self.dtype == other.dtype and np.array_equal(self.low, other.low)
                    and np.array_equal(self.high, other.high))

    class Discrete(Space):  # noqa: F811
        """The integers start, start + 1, ..., start + n - 1."""

        def __init__(self, n, seed=None, start=0):
            if int(n) <= 0:
                raise ValueError("Discrete: n must be > 0, got %r" % (n,))
            self.n = np.int64(n)
            self.start = np.int64(start)
            super().__init__((), np.int64, seed)

        def sample(self):
            return np.int64(self.start + self.np_random.integers(self.n))

        def contains(self, x):
            if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
                v = int(x)
            elif isinstance(x, np.ndarray) and x.shape == () and x.dtype.kind in "iu":
                v = int(x)
            else:
                return False
            return int(self.start) <= v < int(self.start + self.n)

        def __repr__(self):
            return "Discrete(%d)" % self.n if self.start == 0 else \
                "Discrete(%d, start=%d)" % (self.n, self.start)

        def __eq__(self, other):
            return isinstance(other, Discrete) and self.n == other.n and \
                self.start == other.start

    class Dict(Space):  # noqa: F811
        """A dict of named spaces; samples are dicts with the same keys."""

        def __init__(self, spaces=None, seed=None, **kwargs):
            spaces = dict(spaces or {}, **kwargs)
            for key, space in spaces.items():
                if not isinstance(space, Space):
                    raise TypeError("Dict: %r is a %s, not a space" % (key, type(space).__name__))
            self.spaces = spaces
            super().__init__(None, None, None)
            if seed is not None:
                self.seed(seed)

        def seed(self, seed=None):
            """Seeds every subspace from one seed (each gets its own stream)."""
            seeds = super().seed(seed)
            for space in self.spaces.values():
                seeds += space.seed(int(self._np_random.integers(2 ** 31)))
            return seeds

        def sample(self):
            if self._np_random is None:
                self.seed()
            return {key: space.sample() for key, space in self.spaces.items()}

        def contains(self, x):
            return isinstance(x, dict) and x.keys() == self.spaces.keys() and \
                all(space.contains(x[key]) for key, space in self.spaces.items())

        def __getitem__(self, key):
            return self.spaces[key]

        def __iter__(self):
            return iter(self.spaces)

        def keys(self):
            return self.spaces.keys()

        def __len__(self):
            return len(self.spaces)

        def __repr__(self):
            return "Dict(%s)" % ", ".join("%r: %r" % kv for kv in self.spaces.items())
