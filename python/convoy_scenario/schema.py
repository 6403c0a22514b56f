"""The supported subset of OpenSCENARIO 1.x as a table: for each element, the attributes and
the child elements it may have. The reader checks every element of a file (and of the
catalog files it uses) against it before reading, so anything outside the subset ends the
load with the element and its line named.

Attributes that are accepted but have no effect here are listed in IGNORED (docs/scenarios.md).
"""

from .xmltree import ScenarioError
from .schema_more import MORE

from .model_positions import POSITION_TAGS as _POSITION
_CATALOG_KINDS = ("VehicleCatalog", "PedestrianCatalog", "ControllerCatalog", "MiscObjectCatalog",
                  "EnvironmentCatalog", "ManeuverCatalog", "TrajectoryCatalog", "RouteCatalog")
_DISTANCE = ("value", "freespace", "rule", "relativeDistanceType", "coordinateSystem",
             "alongRoute")

# element -> (attributes, children)
SCHEMA = {
    "OpenSCENARIO": ((), ("FileHeader", "ParameterDeclarations", "VariableDeclarations",
                          "CatalogLocations", "RoadNetwork", "Entities", "Storyboard", "Catalog",
                          "ParameterValueDistribution")),
    "FileHeader": (("revMajor", "revMinor", "date", "description", "author"),
                   ("License", "Properties")),
    "ParameterDeclarations": ((), ("ParameterDeclaration",)),
    "ParameterDeclaration": (("name", "parameterType", "value"), ()),
    "CatalogLocations": ((), _CATALOG_KINDS),
    "Directory": (("path",), ()),
    "RoadNetwork": ((), ("LogicFile", "SceneGraphFile", "TrafficSignals")),
    "LogicFile": (("filepath",), ()),
    "SceneGraphFile": (("filepath",), ()),
    "Catalog": (("name",), ("Vehicle", "Pedestrian", "MiscObject", "Controller", "Environment",
                            "Maneuver", "Trajectory", "Route")),
    "Entities": ((), ("ScenarioObject",)),
    "ScenarioObject": (("name",), ("Vehicle", "Pedestrian", "MiscObject", "CatalogReference",
                                   "ObjectController")),
    "Vehicle": (("name", "vehicleCategory", "model3d", "mass", "role"),
                ("ParameterDeclarations", "BoundingBox", "Performance", "Axles", "Properties",
                 "TrailerHitch", "TrailerCoupler", "Trailer")),
    "Pedestrian": (("name", "model", "mass", "pedestrianCategory", "model3d", "role"),
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
    "ManeuverGroup": (("name", "maximumExecutionCount"), ("Actors", "Maneuver",
                                                           "CatalogReference")),
    "Actors": (("selectTriggeringEntities",), ("EntityRef",)),
    "EntityRef": (("entityRef",), ()),
    "Maneuver": (("name",), ("ParameterDeclarations", "Event")),
    "Event": (("name", "priority", "maximumExecutionCount"), ("Action", "StartTrigger")),
    "Action": (("name",), ("GlobalAction", "PrivateAction")),
    # actions
    "GlobalAction": ((), ("EnvironmentAction", "ParameterAction",
                          "InfrastructureAction", "TrafficAction", "VariableAction")),
    "EnvironmentAction": ((), ("Environment", "CatalogReference")),
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
    "PrivateAction": ((), ("LongitudinalAction", "LateralAction", "VisibilityAction",
                           "SynchronizeAction", "ActivateControllerAction", "ControllerAction",
                           "TeleportAction", "RoutingAction", "AppearanceAction",
                           "TrailerAction")),
    "LongitudinalAction": ((), ("SpeedAction", "LongitudinalDistanceAction",
                                "SpeedProfileAction")),
    "SpeedAction": ((), ("SpeedActionDynamics", "SpeedActionTarget")),
    "SpeedActionDynamics": (("dynamicsShape", "dynamicsDimension", "value"), ()),
    "SpeedActionTarget": ((), ("AbsoluteTargetSpeed", "RelativeTargetSpeed")),
    "AbsoluteTargetSpeed": (("value",), ()),
    "RelativeTargetSpeed": (("entityRef", "value", "speedTargetValueType", "continuous"), ()),
    "LateralAction": ((), ("LaneChangeAction", "LaneOffsetAction", "LateralDistanceAction")),
    "LaneChangeAction": (("targetLaneOffset",), ("LaneChangeActionDynamics",
                                                 "LaneChangeTarget")),
    "LaneChangeActionDynamics": (("dynamicsShape", "dynamicsDimension", "value"), ()),
    "LaneChangeTarget": ((), ("RelativeTargetLane", "AbsoluteTargetLane")),
    "RelativeTargetLane": (("entityRef", "value"), ()),
    "AbsoluteTargetLane": (("value",), ()),
    "RoutingAction": ((), ("AssignRouteAction", "FollowTrajectoryAction",
                           "AcquirePositionAction")),
    "AssignRouteAction": ((), ("Route", "CatalogReference")),
    "Route": (("name", "closed"), ("ParameterDeclarations", "Waypoint")),
    "Waypoint": (("routeStrategy",), ("Position",)),
    "FollowTrajectoryAction": (("initialDistanceOffset",),
                               ("Trajectory", "TrajectoryRef", "CatalogReference",
                                "TimeReference", "TrajectoryFollowingMode")),
    "TrajectoryRef": ((), ("Trajectory", "CatalogReference")),
    "Trajectory": (("name", "closed"), ("ParameterDeclarations", "Shape")),
    "Shape": ((), ("Polyline", "Clothoid", "ClothoidSpline", "Nurbs")),
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
                             "DistanceCondition", "SpeedCondition", "EndOfRoadCondition",
                             "CollisionCondition", "OffroadCondition", "AccelerationCondition",
                             "StandStillCondition", "RelativeSpeedCondition",
                             "TraveledDistanceCondition", "RelativeClearanceCondition")),
    "ByValueCondition": ((), ("SimulationTimeCondition", "StoryboardElementStateCondition",
                              "ParameterCondition", "TimeOfDayCondition",
                              "TrafficSignalCondition",
                              "TrafficSignalControllerCondition", "VariableCondition")),
    "SimulationTimeCondition": (("value", "rule"), ()),
    "StoryboardElementStateCondition": (("storyboardElementType", "storyboardElementRef",
                                         "state"), ()),
    "RelativeDistanceCondition": (("entityRef",) + _DISTANCE, ()),
    "TimeHeadwayCondition": (("entityRef",) + _DISTANCE, ()),
    "TimeToCollisionCondition": (_DISTANCE, ("TimeToCollisionConditionTarget",)),
    "TimeToCollisionConditionTarget": ((), ("EntityRef", "Position")),
    "ReachPositionCondition": (("tolerance",), ("Position",)),
    "DistanceCondition": (_DISTANCE, ("Position",)),
    "SpeedCondition": (("value", "rule", "direction"), ()),
}
SCHEMA.update(MORE)
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
