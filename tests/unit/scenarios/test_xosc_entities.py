"""The reader on issue 25's file and entity elements: FileHeader License and Properties,
ObjectController / Controller (inline and from a ControllerCatalog), MiscObject (and its
catalog), trailers, Vehicle role, catalogs found by file name or in esmini's layout,
ParameterAssignment parameterRef="$name", a name declared twice."""

import os
import shutil
import tempfile
import unittest

from test_xosc_support import PATH, VEHICLE, load_text, text

from convoy_scenario import ScenarioError, load, loads
from convoy_scenario import model as m

CONTROLLERS = '''<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="0" date="2020-01-01T00:00:00" description="c" author="a"/>
  <Catalog name="ControllerCatalog">
    <Controller name="acc">
      <ParameterDeclarations>
        <ParameterDeclaration name="TimeGap" parameterType="double" value="1.5"/>
        <ParameterDeclaration name="Mode" parameterType="double" value="time"/>
      </ParameterDeclarations>
      <Properties><Property name="timeGap" value="$TimeGap"/><Property name="mode" value="$Mode"/>
        <Property name="speed" value="$GlobalSpeed"/></Properties>
    </Controller>
  </Catalog>
</OpenSCENARIO>'''

MISC = '''<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="0" date="2020-01-01T00:00:00" description="c" author="a"/>
  <Catalog name="MiscObject">
    <MiscObject name="cone" miscObjectCategory="obstacle" mass="2">
      <ParameterDeclarations/>
      <BoundingBox><Center x="0" y="0" z="0.3"/><Dimensions width="0.3" length="0.3" height="0.6"/></BoundingBox>
    </MiscObject>
  </Catalog>
</OpenSCENARIO>'''


