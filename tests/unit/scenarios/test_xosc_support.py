"""Helpers of the test_xosc_* and test_conditions_* tests (no tests here): small inline
scenarios on straight.xodr read with loads(), and a world-state builder.

Run them: cd tests/unit/scenarios && PYTHONPATH=../../../python /usr/bin/python3 -m unittest
discover -p 'test_*.py'."""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(HERE))), "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)

from convoy_scenario import loads  # noqa: E402

PATH = os.path.join(HERE, "generated.xosc")

VEHICLE = '''<Vehicle name="car" vehicleCategory="car">
        <BoundingBox><Center x="1.4" y="0" z="0.8"/><Dimensions width="2" length="5" height="1.5"/></BoundingBox>
        <Performance maxSpeed="70" maxAcceleration="5" maxDeceleration="10"/>
      </Vehicle>'''


def text(init="", story="", entities=None, params="", header="", catalogs="", network="",
         variables="", stop=""):
    """An OpenSCENARIO text: entities Ego and Target (inline cars) unless entities is given;
    story: the Story's content (Acts)."""
    if entities is None:
        entities = "".join('<ScenarioObject name="%s">%s</ScenarioObject>' % (n, VEHICLE)
                           for n in ("Ego", "Target"))
    return '''<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="t" author="c">%s</FileHeader>
  <ParameterDeclarations>%s</ParameterDeclarations>
  %s
  <CatalogLocations>%s</CatalogLocations>
  <RoadNetwork><LogicFile filepath="straight.xodr"/>%s</RoadNetwork>
  <Entities>%s</Entities>
  <Storyboard>
    <Init><Actions>%s</Actions></Init>
    %s
    %s
  </Storyboard>
</OpenSCENARIO>''' % (header, params, variables, catalogs, network, entities, init,
                      '<Story name="S">%s</Story>' % story if story else "", stop)


def load_text(path=PATH, **kw):
    return loads(text(**kw), path)


def private(action, entity="Ego"):
    return '<Private entityRef="%s"><PrivateAction>%s</PrivateAction></Private>' % (entity,
                                                                                    action)


def act(actions, actors=("Target",), start="", select=False, name="A", event_start="",
        maneuver="M", extra=""):
    """One Act with one ManeuverGroup (actors), one Maneuver and one Event of actions
    ([(name, <PrivateAction>/<GlobalAction> xml)])."""
    refs = "".join('<EntityRef entityRef="%s"/>' % a for a in actors)
    acts = "".join('<Action name="%s">%s</Action>' % a for a in actions)
    return '''<Act name="%s">
      <ManeuverGroup name="G" maximumExecutionCount="1">
        <Actors selectTriggeringEntities="%s">%s</Actors>%s
        <Maneuver name="%s"><Event name="E" priority="overwrite">%s%s</Event></Maneuver>
      </ManeuverGroup>%s
    </Act>''' % (name, "true" if select else "false", refs, extra, maneuver, acts,
                 event_start, start)


def world(names=("Ego", "Target"), **extra):
    """A world state for the Storyboard: every entity at rest on lane -1 of road 1, s = x;
    extra: {name: {key: value}} overrides."""
    out = {}
    for i, n in enumerate(names):
        out[n] = {"x": 20.0 * i, "y": -1.75, "yaw": 0.0, "speed": 0.0, "ax": 0.0, "ay": 0.0,
                  "road": "1", "lane": -1, "s": 20.0 * i, "t": 0.0, "odometer": 0.0,
                  "collisions": [], "offroad": False, "end_of_road": False}
        out[n].update(extra.get(n, {}))
    return out
