"""convoy_scenario.compare: a run's tracks against reference tracks, on synthetic tracks
(a shifted track gives the shift, a time offset shows in coverage and error, a missing
entity is reported, excluded entities stay out of the figure), and on files (tracks.csv and
a gzip'd reference)."""

import gzip
import math
import os
import tempfile
import unittest

from convoy_scenario import compare

HEADER = "t,entity,x,y,z,heading,speed,road,lane,s\n"


def straight(speed=10.0, t_end=10.0, dt=0.05, x0=0.0, y0=0.0, t0=0.0):
    """A Track driving along x at a constant speed, sampled every dt from t0."""
    n = int(round((t_end - t0) / dt)) + 1
    ts = tuple(round(t0 + k * dt, 6) for k in range(n))
    return compare.Track(ts, tuple(x0 + speed * t for t in ts), tuple(y0 for _ in ts),
                         tuple(speed for _ in ts))


def write_tracks(path, tracks, gz=False):
    rows = [HEADER]
    for name, tr in tracks.items():
        for t, x, y, v in zip(tr.t, tr.x, tr.y, tr.speed):
            rows.append("%.3f,%s,%.4f,%.4f,0,0,%.4f,1,-1,%.2f\n" % (t, name, x, y, v, x))
    opener = gzip.open if gz else open
    with opener(path, "wt") as f:
        f.write("".join(rows))


class Synthetic(unittest.TestCase):
    def test_identical_tracks_agree(self):
        ref = {"Ego": straight(), "Lead": straight(speed=5.0, y0=3.5)}
        a = compare.compare_tracks(ref, ref)
        self.assertEqual(a.position_error, 0.0)
        self.assertEqual(a.speed_error, 0.0)
        self.assertEqual(a.coverage, 1.0)
        self.assertEqual((a.missing, a.extra), ((), ()))

    def test_a_shifted_track_gives_the_shift(self):
        ref = {"Ego": straight()}
        run = {"Ego": straight(x0=0.3, y0=-0.4)}
        a = compare.compare_tracks(run, ref)
        self.assertAlmostEqual(a.position_error, 0.5, places=9)
        self.assertAlmostEqual(a.max_position_error, 0.5, places=9)
        self.assertAlmostEqual(a.speed_error, 0.0, places=9)
        self.assertTrue(a.within(0.5))
        self.assertFalse(a.within(0.49))

    def test_interpolates_the_run_at_the_reference_times(self):
        # run at 0.02 s steps starting at 0.01 s: compared at the reference's 0.05 s times
        ref = {"Ego": straight(t_end=4.0)}
        run = {"Ego": straight(t_end=4.01, dt=0.02, t0=0.01)}
        e = compare.compare_tracks(run, ref).entities["Ego"]
        self.assertAlmostEqual(e.median_position_error, 0.0, places=9)
        self.assertEqual(e.samples, 81)
        self.assertEqual(e.compared, 80)   # t = 0 is before the run's first step

    def test_a_time_offset_shows_in_coverage_and_error(self):
        # the run is the same motion 0.5 s late: 0.5 s * 10 m/s behind, over 9.5 of 10 s
        ref = {"Ego": straight(t_end=10.0)}
        late = straight(t_end=10.5, t0=0.5)
        run = {"Ego": compare.Track(late.t, tuple(x - 5.0 for x in late.x), late.y, late.speed)}
        a = compare.compare_tracks(run, ref)
        self.assertAlmostEqual(a.position_error, 5.0, places=6)
        self.assertAlmostEqual(a.coverage, 191 / 201)
        self.assertAlmostEqual(a.entities["Ego"].coverage, 191 / 201)

    def test_a_missing_entity_is_reported(self):
        ref = {"Ego": straight(), "Ghost": straight(y0=3.0)}
        run = {"Ego": straight(), "Extra": straight()}
        a = compare.compare_tracks(run, ref)
        self.assertEqual(a.missing, ("Ghost",))
        self.assertEqual(a.extra, ("Extra",))
        self.assertEqual(list(a.entities), ["Ego"])
        self.assertAlmostEqual(a.coverage, 0.5)
        self.assertEqual(a.position_error, 0.0)

    def test_excluded_entities_stay_out_of_the_figure(self):
        ref = {"Ego": straight(), "Npc": straight(y0=3.5), "Acc": straight(y0=7.0)}
        run = {"Ego": straight(x0=0.1), "Npc": straight(y0=3.5, x0=0.3),
               "Acc": straight(y0=7.0, x0=9.0)}
        a = compare.compare_tracks(run, ref, exclude={"Acc", "NotThere"})
        self.assertAlmostEqual(a.position_error, 0.2)   # median of 0.1 and 0.3
        self.assertAlmostEqual(a.max_position_error, 0.3)
        self.assertEqual(a.excluded, ("Acc",))
        self.assertAlmostEqual(a.entities["Acc"].median_position_error, 9.0)

    def test_speed_error(self):
        ref = {"Ego": straight(speed=10.0)}
        slow = straight(speed=10.0)
        run = {"Ego": compare.Track(slow.t, slow.x, slow.y, tuple(v - 0.25 for v in slow.speed))}
        self.assertAlmostEqual(compare.compare_tracks(run, ref).speed_error, 0.25)

    def test_no_interpolation_across_a_gap(self):
        ref = {"Ego": straight(t_end=10.0)}
        full = straight(t_end=10.0)
        keep = [i for i, t in enumerate(full.t) if not 2.0 < t < 6.0]
        run = {"Ego": compare.Track(*(tuple(col[i] for i in keep) for col in
                                      (full.t, full.x, full.y, full.speed)))}
        e = compare.compare_tracks(run, ref).entities["Ego"]
        self.assertEqual(e.compared, len(keep))
        self.assertEqual(compare.compare_tracks(run, ref, max_gap=5.0).entities["Ego"].compared,
                         201)

    def test_nothing_compared(self):
        a = compare.compare_tracks({}, {"Ego": straight()})
        self.assertIsNone(a.position_error)
        self.assertFalse(a.within(0.5))
        self.assertEqual(a.coverage, 0.0)


