"""Global actions for the reader (xosc.py): EnvironmentAction (an Environment or a
CatalogReference to one), ParameterAction, VariableAction, InfrastructureAction and
TrafficAction; and the RoadNetwork's TrafficSignalControllers."""

import re

from . import model as m
from .params import ParameterError, convert

_DATETIME = re.compile(r"\d{4}-\d\d-\d\dT(\d\d):(\d\d):(\d\d)(\.\d+)?(Z|[+-]\d\d:\d\d)?$")


class GlobalReader:
    def global_action(self, node, scope):
        child = node.only_child(("EnvironmentAction", "ParameterAction", "VariableAction",
                                 "InfrastructureAction", "TrafficAction"))
        if child.tag == "EnvironmentAction":
            return self.environment(child, scope)
        if child.tag in ("ParameterAction", "VariableAction"):
            return self.parameter_action(child, scope)
        if child.tag == "InfrastructureAction":
            sa = child.need("TrafficSignalAction").only_child(
                ("TrafficSignalStateAction", "TrafficSignalControllerAction"))
            if sa.tag == "TrafficSignalStateAction":
                return m.TrafficSignalStateAction(self.value(sa, "name", scope),
                                                  self.value(sa, "state", scope))
            name = self.value(sa, "trafficSignalControllerRef", scope)
            phase = self.value(sa, "phase", scope)
            self.deferred_signal_check(sa, name, phase)
            return m.TrafficSignalControllerAction(name, phase)
        return self.traffic_action(child, scope)

    def parameter_action(self, node, scope):
        variable = node.tag == "VariableAction"
        attr = "variableRef" if variable else "parameterRef"
        name = self.value(node, attr, scope)
        types = self.variable_types if variable else self.global_types
        if name not in types:
            raise node.error("%s: no global %s %s (declared: %s)" % (
                attr, "variable" if variable else "parameter", name,
                ", ".join(sorted(types)) or "none"))
        child = node.only_child(("SetAction", "ModifyAction"))
        if child.tag == "SetAction":
            return m.ParameterAction(name, "set", self.value(child, "value", scope, types[name]),
                                     variable)
        rule = child.need("Rule").only_child(("AddValue", "MultiplyByValue"))
        if types[name] not in ("double", "integer", "int", "unsignedInt", "unsignedShort"):
            raise rule.error("is for numbers; %s is a %s" % (name, types[name]))
        return m.ParameterAction(name, "add" if rule.tag == "AddValue" else "multiply",
                                 self.number(rule, "value", scope), variable)

    def typed_value(self, node, attr, scope, ptype):
        """An attribute converted to a parameter type (the value of a ParameterCondition)."""
        raw = self.value(node, attr, scope)
        try:
            return convert(raw, ptype)
        except ParameterError as e:
            raise node.error("%s: %s" % (attr, e)) from None

    def deferred_signal_check(self, node, name, phase):
        controllers = self.signal_controllers
        if name not in controllers:
            raise node.error("trafficSignalControllerRef: no TrafficSignalController %r "
                             "(controllers: %s)" % (name, ", ".join(controllers) or "none"))
        if phase not in controllers[name]:
            raise node.error("phase: controller %r has no phase %r (phases: %s)"
                             % (name, phase, ", ".join(controllers[name])))

    def signal_controller(self, node, scope):
        phases = []
        for p in node.findall("Phase"):
            states = [m.TrafficSignalState(self.value(s, "trafficSignalId", scope),
                                           self.value(s, "state", scope))
                      for s in p.findall("TrafficSignalState")]
            phases.append(m.Phase(self.value(p, "name", scope),
                                  self.number(p, "duration", scope, minimum=0), tuple(states)))
        ctrl = m.TrafficSignalController(self.value(node, "name", scope), tuple(phases),
                                         self.number(node, "delay", scope, 0.0, minimum=0),
                                         self.value(node, "reference", scope, default=None))
        self.signal_controllers[ctrl.name] = [p.name for p in phases]
        return ctrl

    def traffic_definition(self, node, scope):
        if node is None:
            return None
        cats, ctrls = [], []
        vd = node.find("VehicleCategoryDistribution")
        for e in (vd.findall("VehicleCategoryDistributionEntry") if vd is not None else []):
            cats.append((self.value(e, "category", scope), self.number(e, "weight", scope,
                                                                       minimum=0)))
        cd = node.find("ControllerDistribution")
        for e in (cd.findall("ControllerDistributionEntry") if cd is not None else []):
            ctrls.append((self.controller(e.only_child(("Controller", "CatalogReference")),
                                          scope), self.number(e, "weight", scope, minimum=0)))
        return m.TrafficDefinition(self.value(node, "name", scope), tuple(cats), tuple(ctrls))

    def traffic_action(self, node, scope):
        child = node.only_child(("TrafficSourceAction", "TrafficSinkAction",
                                 "TrafficSwarmAction", "TrafficStopAction"))
        definition = self.traffic_definition(child.find("TrafficDefinition"), scope)
        if child.tag == "TrafficStopAction":
            return m.TrafficStopAction(self.value(node, "trafficName", scope, default=None))
        if child.tag == "TrafficSwarmAction":
            return m.TrafficSwarmAction(
                self.entity_ref(child.need("CentralObject"), scope),
                self.number(child, "innerRadius", scope, minimum=0),
                self.number(child, "semiMajorAxis", scope, minimum=0),
                self.number(child, "semiMinorAxis", scope, minimum=0),
                self.value(child, "numberOfVehicles", scope, "unsignedInt"),
                self.number(child, "offset", scope, 0.0),
                self.number(child, "velocity", scope, None, minimum=0), definition)
        position = self.position(child.need("Position"), scope)
        radius = self.number(child, "radius", scope, minimum=0)
        if child.tag == "TrafficSourceAction":
            return m.TrafficSourceAction(position, radius,
                                         self.number(child, "rate", scope, minimum=0),
                                         self.number(child, "velocity", scope, None, minimum=0),
                                         definition)
        return m.TrafficSinkAction(position, radius,
                                   self.number(child, "rate", scope, None, minimum=0), definition)

    # --- environment -----------------------------------------------------------------------

    def environment(self, node, scope):
        env = node.only_child(("Environment", "CatalogReference"))
        if env.tag == "CatalogReference":
            env, scope, _ = self.catalog_entry(env, scope, ("Environment",))
        else:
            scope = self.declare(env.find("ParameterDeclarations"), scope)
        tod = None
        if env.find("TimeOfDay") is not None:
            t = env.find("TimeOfDay")
            stamp = self.value(t, "dateTime", scope, "dateTime")
            match = _DATETIME.match(stamp)
            if not match or int(match.group(1)) > 23 or int(match.group(2)) > 59 \
                    or int(match.group(3)) > 59:
                raise t.error("dateTime: expected YYYY-MM-DDThh:mm:ss, got %r" % stamp)
            tod = (self.boolean(t, "animation", scope), stamp)
        friction = None
        if env.find("RoadCondition") is not None:
            friction = self.number(env.find("RoadCondition"), "frictionScaleFactor", scope,
                                   minimum=0)
        return m.EnvironmentAction(m.Environment(self.value(env, "name", scope), tod,
                                                 self.weather(env.find("Weather"), scope),
                                                 friction))

    def weather(self, w, scope):
        if w is None:
            return None
        sun = fog = precip = wind = None
        if w.find("Sun") is not None:
            s = w.find("Sun")
            lux = self.number(s, "illuminance", scope, None, minimum=0)
            if lux is None:
                lux = self.number(s, "intensity", scope, None, minimum=0)
            sun = m.Sun(self.number(s, "azimuth", scope), self.number(s, "elevation", scope), lux)
        if w.find("Fog") is not None:
            fog = self.number(w.find("Fog"), "visualRange", scope, positive=True)
        if w.find("Precipitation") is not None:
            p = w.find("Precipitation")
            intensity = self.number(p, "intensity", scope, None, minimum=0)
            if intensity is not None and intensity > 1:
                raise p.error("intensity: must be in [0, 1], got %g" % intensity)
            mm = self.number(p, "precipitationIntensity", scope, None, minimum=0)
            if intensity is None and mm is None:
                raise p.error("needs attribute precipitationIntensity (1.1) or intensity (1.0)")
            precip = m.Precipitation(
                self.value(p, "precipitationType", scope, "enum",
                           choices=("dry", "rain", "snow")), intensity, mm)
        if w.find("Wind") is not None:
            wn = w.find("Wind")
            wind = (self.number(wn, "direction", scope), self.number(wn, "speed", scope,
                                                                     minimum=0))
        cloud = self.value(w, "fractionalCloudCover", scope, default=None)
        return m.Weather(sun, fog, precip, wind,
                         cloud if cloud is not None else
                         self.value(w, "cloudState", scope, default=None),
                         self.number(w, "temperature", scope, None),
                         self.number(w, "atmosphericPressure", scope, None))
