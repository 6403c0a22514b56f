"""The esmini reference recording (tools/esmini): reading esmini's CSV_Logger rows in blocks of
31 fields (entities spawned mid-run included), the compact reference format, the controller
detection that decides --disable_controllers, and the committed reference data's consistency
(manifest <-> files). esmini itself is not needed."""

import gzip
import json
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tools", "esmini"))
import esmini_csv  # noqa: E402
import xosc_info  # noqa: E402

from convoy_scenario import compare  # noqa: E402

ESMINI = os.path.join(REPO, "tests", "data", "esmini")


def block(name, eid, speed, x, y, heading, s, lane, collisions=""):
    """31 CSV_Logger fields of one entity."""
    f = [name, str(eid), "%f" % speed, "0", "0", "1.4", "0", "0.75", "5.04", "2", "1.5",
         "%f" % x, "%f" % y, "0.100000", "0", "0", "0", "0", "0", "0", "%f" % s, "-1.5",
         str(lane), "0", "%f" % heading, "0", "0", "0", "0", "0", collisions]
    assert len(f) == 31
    return f


def csv_logger_text(steps):
    head = ["esmini GIT REV: x", "esmini GIT TAG: ", "esmini GIT BRANCH: x",
            "esmini BUILD VERSION: x", "Scenario File Name: t.xosc", "Number of Vehicles: 1",
            "Index [-], TimeStamp [s], #1 Entity_Name [-], ..."]
    rows = []
    for k, (t, blocks) in enumerate(steps):
        rows.append(", ".join([str(k), "%f" % t] + [v for b in blocks for v in b]) + ", ")
    return "\n".join(head + rows) + "\n"


class EsminiCsv(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def write(self, name, text):
        path = os.path.join(self.tmp.name, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def test_blocks_of_31_with_an_entity_spawned_mid_run(self):
        path = self.write("run.csv", csv_logger_text([
            (0.0, [block("Ego", 0, 10, 0, 0, 0.0, 5, -1)]),
            (0.05, [block("Ego", 0, 10, 0.5, 0, 0.0, 5.5, -1),
                    block("swarm_0", 1, 20, 100, 3.5, 6.0, 100, -2, "0 2")])]))
        rows = esmini_csv.read_csv_logger(path)
        self.assertEqual([(r[0], r[1]) for r in rows],
                         [(0.0, "Ego"), (0.05, "Ego"), (0.05, "swarm_0")])
        t, name, x, y, z, heading, speed, lane, s = rows[2]
        self.assertEqual((x, y, z, heading, speed, lane, s), (100, 3.5, 0.1, 6.0, 20, -2, 100))
        self.assertEqual(esmini_csv.entities_in_order(rows), ["Ego", "swarm_0"])

    def test_a_row_not_in_blocks_of_31_names_file_and_line(self):
        text = csv_logger_text([(0.0, [block("Ego", 0, 10, 0, 0, 0.0, 5, -1)])])
        path = self.write("bad.csv", text.rstrip("\n").rsplit(",", 3)[0] + "\n")
        with self.assertRaisesRegex(ValueError,
                                    r"bad\.csv:8: \d+ fields, not 2 \+ a multiple of 31"):
            esmini_csv.read_csv_logger(path)

    def test_reference_format_rounds_and_wraps(self):
        rows = [(0.0, "Ego", 1.23456, -2.0049, 0.0, 6.2, 13.456789, -1, 50.0),
                (0.05, "Ego", 1.5, -2.0, -0.001, 3.5, 0.0, -1, 50.5),
                (0.1, "Ego", 2.0, -2.0, 0.0, 0.0, 1.0, -1, 51.0)]
        text = esmini_csv.format_rows(rows, {(0.05, "Ego"): "7"}, every=1)
        self.assertEqual(text.splitlines(), [
            "t,entity,x,y,z,heading,speed,road,lane,s",
            "0,Ego,1.23,-2,0,-0.083,13.46,,-1,50",
            "0.05,Ego,1.5,-2,0,-2.783,0,7,-1,50.5",
            "0.1,Ego,2,-2,0,0,1,,-1,51"])
        every2 = esmini_csv.format_rows(rows, {}, every=2).splitlines()
        self.assertEqual([line.split(",")[0] for line in every2[1:]], ["0", "0.1"])

    def test_gzip_is_deterministic(self):
        a = esmini_csv.gzip_bytes("t,entity\n0,Ego\n")
        self.assertEqual(a, esmini_csv.gzip_bytes("t,entity\n0,Ego\n"))
        self.assertEqual(gzip.decompress(a), b"t,entity\n0,Ego\n")

    def test_dat2csv_road_ids(self):
        path = self.write("rec.csv", "time, id, name, x, y, z, h, p, r, roadId, laneId\n"
                                     "0.050, 0, Ego, 1, 2, 0, 0, 0, 0, 12, -1\n")
        self.assertEqual(esmini_csv.read_dat2csv_roads(path), {(0.05, "Ego"): "12"})


class Controllers(unittest.TestCase):
    def info(self, name):
        return xosc_info.scenario_info(os.path.join(ESMINI, "xosc", name + ".xosc"))

    def test_an_interactive_ego_is_detected_through_the_catalog(self):
        info = self.info("cut-in_interactive")
        self.assertEqual(info["controllers"], {"Ego": ["InteractiveController"]})
        self.assertTrue(xosc_info.has_input_controller(info))
        self.assertEqual(xosc_info.figure_entities(info), ["Ego", "OverTaker"])

    def test_a_driver_model_is_left_out_of_the_figure(self):
        info = self.info("acc-test")
        self.assertFalse(xosc_info.has_input_controller(info))
        self.assertEqual(xosc_info.figure_entities(info), ["Target"])

    def test_a_distribution_names_its_scenario(self):
        self.assertEqual(self.info("cut-in_parameter_set")["distribution"], "cut-in.xosc")


class CommittedReference(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(ESMINI, "reference", "manifest.json")) as f:
            cls.manifest = json.load(f)

    def test_every_example_is_in_the_manifest(self):
        names = sorted(f[:-5] for f in os.listdir(os.path.join(ESMINI, "xosc"))
                       if f.endswith(".xosc"))
        self.assertEqual(len(names), 69)
        self.assertEqual(sorted(self.manifest["scenarios"]), names)
        skipped = [n for n, e in self.manifest["scenarios"].items() if "skipped" in e]
        self.assertEqual(skipped, ["car_walk"])

    def test_the_files_match_the_manifest(self):
        for name, entry in self.manifest["scenarios"].items():
            for variant in entry.get("variants", [entry] if "reference" in entry else []):
                with self.subTest(scenario=name, reference=variant["reference"]):
                    tracks = compare.read_tracks(os.path.join(ESMINI, "reference",
                                                              variant["reference"]))
                    self.assertEqual(sorted(tracks), sorted(variant["entities"]))
                    self.assertAlmostEqual(max(t.t[-1] for t in tracks.values()),
                                           variant["end_time"], places=6)
                    self.assertLessEqual(set(entry["figure_entities"]), set(tracks))

    def test_input_controllers_were_disabled(self):
        for name, entry in self.manifest["scenarios"].items():
            with self.subTest(scenario=name):
                inputs = any(k in xosc_info.INPUT_CONTROLLERS
                             for kinds in entry["controllers"].values() for k in kinds)
                self.assertEqual(entry["disable_controllers"], inputs)
                self.assertEqual("--disable_controllers" in entry["esmini_args"], inputs)


if __name__ == "__main__":
    unittest.main()