class Entities(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, self.tmp)
        shutil.copy(os.path.join(os.path.dirname(PATH), "straight.xodr"), self.tmp)
        os.makedirs(os.path.join(self.tmp, "Catalogs", "Controllers"))
        os.makedirs(os.path.join(self.tmp, "Catalogs", "MiscObjects"))
        with open(os.path.join(self.tmp, "Catalogs", "Controllers", "ControllerCatalog.xosc"),
                  "w") as f:
            f.write(CONTROLLERS)
        with open(os.path.join(self.tmp, "Catalogs", "MiscObjects", "MiscObjectCatalog.xosc"),
                  "w") as f:
            f.write(MISC)
        self.path = os.path.join(self.tmp, "s.xosc")

    def test_header_license_and_properties(self):
        s = load_text(header='<License name="MPL-2.0" spdxId="MPL-2.0"/><Properties>'
                             '<Property name="k" value="v"/></Properties>')
        self.assertEqual(s.header.license, ("MPL-2.0", "", "MPL-2.0", ""))
        self.assertEqual(s.header.properties, (("k", "v"),))

    def test_object_controllers_inline_and_from_a_catalog(self):
        ents = ('<ScenarioObject name="Ego">%s<ObjectController><Controller name="drv" '
                'controllerType="movement"><Properties><Property name="a" value="1"/>'
                '</Properties></Controller></ObjectController></ScenarioObject>'
                '<ScenarioObject name="Target">%s<ObjectController><CatalogReference '
                'catalogName="ControllerCatalog" entryName="acc"><ParameterAssignments>'
                '<ParameterAssignment parameterRef="$TimeGap" value="2"/>'
                '</ParameterAssignments></CatalogReference></ObjectController>'
                '</ScenarioObject>') % (VEHICLE, VEHICLE)
        # the controller directory is given in esmini's layout (../xosc/Controllers, absent
        # here): Catalogs/Controllers beside the scenario is used
        s = loads(text(entities=ents, params='<ParameterDeclaration name="GlobalSpeed" '
                                             'parameterType="double" value="20"/>',
                       catalogs='<ControllerCatalog><Directory path="../xosc/Controllers"/>'
                                '</ControllerCatalog>'), self.path)
        ego, target = s.entity("Ego"), s.entity("Target")
        self.assertEqual(ego.controllers, (("drv", m.Controller("drv", "movement",
                                                                (("a", "1"),))),))
        name, ctrl = target.controllers[0]
        self.assertEqual(name, "acc")
        # the assignment ($TimeGap: esmini's form), the text of a double "time" kept
        # (esmini does not check types), a global parameter seen from the catalog
        self.assertEqual(ctrl.properties, (("timeGap", "2"), ("mode", "time"), ("speed", "20")))
        self.assertEqual(ctrl.catalog.entry, "acc")

    def test_misc_object_from_a_catalog_named_by_its_file(self):
        ents = ('<ScenarioObject name="Ego">%s</ScenarioObject><ScenarioObject name="Cone">'
                '<CatalogReference catalogName="MiscObjectCatalog" entryName="cone"/>'
                '</ScenarioObject>') % VEHICLE
        s = loads(text(entities=ents, catalogs='<MiscObjectCatalog><Directory '
                       'path="Catalogs/MiscObjects"/></MiscObjectCatalog>'), self.path)
        cone = s.entity("Cone")
        self.assertEqual(cone.kind, "misc")
        self.assertEqual((cone.object.category, cone.object.mass), ("obstacle", 2.0))

    def test_trailers(self):
        truck = VEHICLE.replace('</Vehicle>', '<TrailerHitch dx="-1.2"/><Trailer><TrailerRef '
                                'entityRef="Cart"/></Trailer></Vehicle>').replace(
            'vehicleCategory="car"', 'vehicleCategory="truck" role="police"')
        cart = VEHICLE.replace('</Vehicle>', '<TrailerCoupler dx="3.2"/></Vehicle>')
        ents = ('<ScenarioObject name="Ego">%s</ScenarioObject>'
                '<ScenarioObject name="Cart">%s</ScenarioObject>') % (truck, cart)
        s = load_text(entities=ents)
        ego = s.entity("Ego").object
        self.assertEqual((ego.trailer_hitch, ego.trailer, ego.role),
                         (-1.2, m.Trailer(entity="Cart"), "police"))
        self.assertEqual(s.entity("Cart").object.trailer_coupler, 3.2)
        with self.assertRaises(ScenarioError) as e:
            load_text(entities=ents.replace('entityRef="Cart"', 'entityRef="Kart"'))
        self.assertIn("<TrailerRef> entityRef: no entity 'Kart' (entities: Ego, Cart)",
                      str(e.exception))
        empty = load_text(entities=ents.replace('entityRef="Cart"', 'entityRef=""'))
        self.assertIsNone(empty.entity("Ego").object.trailer)

    def test_a_parameter_declared_twice_takes_the_later(self):
        s = load_text(params='<ParameterDeclaration name="a" parameterType="double" value="1"/>'
                             '<ParameterDeclaration name="a" parameterType="double" value="2"/>')
        self.assertEqual(dict(s.parameters)["a"], 2.0)

    def test_missing_catalog_names_path_and_element(self):
        ents = ('<ScenarioObject name="Ego"><CatalogReference catalogName="x" entryName="y"/>'
                '</ScenarioObject>')
        with self.assertRaises(ScenarioError) as e:
            loads(text(entities=ents, catalogs='<VehicleCatalog><Directory path="/no/such/dir"/>'
                                               '</VehicleCatalog>'), self.path)
        self.assertEqual(str(e.exception), "s.xosc:8: <CatalogReference> catalogName: 'x': the "
                         "catalog directory /no/such/dir (s.xosc:6) does not exist")

    def test_logic_file_found_by_name_beside_the_scenario(self):
        s = loads(text().replace('filepath="straight.xodr"', 'filepath="c:/maps/straight.xodr"'),
                  self.path)
        self.assertEqual(s.logic_file, os.path.join(self.tmp, "straight.xodr"))
        with self.assertRaises(ScenarioError):
            load(os.path.join(self.tmp, "none.xosc"))


if __name__ == "__main__":
    unittest.main()
