"""Private actions for the reader (xosc.py): longitudinal, lateral, synchronize, controller,
teleport, routing, visibility, appearance and trailer actions."""

from . import model as m

DISTANCE_SYSTEMS = ("entity", "lane", "road", "trajectory")
SHAPES = ("step", "linear", "cubic", "sinusoidal")


class ActionsReader:
    def private_action(self, node, scope):
        child = node.only_child(("LongitudinalAction", "LateralAction", "VisibilityAction",
                                 "SynchronizeAction", "ActivateControllerAction",
                                 "ControllerAction", "TeleportAction", "RoutingAction",
                                 "AppearanceAction", "TrailerAction"))
        return getattr(self, "_private_" + child.tag)(child, scope)

    def dynamics(self, node, scope, dimensions):
        shape = self.value(node, "dynamicsShape", scope, "enum", choices=SHAPES)
        dim = self.value(node, "dynamicsDimension", scope, "enum",
                         choices=("time", "rate", "distance"))
        value = self.number(node, "value", scope)
        if shape != "step" and dim in ("time", "distance") and value == 0:
            shape = "step"   # esmini: a transition over no time is a step
        if shape != "step":
            if dim not in dimensions.get(shape, ()):
                raise node.error("dynamicsDimension: %s is not supported with dynamicsShape %s "
                                 "(supported: %s)" % (dim, shape, ", ".join(dimensions[shape])))
            if dim == "rate" and value == 0:
                raise node.error("value: a rate must not be 0")
            if dim != "rate" and value <= 0:
                raise node.error("value: a %s must be > 0, got %g" % (dim, value))
        return m.Dynamics(shape, dim, value)

    def constraints(self, node, scope):
        if node is None:
            return None
        get = lambda a: self.number(node, a, scope, None, minimum=0)  # noqa: E731
        return m.DynamicConstraints(get("maxAcceleration"), get("maxDeceleration"),
                                    get("maxSpeed"), get("maxAccelerationRate"),
                                    get("maxDecelerationRate"))

    # --- longitudinal ----------------------------------------------------------------------

    def _private_LongitudinalAction(self, child, scope):
        kind = child.only_child(("SpeedAction", "LongitudinalDistanceAction",
                                 "SpeedProfileAction"))
        if kind.tag == "LongitudinalDistanceAction":
            return self.longitudinal_distance(kind, scope)
        if kind.tag == "SpeedProfileAction":
            return self.speed_profile(kind, scope)
        sa = kind
        dyn = self.dynamics(sa.need("SpeedActionDynamics"), scope,
                            {"linear": ("time", "rate", "distance"),
                             "cubic": ("time", "rate", "distance"),
                             "sinusoidal": ("time", "rate", "distance")})
        target = sa.need("SpeedActionTarget").only_child(
            ("AbsoluteTargetSpeed", "RelativeTargetSpeed"))
        if target.tag == "AbsoluteTargetSpeed":
            t = m.AbsoluteTargetSpeed(self.number(target, "value", scope))
        else:
            t = m.RelativeTargetSpeed(
                self.entity_ref(target, scope), self.number(target, "value", scope),
                self.value(target, "speedTargetValueType", scope, "enum",
                           choices=("delta", "factor")),
                self.boolean(target, "continuous", scope))
        return m.SpeedAction(dyn, t)

    def longitudinal_distance(self, node, scope):
        distance = self.number(node, "distance", scope, None, minimum=0)
        gap = self.number(node, "timeGap", scope, None, minimum=0)
        if (distance is None) == (gap is None):
            raise node.error("needs exactly one of the attributes distance and timeGap")
        return m.LongitudinalDistanceAction(
            self.entity_ref(node, scope), distance, gap, self.boolean(node, "freespace", scope),
            self.boolean(node, "continuous", scope),
            self.value(node, "coordinateSystem", scope, "enum", "entity", DISTANCE_SYSTEMS),
            self.value(node, "displacement", scope, "enum", "trailingReferencedEntity",
                       ("trailingReferencedEntity", "leadingReferencedEntity", "any")),
            self.constraints(node.find("DynamicConstraints"), scope))

    def speed_profile(self, node, scope):
        entries = tuple(m.SpeedProfileEntry(self.number(e, "speed", scope),
                                            self.number(e, "time", scope, None, minimum=0))
                        for e in node.findall("SpeedProfileEntry"))
        if not entries:
            raise node.error("needs at least one <SpeedProfileEntry>")
        entity = self.entity_ref(node, scope) if "entityRef" in node.attrib else None
        return m.SpeedProfileAction(
            entries, self.value(node, "followingMode", scope, "enum", choices=("position",
                                                                                "follow")),
            entity, self.constraints(node.find("DynamicConstraints"), scope))

    # --- lateral ---------------------------------------------------------------------------

    def _private_LateralAction(self, child, scope):
        kind = child.only_child(("LaneChangeAction", "LaneOffsetAction", "LateralDistanceAction"))
        if kind.tag == "LaneOffsetAction":
            return self.lane_offset(kind, scope)
        if kind.tag == "LateralDistanceAction":
            return m.LateralDistanceAction(
                self.entity_ref(kind, scope), self.number(kind, "distance", scope, None, minimum=0),
                self.boolean(kind, "freespace", scope), self.boolean(kind, "continuous", scope),
                self.value(kind, "coordinateSystem", scope, "enum", "entity", DISTANCE_SYSTEMS),
                self.value(kind, "displacement", scope, "enum", "any",
                           ("any", "leftToReferencedEntity", "rightToReferencedEntity")),
                self.constraints(kind.find("DynamicConstraints"), scope))
        lc = kind
        dyn = self.dynamics(lc.need("LaneChangeActionDynamics"), scope,
                            {"linear": ("time", "distance"), "cubic": ("time", "distance"),
                             "sinusoidal": ("time", "distance")})
        target = lc.need("LaneChangeTarget").only_child(
            ("RelativeTargetLane", "AbsoluteTargetLane"))
        if target.tag == "RelativeTargetLane":
            t = m.RelativeTargetLane(self.entity_ref(target, scope),
                                     self.value(target, "value", scope, "integer"))
        else:
            lane = self.value(target, "value", scope)
            try:
                if int(lane) == 0:
                    raise ValueError
            except ValueError:
                raise target.error("value: expected a lane id (a non-zero integer), got %r"
                                   % lane) from None
            t = m.AbsoluteTargetLane(str(int(lane)))
        return m.LaneChangeAction(dyn, t, self.number(lc, "targetLaneOffset", scope, 0.0))

    def lane_offset(self, node, scope):
        dyn = node.need("LaneOffsetActionDynamics")
        target = node.need("LaneOffsetTarget").only_child(("RelativeTargetLaneOffset",
                                                           "AbsoluteTargetLaneOffset"))
        entity = self.entity_ref(target, scope) if target.tag.startswith("Relative") else None
        return m.LaneOffsetAction(
            self.value(dyn, "dynamicsShape", scope, "enum", choices=SHAPES),
            self.number(dyn, "maxLateralAcc", scope, None, positive=True),
            self.number(target, "value", scope), entity, self.boolean(node, "continuous", scope))

    # --- synchronize, teleport, routing -----------------------------------------------------

    def _private_SynchronizeAction(self, node, scope):
        final = None
        fs = node.find("FinalSpeed")
        if fs is not None:
            speed = fs.only_child(("AbsoluteSpeed", "RelativeSpeedToMaster"))
            steady = speed.find("TargetDistanceSteadyState") or speed.find("TargetTimeSteadyState")
            state = None
            if steady is not None:
                attr = "distance" if steady.tag == "TargetDistanceSteadyState" else "time"
                state = (attr, self.number(steady, attr, scope, minimum=0))
            if speed.tag == "AbsoluteSpeed":
                final = m.FinalSpeed("absolute", self.number(speed, "value", scope), None, state)
            else:
                final = m.FinalSpeed("relative", self.number(speed, "value", scope),
                                     self.value(speed, "speedTargetValueType", scope, "enum",
                                                choices=("delta", "factor")), state)
        return m.SynchronizeAction(
            self.entity_ref(node, scope, "masterEntityRef"),
            self.position(node.need("TargetPositionMaster"), scope),
            self.position(node.need("TargetPosition"), scope), final,
            self.number(node, "targetToleranceMaster", scope, None, minimum=0),
            self.number(node, "targetTolerance", scope, None, minimum=0))

    def _private_TeleportAction(self, node, scope):
        return m.TeleportAction(self.position(node.need("Position"), scope))

    def _private_RoutingAction(self, node, scope):
        routing = node.only_child(("AssignRouteAction", "FollowTrajectoryAction",
                                   "AcquirePositionAction"))
        if routing.tag == "AcquirePositionAction":
            return m.AcquirePositionAction(self.position(routing.need("Position"), scope))
        if routing.tag == "AssignRouteAction":
            route = self.route(routing.only_child(("Route", "CatalogReference")), scope)
            return m.AssignRouteAction(route.name, route.closed, route.waypoints, route.catalog)
        return self.follow_trajectory(routing, scope)

    def follow_trajectory(self, node, scope):
        ref = node.find("Trajectory") or node.find("CatalogReference")
        if ref is None:
            ref = node.need("TrajectoryRef").only_child(("Trajectory", "CatalogReference"))
        tr = node.need("TimeReference").only_child(("None", "Timing"))
        timing = None
        if tr.tag == "Timing":
            timing = m.Timing(self.value(tr, "domainAbsoluteRelative", scope, "enum",
                                         choices=("absolute", "relative")),
                              self.number(tr, "scale", scope, positive=True),
                              self.number(tr, "offset", scope))
        traj, source = self.trajectory(ref, scope, timed=timing is not None)
        mode = "follow"
        if node.find("TrajectoryFollowingMode") is not None:
            mode = self.value(node.find("TrajectoryFollowingMode"), "followingMode", scope,
                              "enum", choices=("position", "follow"))
        vertices = traj.shape.vertices if isinstance(traj.shape, m.Polyline) else ()
        return m.FollowTrajectoryAction(traj.name, vertices, timing, mode, traj.shape,
                                        traj.closed,
                                        self.number(node, "initialDistanceOffset", scope, 0.0,
                                                    minimum=0), source)

    # --- controllers -----------------------------------------------------------------------

    def _private_ActivateControllerAction(self, node, scope):
        get = lambda a: self.boolean(node, a, scope, None)  # noqa: E731
        return m.ActivateControllerAction(get("lateral"), get("longitudinal"), get("lighting"),
                                          get("animation"),
                                          self.value(node, "objectControllerRef", scope,
                                                     default=None))

    def _private_ControllerAction(self, node, scope):
        parts = []
        for c in node.children:
            if c.tag == "ActivateControllerAction":
                parts.append(self._private_ActivateControllerAction(c, scope))
            elif c.tag == "AssignControllerAction":
                parts.append(self.assign_controller(c, scope))
            else:
                parts.append(self.override_controller(c, scope))
        if not parts:
            raise node.error("needs an <AssignControllerAction>, <OverrideControllerValueAction> "
                             "or <ActivateControllerAction>")
        return parts[0] if len(parts) == 1 else m.ControllerAction(tuple(parts))

    def assign_controller(self, node, scope):
        get = lambda a: self.boolean(node, a, scope, None)  # noqa: E731
        child = node.only_child(("Controller", "CatalogReference", "ObjectController"))
        if child.tag == "ObjectController":
            name, ctrl = self.object_controller(child, scope)
        else:
            name, ctrl = None, self.controller(child, scope)
        return m.AssignControllerAction(ctrl, name, get("activateLateral"),
                                        get("activateLongitudinal"), get("activateLighting"),
                                        get("activateAnimation"))

    def override_controller(self, node, scope):
        out = []
        for part in node.children:
            values = []
            for attr in ("value", "maxRate", "maxTorque", "number"):
                if attr in part.attrib:
                    values.append((attr, self.number(part, attr, scope)))
            for sub in part.children:   # BrakePercent / BrakeForce, ManualGear / AutomaticGear
                for attr in ("value", "maxRate", "number"):
                    if attr in sub.attrib:
                        values.append((sub.tag + "." + attr, self.number(sub, attr, scope)))
                if "gear" in sub.attrib:
                    values.append(("gear", self.value(sub, "gear", scope, "enum",
                                                      choices=("n", "p", "r", "d"))))
            out.append(m.ControllerOverride(part.tag, self.boolean(part, "active", scope),
                                            tuple(values)))
        if not out:
            raise node.error("needs at least one override (Throttle, Brake, ...)")
        return m.OverrideControllerValueAction(tuple(out))

    # --- visibility, appearance, trailers --------------------------------------------------

    def _private_VisibilityAction(self, node, scope):
        refs = node.find("SensorReferenceSet")
        names = tuple(self.value(r, "name", scope) for r in refs.findall("SensorReference")) \
            if refs is not None else ()
        return m.VisibilityAction(self.boolean(node, "graphics", scope),
                                  self.boolean(node, "traffic", scope),
                                  self.boolean(node, "sensors", scope), names)

    def _private_AppearanceAction(self, node, scope):
        child = node.only_child(("LightStateAction", "AnimationAction"))
        if child.tag == "AnimationAction":
            kind = child.need("AnimationType").children
            state = child.find("AnimationState")
            return m.AnimationAction(
                kind[0].tag if kind else "", self.number(child, "animationDuration", scope, None),
                self.boolean(child, "loop", scope, False),
                self.number(state, "state", scope) if state is not None else None)
        light = child.need("LightType").only_child(("VehicleLight", "UserDefinedLight"))
        user = light.tag == "UserDefinedLight"
        ltype = self.value(light, "userDefinedLightType" if user else "vehicleLightType", scope)
        st = child.need("LightState")
        color = None
        if st.find("Color") is not None:
            c = st.find("Color")
            comp = c.only_child(("ColorRgb", "ColorCmyk"))
            color = (self.value(c, "colorType", scope),
                     tuple((a, self.number(comp, a, scope, minimum=0)) for a in comp.attrib))
        return m.LightStateAction(
            ltype, self.value(st, "mode", scope, "enum", choices=("on", "off", "flashing")),
            self.number(child, "transitionTime", scope, 0.0, minimum=0),
            self.number(st, "luminousIntensity", scope, None, minimum=0),
            self.number(st, "flashingOnDuration", scope, None, minimum=0),
            self.number(st, "flashingOffDuration", scope, None, minimum=0), color, user)

    def _private_TrailerAction(self, node, scope):
        child = node.only_child(("ConnectTrailerAction", "DisconnectTrailerAction"))
        if child.tag == "DisconnectTrailerAction":
            return m.DisconnectTrailerAction()
        return m.ConnectTrailerAction(self.entity_ref(child, scope, "trailerRef"))
