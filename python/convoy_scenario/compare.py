"""Agreement of a scenario run's tracks with reference tracks (esmini's, recorded by
tools/esmini/record_reference.py into tests/data/esmini/reference).

Both files have Convoy's tracks.csv columns (tracks.py): `t,entity,x,y,z,heading,speed,road,
lane,s`; a name ending in .gz is read gzip'd. Per entity of the reference, the run's track is
interpolated linearly at the reference's times inside the run's span (never across a gap
longer than `max_gap`), and compared there:
- position error: distance in x, y; speed error: |speed difference|;
- median and max position error, median speed error over the compared times;
- coverage: the fraction of the reference's times that were compared.
An entity of the reference the run does not have is reported missing; one the run has and the
reference does not, extra. A scenario's figure is the median over its entities (those not
excluded, with at least one compared time) of their median errors.

    /usr/bin/python3 -m convoy_scenario.compare TRACKS.csv REFERENCE.csv.gz [--exclude NAME...]
"""

import bisect
import csv
import dataclasses
import gzip
import math
import statistics
import sys

MAX_GAP = 1.0


@dataclasses.dataclass(frozen=True)
class Track:
    t: tuple
    x: tuple
    y: tuple
    speed: tuple


@dataclasses.dataclass(frozen=True)
class EntityAgreement:
    entity: str
    samples: int                  # reference times
    compared: int                 # of them inside the run's track
    median_position_error: float  # m (None when nothing compared)
    max_position_error: float     # m
    median_speed_error: float     # m/s

    @property
    def coverage(self):
        return self.compared / self.samples if self.samples else 0.0


@dataclasses.dataclass(frozen=True)
class ScenarioAgreement:
    entities: dict                # name -> EntityAgreement (reference entities in the run)
    missing: tuple                # reference entities the run does not have
    extra: tuple                  # run entities the reference does not have
    excluded: tuple               # reference entities left out of the figure
    position_error: float         # median over the figure's entities (None if none)
    speed_error: float
    max_position_error: float
    coverage: float               # compared / reference times, over the figure's entities

    def within(self, metres):
        return self.position_error is not None and self.position_error <= metres


def _open(path):
    return gzip.open(path, "rt", newline="") if path.endswith(".gz") else open(path, newline="")


def read_tracks(path):
    """entity -> Track (time-ordered) of a tracks.csv or reference file."""
    rows = {}
    with _open(path) as f:
        reader = csv.DictReader(f)
        missing = {"t", "entity", "x", "y", "speed"} - set(reader.fieldnames or ())
        if missing:
            raise ValueError("%s: no column %s (tracks.csv has t,entity,x,y,z,heading,speed,"
                             "road,lane,s)" % (path, ", ".join(sorted(missing))))
        for line, row in enumerate(reader, 2):
            try:
                sample = (float(row["t"]), float(row["x"]), float(row["y"]), float(row["speed"]))
            except (TypeError, ValueError):
                raise ValueError("%s:%d: not a number in %r" % (path, line, row)) from None
            rows.setdefault(row["entity"], []).append(sample)
    tracks = {}
    for name, samples in rows.items():
        samples.sort(key=lambda s: s[0])
        tracks[name] = Track(*(tuple(col) for col in zip(*samples)))
    return tracks


def interpolate(track, t, max_gap=MAX_GAP):
    """(x, y, speed) of the track at time t, or None outside its span or inside a gap."""
    eps = 1e-6
    if not track.t or t < track.t[0] - eps or t > track.t[-1] + eps:
        return None
    i = bisect.bisect_left(track.t, t - eps)
    if i < len(track.t) and abs(track.t[i] - t) <= eps:
        return track.x[i], track.y[i], track.speed[i]
    t0, t1 = track.t[i - 1], track.t[i]
    if t1 - t0 > max_gap:
        return None
    w = (t - t0) / (t1 - t0)
    return tuple(a + w * (b - a) for a, b in ((track.x[i - 1], track.x[i]),
                                              (track.y[i - 1], track.y[i]),
                                              (track.speed[i - 1], track.speed[i])))


def compare_entity(name, run, reference, max_gap=MAX_GAP):
    position, speed = [], []
    for t, x, y, v in zip(reference.t, reference.x, reference.y, reference.speed):
        at = interpolate(run, t, max_gap)
        if at is None:
            continue
        position.append(math.hypot(at[0] - x, at[1] - y))
        speed.append(abs(at[2] - v))
    return EntityAgreement(
        name, len(reference.t), len(position),
        statistics.median(position) if position else None,
        max(position) if position else None,
        statistics.median(speed) if speed else None)


def compare_tracks(run, reference, exclude=(), max_gap=MAX_GAP):
    """ScenarioAgreement of run tracks with reference tracks (both entity -> Track)."""
    exclude = set(exclude)
    entities = {name: compare_entity(name, run[name], ref, max_gap)
                for name, ref in sorted(reference.items()) if name in run}
    figure = [e for name, e in entities.items() if name not in exclude and e.compared]
    samples = sum(len(ref.t) for name, ref in reference.items() if name not in exclude)
    compared = sum(e.compared for name, e in entities.items() if name not in exclude)
    return ScenarioAgreement(
        entities=entities,
        missing=tuple(sorted(set(reference) - set(run))),
        extra=tuple(sorted(set(run) - set(reference))),
        excluded=tuple(sorted(exclude & set(reference))),
        position_error=statistics.median(e.median_position_error for e in figure)
        if figure else None,
        speed_error=statistics.median(e.median_speed_error for e in figure) if figure else None,
        max_position_error=max(e.max_position_error for e in figure) if figure else None,
        coverage=compared / samples if samples else 0.0)


def compare_files(run_path, reference_path, exclude=(), max_gap=MAX_GAP):
    return compare_tracks(read_tracks(run_path), read_tracks(reference_path), exclude, max_gap)


def _fmt(value, unit):
    return "-" if value is None else "%.3f %s" % (value, unit)


def report(agreement):
    lines = []
    for name, e in agreement.entities.items():
        lines.append("%-24s position %s (max %s), speed %s, coverage %.0f%%%s" % (
            name, _fmt(e.median_position_error, "m"), _fmt(e.max_position_error, "m"),
            _fmt(e.median_speed_error, "m/s"), 100 * e.coverage,
            " (excluded)" if name in agreement.excluded else ""))
    for name in agreement.missing:
        lines.append("%-24s missing from the run%s" % (
            name, " (excluded)" if name in agreement.excluded else ""))
    if agreement.extra:
        lines.append("not in the reference: %s" % ", ".join(agreement.extra))
    lines.append("scenario: position %s, speed %s, max %s, coverage %.0f%%" % (
        _fmt(agreement.position_error, "m"), _fmt(agreement.speed_error, "m/s"),
        _fmt(agreement.max_position_error, "m"), 100 * agreement.coverage))
    return "\n".join(lines)


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(description="tracks.csv against reference tracks")
    ap.add_argument("tracks")
    ap.add_argument("reference")
    ap.add_argument("--exclude", nargs="*", default=(), metavar="ENTITY")
    a = ap.parse_args(argv)
    try:
        print(report(compare_files(a.tracks, a.reference, a.exclude)))
    except (OSError, ValueError) as e:
        print("compare: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
