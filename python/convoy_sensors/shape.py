"""What a LiDAR cluster is, from what the sensor measures of it (issue 27: phantom braking for
roadside trees): its height profile and its returns' intensities, never the points'
ground-truth instance or label.

    f = features(q, intensity)      # q: the cluster's points (N x 3, ego frame), intensity: N
    kind = vegetation(f)            # "trunk_canopy", "foliage" or None

Height profile: the points in SLICE m slices of height from the ground up; each slice's span
is the larger of its x and y extents. A tree is a narrow trunk under a wide crown: the slices starting
below CANOPY_MIN_Z m (a car's roof) are at most TRUNK_SPAN m wide, and one above is at least
CANOPY_SPAN m and CANOPY_RATIO times as wide ("trunk_canopy"). A vehicle's lowest slices (bumpers, wheels,
its body) are as wide as it is or wider than its cabin; a walker is narrow all the way up.

Intensity (docs/lidar.md, reflectivity.h): leaves give reflectivity 0.45 times the cosine of
incidence, so foliage never returns more than about VEGETATION_MAX; a vehicle has paint
(0.45-0.70, metal and light paint the brightest), plates and lights (0.68-0.85) and glass, tyres
and trim (0.03-0.05). "foliage": the cluster's bright fraction (intensity above
VEGETATION_MAX) is at most FOLIAGE_BRIGHT and its dark fraction (below DARK: glass, tyres)
at most FOLIAGE_DARK, with at least FOLIAGE_MIN_POINTS returns (fewer say nothing). Fog
dims every return (two-way transmission), which can only lower the bright fraction and raise
the dark one: a dimmed car keeps its glass's dark returns.
"""

import numpy as np

SLICE = 0.4            # m
TRUNK_SPAN = 0.8       # m: a slice this narrow under a crown is a trunk
CANOPY_SPAN = 1.4      # m: a crown is at least this wide ...
CANOPY_RATIO = 2.0     # ... and this many times the trunk's span
CANOPY_MIN_Z = 1.5     # m: the crown is above this (a car's roof; a car's body is wide from its
#                        sills up: a wheel under it is no trunk)
TRUNK_POINTS = 2       # returns under the crown, at least
VEGETATION_MAX = 0.47  # leaves: reflectivity 0.45 x cos(incidence), noise aside
DARK = 0.12            # glass 0.05, tyres and trim about 0.03
FOLIAGE_BRIGHT = 0.03
FOLIAGE_DARK = 0.15
FOLIAGE_MIN_POINTS = 30


def profile(q, ground_z=0.3, slice_m=SLICE):
    """[(z0, span, points)] of the cluster's occupied height slices, lowest first."""
    q = np.asarray(q, float).reshape(-1, 3)
    if not len(q):
        return []
    k = np.floor((q[:, 2] - ground_z) / slice_m).astype(np.int64)
    out = []
    for s in np.unique(k).tolist():
        p = q[k == s]
        span = max(float(np.ptp(p[:, 0])), float(np.ptp(p[:, 1])))
        out.append((ground_z + s * slice_m, span, int(len(p))))
    return out


def trunk_canopy(prof):
    """True for a tree's profile: every slice starting below CANOPY_MIN_Z is a trunk (at most
    TRUNK_SPAN wide, at least TRUNK_POINTS returns in all), and a slice above is a crown (at
    least CANOPY_SPAN wide and CANOPY_RATIO times the trunk's width)."""
    trunk = [(span, n) for z0, span, n in prof if z0 < CANOPY_MIN_Z]
    crown = [span for z0, span, _ in prof if z0 >= CANOPY_MIN_Z]
    if not trunk or not crown or sum(n for _, n in trunk) < TRUNK_POINTS:
        return False
    widest_trunk = max(span for span, _ in trunk)
    return widest_trunk <= TRUNK_SPAN and max(crown) >= max(CANOPY_SPAN, CANOPY_RATIO * max(widest_trunk, 0.1))


def features(q, intensity=None, ground_z=0.3):
    """A dict of the cluster's measured features: profile, top, trunk_canopy, and with
    intensities bright (fraction above VEGETATION_MAX), dark (below DARK), median."""
    q = np.asarray(q, float).reshape(-1, 3)
    prof = profile(q, ground_z)
    f = {"points": int(len(q)), "profile": prof, "top": float(q[:, 2].max()) if len(q) else 0.0,
         "trunk_canopy": trunk_canopy(prof)}
    if intensity is not None and len(q):
        i = np.asarray(intensity, float).reshape(-1)
        f["bright"] = float(np.mean(i > VEGETATION_MAX))
        f["dark"] = float(np.mean(i < DARK))
        f["median"] = float(np.median(i))
    return f


def vegetation(f):
    """"trunk_canopy", "foliage" or None (module docstring) from features()."""
    if f["trunk_canopy"]:
        return "trunk_canopy"
    if "bright" in f and f["points"] >= FOLIAGE_MIN_POINTS and f["bright"] <= FOLIAGE_BRIGHT \
            and f["dark"] <= FOLIAGE_DARK:
        return "foliage"
    return None
