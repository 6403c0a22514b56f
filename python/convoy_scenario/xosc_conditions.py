"""Triggers and conditions for the reader (xosc.py)."""

from . import model as m
from . import schema
from .xosc_actions import DISTANCE_SYSTEMS

RULES = ("greaterThan", "lessThan", "equalTo", "greaterOrEqual", "lessOrEqual", "notEqualTo")
ELEMENT_TYPES = ("story", "act", "maneuverGroup", "maneuver", "event", "action")
STATES = ("standbyState", "runningState", "completeState", "startTransition", "endTransition",
          "stopTransition", "skipTransition")
DIRECTIONS = ("longitudinal", "lateral", "vertical")
BY_VALUE = ("SimulationTimeCondition", "StoryboardElementStateCondition", "ParameterCondition",
            "VariableCondition", "TimeOfDayCondition", "TrafficSignalCondition",
            "TrafficSignalControllerCondition")


class ConditionsReader:
    def trigger(self, node, scope):
        """A Trigger, or None for no trigger (an empty <StartTrigger/> or <StopTrigger/> is
        none: a StartTrigger without conditions is true at once, a StopTrigger never)."""
        if node is None:
            return None
        groups = []
        for g in node.findall("ConditionGroup"):
            conds = tuple(self.condition(c, scope) for c in g.findall("Condition"))
            if not conds:
                raise g.error("needs at least one <Condition>")
            groups.append(conds)
        return m.Trigger(tuple(groups)) if groups else None

    def rule(self, node, scope):
        return self.value(node, "rule", scope, "enum", choices=RULES)

    def distance_common(self, node, scope, types, systems=DISTANCE_SYSTEMS):
        """(value, freespace, relativeDistanceType, rule, coordinateSystem, alongRoute)."""
        dtype = self.value(node, "relativeDistanceType", scope, "enum", types[0], types)
        system = self.value(node, "coordinateSystem", scope, "enum", "entity", DISTANCE_SYSTEMS)
        along = self.boolean(node, "alongRoute", scope, False)
        if along and "coordinateSystem" not in node.attrib:
            system = "road"   # 1.0's alongRoute: measured along the road
        return (self.number(node, "value", scope, minimum=0),
                self.boolean(node, "freespace", scope), dtype, self.rule(node, scope), system,
                along)

    def condition(self, node, scope):
        name = self.value(node, "name", scope)
        delay = self.number(node, "delay", scope, 0.0, minimum=0)
        edge = self.value(node, "conditionEdge", scope, "enum",
                          choices=("rising", "falling", "risingOrFalling", "none"))
        child = node.only_child(("ByEntityCondition", "ByValueCondition"))
        triggering, trule = (), "any"
        if child.tag == "ByValueCondition":
            test = self.value_condition(child.only_child(BY_VALUE), scope)
        else:
            te = child.need("TriggeringEntities")
            trule = self.value(te, "triggeringEntitiesRule", scope, "enum",
                               choices=("any", "all"))
            triggering = tuple(self.entity_ref(e, scope) for e in te.findall("EntityRef"))
            if not triggering:
                raise te.error("needs at least one <EntityRef>")
            ec = child.need("EntityCondition")
            c = ec.only_child(schema.SCHEMA["EntityCondition"][1])
            test = self.entity_condition(c, scope)
        return m.Condition(name, delay, edge, test, triggering, trule, node.where())

    def value_condition(self, c, scope):
        if c.tag == "SimulationTimeCondition":
            return m.SimulationTimeCondition(self.number(c, "value", scope), self.rule(c, scope))
        if c.tag == "StoryboardElementStateCondition":
            test = m.StoryboardElementStateCondition(
                self.value(c, "storyboardElementType", scope, "enum", choices=ELEMENT_TYPES),
                self.value(c, "storyboardElementRef", scope),
                self.value(c, "state", scope, "enum", choices=STATES))
            self.state_conditions.append((c, test, self.context))
            return test
        if c.tag in ("ParameterCondition", "VariableCondition"):
            variable = c.tag == "VariableCondition"
            attr = "variableRef" if variable else "parameterRef"
            name = self.value(c, attr, scope)
            types = self.variable_types if variable else self.global_types
            if name not in types:
                raise c.error("%s: no global %s %s (declared: %s)" % (
                    attr, "variable" if variable else "parameter", name,
                    ", ".join(sorted(types)) or "none"))
            rule = self.rule(c, scope)
            if types[name] in ("string", "boolean", "dateTime") and \
                    rule not in ("equalTo", "notEqualTo"):
                raise c.error("rule: %s compares numbers; %s is a %s" % (rule, name, types[name]))
            return m.ParameterCondition(name, self.typed_value(c, "value", scope, types[name]),
                                        rule, variable)
        if c.tag == "TimeOfDayCondition":
            return m.TimeOfDayCondition(self.value(c, "dateTime", scope, "dateTime"),
                                        self.rule(c, scope))
        if c.tag == "TrafficSignalCondition":
            return m.TrafficSignalCondition(self.value(c, "name", scope),
                                            self.value(c, "state", scope))
        name = self.value(c, "trafficSignalControllerRef", scope)
        phase = self.value(c, "phase", scope)
        self.deferred_signal_check(c, name, phase)
        return m.TrafficSignalControllerCondition(name, phase)

    def entity_condition(self, c, scope):
        both = ("euclidianDistance", "cartesianDistance", "longitudinal", "lateral")
        if c.tag == "RelativeDistanceCondition":
            ref = self.entity_ref(c, scope)
            v, free, dtype, rule, system, along = self.distance_common(
                c, scope, ("euclidianDistance",) + both[1:])
            if "relativeDistanceType" not in c.attrib:
                raise c.error("needs attribute relativeDistanceType")
            return m.RelativeDistanceCondition(ref, v, free, dtype, rule, system, along)
        if c.tag == "TimeHeadwayCondition":
            ref = self.entity_ref(c, scope)
            v, free, _, rule, system, along = self.distance_common(c, scope, ("longitudinal",))
            return m.TimeHeadwayCondition(ref, v, free, rule, system, along)
        if c.tag == "TimeToCollisionCondition":
            target = c.need("TimeToCollisionConditionTarget").only_child(("EntityRef",
                                                                          "Position"))
            ref = self.entity_ref(target, scope) if target.tag == "EntityRef" \
                else self.position(target, scope)
            v, free, dtype, rule, system, along = self.distance_common(c, scope, both)
            return m.TimeToCollisionCondition(ref, v, free, rule, dtype, system, along)
        if c.tag == "ReachPositionCondition":
            return m.ReachPositionCondition(self.position(c.need("Position"), scope),
                                            self.number(c, "tolerance", scope, minimum=0))
        if c.tag == "DistanceCondition":
            v, free, dtype, rule, system, along = self.distance_common(c, scope, both)
            return m.DistanceCondition(self.position(c.need("Position"), scope), v, free, rule,
                                       dtype, system, along)
        if c.tag == "SpeedCondition":
            return m.SpeedCondition(self.number(c, "value", scope), self.rule(c, scope),
                                    self.direction(c, scope))
        return getattr(self, "_cond_" + c.tag)(c, scope)

    def direction(self, c, scope):
        return self.value(c, "direction", scope, "enum", None, DIRECTIONS)

    def _cond_TraveledDistanceCondition(self, c, scope):
        return m.TraveledDistanceCondition(self.number(c, "value", scope, minimum=0))

    def _cond_EndOfRoadCondition(self, c, scope):
        return m.EndOfRoadCondition(self.number(c, "duration", scope, minimum=0))

    def _cond_OffroadCondition(self, c, scope):
        return m.OffroadCondition(self.number(c, "duration", scope, minimum=0))

    def _cond_StandStillCondition(self, c, scope):
        return m.StandStillCondition(self.number(c, "duration", scope, minimum=0))

    def _cond_CollisionCondition(self, c, scope):
        target = c.only_child(("EntityRef", "ByType"))
        if target.tag == "EntityRef":
            return m.CollisionCondition(entity=self.entity_ref(target, scope))
        return m.CollisionCondition(object_type=self.value(
            target, "objectType", scope, "enum",
            choices=("pedestrian", "vehicle", "miscellaneous", "external")))

    def _cond_AccelerationCondition(self, c, scope):
        return m.AccelerationCondition(self.number(c, "value", scope), self.rule(c, scope),
                                       self.direction(c, scope))

    def _cond_RelativeSpeedCondition(self, c, scope):
        return m.RelativeSpeedCondition(self.entity_ref(c, scope), self.number(c, "value", scope),
                                        self.rule(c, scope), self.direction(c, scope))

    def _cond_RelativeClearanceCondition(self, c, scope):
        ranges = []
        for r in c.findall("RelativeLaneRange"):
            lo = self.value(r, "from", scope, "integer", None)
            hi = self.value(r, "to", scope, "integer", None)
            lo = hi if lo is None else lo
            hi = lo if hi is None else hi
            if lo is None:
                raise r.error("needs attribute from or to")
            if lo > hi:
                raise r.error("from: %d is greater than to %d" % (lo, hi))
            ranges.append((lo, hi))
        return m.RelativeClearanceCondition(
            self.number(c, "distanceForward", scope, 0.0, minimum=0),
            self.number(c, "distanceBackward", scope, 0.0, minimum=0),
            self.boolean(c, "freeSpace", scope), self.boolean(c, "oppositeLanes", scope),
            tuple(ranges), tuple(self.entity_ref(e, scope) for e in c.findall("EntityRef")))
