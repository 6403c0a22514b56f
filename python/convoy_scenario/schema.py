"""The supported subset of OpenSCENARIO 1.x as a table: for each element, the attributes and
the child elements it may have. The reader checks every element of a file (and of the
catalog files it uses) against it before reading, so anything outside the subset ends the
load with the element and its line named.

Attributes that are accepted but have no effect here are listed in IGNORED (docs/scenarios.md).
"""

from .xmltree import ScenarioError

_POSITION = ("WorldPosition", "LanePosition")
_CATALOG_KINDS = ("VehicleCatalog", "PedestrianCatalog", "ControllerCatalog", "MiscObjectCatalog",
                  "EnvironmentCatalog", "ManeuverCatalog", "TrajectoryCatalog", "RouteCatalog")
_DISTANCE = ("value", "freespace", "rule", "relativeDistanceType", "coordinateSystem",
             "alongRoute")

# element -> (attributes, children)
SCHEMA = {
    "OpenSCENARIO": ((), ("FileHeader", "ParameterDeclarations", "CatalogLocations",
                          "RoadNetwork", "Entities", "Storyboard", "Catalog")),
    "FileHeader": (("revMajor", "revMinor", "date", "description", "author"), ()),
    "ParameterDeclarations": ((), ("ParameterDeclaration",)),
    "ParameterDeclaration": (("name", "parameterType", "value"), ()),
    "CatalogLocations": ((), _CATALOG_KINDS),
    "Directory": (("path",), ()),
    "RoadNetwork": ((), ("LogicFile", "SceneGraphFile")),
    "LogicFile": (("filepath",), ()),
    "SceneGraphFile": (("filepath",), ()),
    "Catalog": (("name",), ("Vehicle", "Pedestrian")),
    "Entities": ((), ("ScenarioObject",)),
    "ScenarioObject": (("name",), ("Vehicle", "Pedestrian", "CatalogReference")),
    "Vehicle": (("name", "vehicleCategory", "model3d", "mass"),
                ("ParameterDeclarations", "BoundingBox", "Performance", "Axles", "Properties")),
    "Pedestrian": (("name", "model", "mass", "pedestrianCategory", "model3d"),
                   ("ParameterDeclarations", "BoundingBox", "Properties")),
    "BoundingBox": ((), ("Center", "Dimensions")),
    "Center": (("x", "y", "z"), ()),
    "Dimensions": (("width", "length", "height"), ()),
    "Performance": (("maxSpeed", "maxAcceleration", "maxDeceleration"), ()),
    "Axles": ((), ("FrontAxle", "RearAxle", "AdditionalAxle")),
    "FrontAxle": (("maxSteering", "wheelDiameter", "trackWidth", "positionX", "positionZ"), ()),
    "RearAxle": (("maxSteering", "wheelDiameter", "trackWidth", "positionX", "positionZ"), ()),
    "AdditionalAxle": (("maxSteering", "wheelDiameter", "trackWidth", "positionX", "positionZ"),
                       ()),
    "Properties": ((), ("Property", "File")),
    "Property": (("name", "value"), ()),
    "File": (("filepath",), ()),
    "CatalogReference": (("catalogName", "entryName"), ("ParameterAssignments",)),
    "ParameterAssignments": ((), ("ParameterAssignment",)),
    "ParameterAssignment": (("parameterRef", "value"), ()),
    # storyboard
    "Storyboard": ((), ("Init", "Story", "StopTrigger")),
    "Init": ((), ("Actions",)),
    "Actions": ((), ("GlobalAction", "Private")),
    "Private": (("entityRef",), ("PrivateAction",)),
    "Story": (("name",), ("ParameterDeclarations", "Act")),
    "Act": (("name",), ("ManeuverGroup", "StartTrigger", "StopTrigger")),
    "ManeuverGroup": (("name", "maximumExecutionCount"), ("Actors", "Maneuver")),
    "Actors": (("selectTriggeringEntities",), ("EntityRef",)),
    "EntityRef": (("entityRef",), ()),
    "Maneuver": (("name",), ("ParameterDeclarations", "Event")),
    "Event": (("name", "priority", "maximumExecutionCount"), ("Action", "StartTrigger")),
    "Action": (("name",), ("GlobalAction", "PrivateAction")),
    # actions
    "GlobalAction": ((), ("EnvironmentAction",)),
    "EnvironmentAction": ((), ("Environment",)),
    "Environment": (("name",), ("ParameterDeclarations", "TimeOfDay", "Weather",
                                "RoadCondition")),
    "TimeOfDay": (("animation", "dateTime"), ()),
    "Weather": (("cloudState", "fractionalCloudCover", "temperature", "atmosphericPressure"),
                ("Sun", "Fog", "Precipitation", "Wind")),
    "Sun": (("azimuth", "elevation", "intensity", "illuminance"), ()),
    "Fog": (("visualRange",), ()),
    "Precipitation": (("precipitationType", "intensity", "precipitationIntensity"), ()),
    "Wind": (("direction", "speed"), ()),
    "RoadCondition": (("frictionScaleFactor",), ()),
    "PrivateAction": ((), ("LongitudinalAction", "LateralAction", "RoutingAction",
                           "TeleportAction")),
    "LongitudinalAction": ((), ("SpeedAction",)),
    "SpeedAction": ((), ("SpeedActionDynamics", "SpeedActionTarget")),
    "SpeedActionDynamics": (("dynamicsShape", "dynamicsDimension", "value"), ()),
    "SpeedActionTarget": ((), ("AbsoluteTargetSpeed", "RelativeTargetSpeed")),
    "AbsoluteTargetSpeed": (("value",), ()),
    "RelativeTargetSpeed": (("entityRef", "value", "speedTargetValueType", "continuous"), ()),
    "LateralAction": ((), ("LaneChangeAction",)),
    "LaneChangeAction": (("targetLaneOffset",), ("LaneChangeActionDynamics",
                                                 "LaneChangeTarget")),
    "LaneChangeActionDynamics": (("dynamicsShape", "dynamicsDimension", "value"), ()),
    "LaneChangeTarget": ((), ("RelativeTargetLane", "AbsoluteTargetLane")),
    "RelativeTargetLane": (("entityRef", "value"), ()),
    "AbsoluteTargetLane": (("value",), ()),
    "RoutingAction": ((), ("AssignRouteAction", "FollowTrajectoryAction")),
    "AssignRouteAction": ((), ("Route",)),
    "Route": (("name", "closed"), ("ParameterDeclarations", "Waypoint")),
    "Waypoint": (("routeStrategy",), ("Position",)),
    "FollowTrajectoryAction": ((), ("Trajectory", "TrajectoryRef", "TimeReference",
                                    "TrajectoryFollowingMode")),
    "TrajectoryRef": ((), ("Trajectory",)),
    "Trajectory": (("name", "closed"), ("ParameterDeclarations", "Shape")),
    "Shape": ((), ("Polyline",)),
    "Polyline": ((), ("Vertex",)),
    "Vertex": (("time",), ("Position",)),
    "TimeReference": ((), ("None", "Timing")),
    "None": ((), ()),
    "Timing": (("domainAbsoluteRelative", "scale", "offset"), ()),
    "TrajectoryFollowingMode": (("followingMode",), ()),
    "TeleportAction": ((), ("Position",)),
    "Position": ((), _POSITION),
    "WorldPosition": (("x", "y", "z", "h", "p", "r"), ()),
    "LanePosition": (("roadId", "laneId", "s", "offset"), ("Orientation",)),
    "Orientation": (("type", "h", "p", "r"), ()),
    # triggers and conditions
    "StartTrigger": ((), ("ConditionGroup",)),
    "StopTrigger": ((), ("ConditionGroup",)),
    "ConditionGroup": ((), ("Condition",)),
    "Condition": (("name", "delay", "conditionEdge"), ("ByEntityCondition", "ByValueCondition")),
    "ByEntityCondition": ((), ("TriggeringEntities", "EntityCondition")),
    "TriggeringEntities": (("triggeringEntitiesRule",), ("EntityRef",)),
    "EntityCondition": ((), ("RelativeDistanceCondition", "TimeToCollisionCondition",
                             "TimeHeadwayCondition", "ReachPositionCondition",
                             "DistanceCondition", "SpeedCondition")),
    "ByValueCondition": ((), ("SimulationTimeCondition", "StoryboardElementStateCondition")),
    "SimulationTimeCondition": (("value", "rule"), ()),
    "StoryboardElementStateCondition": (("storyboardElementType", "storyboardElementRef",
                                         "state"), ()),
    "RelativeDistanceCondition": (("entityRef",) + _DISTANCE, ()),
    "TimeHeadwayCondition": (("entityRef",) + _DISTANCE, ()),
    "TimeToCollisionCondition": (_DISTANCE, ("TimeToCollisionConditionTarget",)),
    "TimeToCollisionConditionTarget": ((), ("EntityRef",)),
    "ReachPositionCondition": (("tolerance",), ("Position",)),
    "DistanceCondition": (_DISTANCE, ("Position",)),
    "SpeedCondition": (("value", "rule"), ()),
}
for _kind in _CATALOG_KINDS:
    SCHEMA[_kind] = ((), ("Directory",))