class Files(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_tracks_csv_against_a_gzip_reference(self):
        write_tracks(self.path("ref.csv.gz"), {"Ego": straight(), "Lead": straight(y0=3.5)},
                     gz=True)
        write_tracks(self.path("tracks.csv"), {"Ego": straight(y0=0.2),
                                               "Lead": straight(y0=3.5)})
        a = compare.compare_files(self.path("tracks.csv"), self.path("ref.csv.gz"))
        self.assertAlmostEqual(a.entities["Ego"].median_position_error, 0.2, places=4)
        self.assertAlmostEqual(a.position_error, 0.1, places=4)
        text = compare.report(a)
        self.assertIn("Ego", text)
        self.assertIn("scenario: position 0.100 m", text)

    def test_a_file_without_the_columns_is_named(self):
        with open(self.path("bad.csv"), "w") as f:
            f.write("time,name\n0,Ego\n")
        with self.assertRaisesRegex(ValueError, r"bad\.csv: no column .*speed"):
            compare.read_tracks(self.path("bad.csv"))

    def test_a_bad_number_names_file_and_line(self):
        with open(self.path("bad.csv"), "w") as f:
            f.write(HEADER + "0,Ego,1,2,0,0,3,,,\n0.05,Ego,x,2,0,0,3,,,\n")
        with self.assertRaisesRegex(ValueError, r"bad\.csv:3: not a number"):
            compare.read_tracks(self.path("bad.csv"))

    def test_the_committed_reference_reads(self):
        ref = os.path.join(os.path.dirname(__file__), "..", "..", "data", "esmini", "reference",
                           "cut-in.csv.gz")
        tracks = compare.read_tracks(ref)
        self.assertEqual(sorted(tracks), ["Ego", "OverTaker"])
        ego = tracks["Ego"]
        self.assertEqual(ego.t[0], 0.0)
        self.assertTrue(all(math.isclose(b - a, 0.05, abs_tol=1e-9)
                            for a, b in zip(ego.t, ego.t[1:])))
        self.assertEqual(compare.compare_tracks(tracks, tracks).position_error, 0.0)


if __name__ == "__main__":
    unittest.main()
