"""Every esmini example scenario (tests/data/esmini/xosc, helper B's copies of esmini's
resources/xosc with its catalogs and maps) is read; car_walk's catalog is not shipped with
esmini, and its error names the catalog path and the element. Skipped without the copies."""

import glob
import os
import unittest

from test_xosc_support import HERE

from convoy_scenario import ScenarioError, Storyboard, load

ESMINI = os.path.join(os.path.dirname(os.path.dirname(HERE)), "data", "esmini", "xosc")


@unittest.skipUnless(os.path.isdir(ESMINI), "no esmini examples in %s" % ESMINI)
class EsminiExamples(unittest.TestCase):
    def test_all_but_car_walk_load(self):
        files = sorted(glob.glob(os.path.join(ESMINI, "*.xosc")))
        self.assertEqual(len(files), 69)
        failed = {}
        for f in files:
            try:
                scenario = load(f)
                Storyboard(scenario)
            except ScenarioError as e:
                failed[os.path.basename(f)] = str(e)
        self.assertEqual(sorted(failed), ["car_walk.xosc"], failed)
        self.assertEqual(failed["car_walk.xosc"],
                         "car_walk.xosc:15: <CatalogReference> catalogName: "
                         "'openx_assets_3d.catalog': the catalog directory "
                         "/tmp/openx-assets/catalogs (car_walk.xosc:6) does not exist")

    def test_a_distribution_file_reads_its_first_variant(self):
        s = load(os.path.join(ESMINI, "cut-in_parameter_set.xosc"))
        self.assertEqual(os.path.basename(s.path), "cut-in.xosc")
        params = dict(s.parameters)
        self.assertEqual((params["HostVehicle"], params["TargetVehicle"], params["EgoSpeed"]),
                         ("car_blue", "car_yellow", 70.0))
        self.assertAlmostEqual(params["TargetSpeedFactor"], 1.1)


if __name__ == "__main__":
    unittest.main()