# Accepted, read, and without effect on the executor (they are kept on the objects or
# documented as dropped).
IGNORED = {"Vehicle": ("model3d", "mass"), "Pedestrian": ("model3d",),
           "Weather": ("cloudState", "fractionalCloudCover", "temperature",
                       "atmosphericPressure")}


def check(node, parent=None):
    """Raise ScenarioError at the first element (in document order) or attribute outside
    the subset."""
    entry = SCHEMA.get(node.tag)
    if entry is None or (parent is not None and node.tag not in SCHEMA[parent.tag][1]):
        where = "<%s>" % parent.tag if parent is not None else "the file"
        allowed = SCHEMA[parent.tag][1] if parent is not None else ("OpenSCENARIO",)
        raise ScenarioError("%s: <%s> is not supported in %s (supported here: %s)" % (
            node.where(), node.tag, where, ", ".join(allowed) or "nothing"))
    attrs, _ = entry
    for name in node.attrib:
        if node.tag == "OpenSCENARIO" and (":" in name or name.startswith("xmlns")):
            continue
        if name not in attrs:
            raise ScenarioError("%s: <%s> attribute %s is not supported (supported: %s)" % (
                node.where(), node.tag, name, ", ".join(attrs) or "none"))
    if node.text.strip():
        raise node.error("has text %r; OpenSCENARIO values are attributes" % node.text.strip()[:20])
    for child in node.children:
        check(child, node)
