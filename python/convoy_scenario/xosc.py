"""Reading an OpenSCENARIO 1.x file (.xosc) of the supported subset into the immutable
objects of convoy_scenario.model (docs/scenarios.md has the subset as a table).

Rules:
- Every element and attribute is checked against convoy_scenario.schema first (the file's,
  then each catalog file's when a reference uses it): anything else raises ScenarioError
  ``file.xosc:LINE: <Element> is not supported in <Parent> (supported here: ...)``.
- Attribute values are resolved in the scope where they stand (convoy_scenario.params):
  ``$name`` references, ``${...}`` expressions; a bad value, an unknown parameter or a value
  out of range raises ``file.xosc:LINE: <Element> attribute: what is wrong``.
- Paths (LogicFile, SceneGraphFile, catalog Directory) are relative to the directory of the
  file they are written in. The LogicFile must exist.
- CatalogReference (entities only): every ``*.xosc`` file of the VehicleCatalog and
  PedestrianCatalog directories is searched (sorted by name) for ``<Catalog name=catalogName>``
  and in it the Vehicle or Pedestrian named entryName. The entry's ParameterDeclarations see
  only themselves; ParameterAssignments (evaluated where the reference stands) set them.
- Storyboard element names: each element's path is its name and its ancestors' joined by
  ``::`` (Story::Act::Group::Maneuver::Event::Action) and must be unique. A
  StoryboardElementStateCondition's storyboardElementRef is a name or a ``::`` path suffix
  and must match exactly one element of its type.
- Entity references (Private, Actors, TriggeringEntities, conditions, relative targets) must
  name a ScenarioObject.
"""

import os
import re

from . import model as m
from . import schema
from .params import ParameterError, Scope, TYPES, convert, resolve
from .xmltree import Node, ScenarioError, parse_bytes, parse_file

RULES = ("greaterThan", "lessThan", "equalTo", "greaterOrEqual", "lessOrEqual", "notEqualTo")
ELEMENT_TYPES = ("story", "act", "maneuverGroup", "maneuver", "event", "action")
STATES = ("standbyState", "runningState", "completeState", "startTransition", "endTransition",
          "stopTransition", "skipTransition")
VEHICLE_CATEGORIES = ("car", "van", "truck", "trailer", "semitrailer", "bus", "motorbike",
                      "bicycle", "train", "tram")
_REQUIRED = object()
_DATETIME = re.compile(r"\d{4}-\d\d-\d\dT(\d\d):(\d\d):(\d\d)(\.\d+)?(Z|[+-]\d\d:\d\d)?$")


def load(path, parameters=None):
    """The Scenario of the .xosc file at path; ScenarioError when it is outside the subset
    or wrong. parameters ({name: value}) override the values of global parameters (as a
    ParameterAssignment does: the value is converted to the declared type)."""
    path = os.path.abspath(path)
    return _Reader(path).read(parse_file(path), parameters)


def loads(text, path, parameters=None):
    """The Scenario of the .xosc text, as if read from path (for messages and relative
    paths)."""
    path = os.path.abspath(path)
    data = text.encode("utf-8") if isinstance(text, str) else text
    return _Reader(path).read(parse_bytes(data, path), parameters)


class _Reader:
    def __init__(self, path):
        self.path = path
        self.catalog_dirs = []       # (kind, absolute directory, Directory node)
        self.catalog_files = {}      # path -> root Node
        self.entities = {}
        self.elements = {t: [] for t in ELEMENT_TYPES}
        self.state_conditions = []   # (node, condition) resolved once all elements are known

    # --- attributes ------------------------------------------------------------------------

    def value(self, node, attr, scope, kind="string", default=_REQUIRED, choices=None):
        raw = node.attrib.get(attr)
        if raw is None:
            if default is _REQUIRED:
                raise node.error("needs attribute %s" % attr)
            return default
        try:
            v = resolve(raw, scope)
            if kind == "enum":
                v = convert(v, "string")
                if v not in choices:
                    raise ParameterError("%r is not one of %s" % (v, ", ".join(choices)))
            else:
                v = convert(v, kind)
        except ParameterError as e:
            src = " (from %s)" % raw if raw.startswith("$") and "unknown" not in str(e) else ""
            raise node.error("%s: %s%s" % (attr, e, src)) from None
        return v

    def number(self, node, attr, scope, default=_REQUIRED, minimum=None, positive=False):
        v = self.value(node, attr, scope, "double", default)
        if v is None:
            return v
        if minimum is not None and v < minimum:
            raise node.error("%s: must be >= %g, got %g" % (attr, minimum, v))
        if positive and not v > 0:
            raise node.error("%s: must be > 0, got %g" % (attr, v))
        return v

    def entity_ref(self, node, scope, attr="entityRef"):
        name = self.value(node, attr, scope)
        if name not in self.entities:
            raise node.error("%s: no entity %r (entities: %s)" % (
                attr, name, ", ".join(self.entities) or "none"))
        return name

    def declare(self, decls, scope, assignments=None):
        """A new scope under scope with the ParameterDeclarations node decls (may be None);
        assignments (name -> (value, node)) replace declared values."""
        inner = Scope(scope)
        assignments = dict(assignments or {})
        for d in (decls.findall("ParameterDeclaration") if decls is not None else []):
            name = self.value(d, "name", inner)
            if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
                raise d.error("name: %r is not a parameter name" % name)
            if name in inner.values:
                raise d.error("name: parameter %s is declared twice" % name)
            ptype = self.value(d, "parameterType", inner, "enum", choices=TYPES)
            if name in assignments:
                raw, anode = assignments.pop(name)
                try:
                    inner.values[name] = (ptype, convert(raw, ptype))
                except ParameterError as e:
                    raise anode.error("value: %s" % e) from None
            else:
                inner.values[name] = (ptype, self.value(d, "value", inner, ptype))
        for name, (raw, anode) in assignments.items():
            raise anode.error("parameterRef: the entry declares no parameter %s" % name)
        return inner

    # --- the file --------------------------------------------------------------------------

    def read(self, root, overrides=None):
        if root.tag != "OpenSCENARIO":
            raise root.error("is not an OpenSCENARIO file (the root must be <OpenSCENARIO>)")
        schema.check(root)
        if root.find("Catalog") is not None:
            raise root.find("Catalog").error("is a catalog file, not a scenario")
        header = self.header(root.need("FileHeader"))
        decls = root.find("ParameterDeclarations")
        overrides = {name: (value if isinstance(value, str) else
                            ("true" if value is True else "false") if isinstance(value, bool)
                            else repr(value), _Override(self.path, name))
                     for name, value in (overrides or {}).items()}
        declared = {d.attrib.get("name") for d in
                    (decls.findall("ParameterDeclaration") if decls is not None else [])}
        for name in overrides:
            if name not in declared:
                raise ScenarioError("%s: parameter override %s: the file declares no global "
                                    "parameter %s" % (os.path.basename(self.path), name, name))
        scope = self.declare(decls, Scope(), overrides)
        locations = root.find("CatalogLocations")
        if locations is not None:
            for kind_node in locations.children:
                for d in kind_node.findall("Directory"):
                    rel = self.value(d, "path", scope)
                    self.catalog_dirs.append((kind_node.tag, self.rel(rel), d))
        logic = scene = None
        network = root.find("RoadNetwork")
        if network is not None:
            if network.find("LogicFile") is not None:
                node = network.find("LogicFile")
                logic = self.rel(self.value(node, "filepath", scope))
                if not os.path.isfile(logic):
                    raise node.error("filepath: no such file %s" % logic)
            if network.find("SceneGraphFile") is not None:
                scene = self.rel(self.value(network.find("SceneGraphFile"), "filepath", scope))
        entities = []
        for obj in root.need("Entities").findall("ScenarioObject"):
            entities.append(self.scenario_object(obj, scope))
        board = root.need("Storyboard")
        init = self.init(board.need("Init"), scope)
        stories = tuple(self.story(s, scope) for s in board.findall("Story"))
        stop = self.trigger(board.find("StopTrigger"), scope)
        for node, cond in self.state_conditions:
            object.__setattr__(cond, "element_path",
                               self.find_element(node, cond.element_type, cond.element_ref))
        return m.Scenario(path=self.path, header=header,
                          parameters=tuple(sorted(scope.flat().items())), logic_file=logic,
                          scene_graph_file=scene, entities=tuple(entities), init=init,
                          stories=stories, stop_trigger=stop,
                          catalog_dirs=tuple((k, d) for k, d, _ in self.catalog_dirs))

    def rel(self, p, base=None):
        return os.path.normpath(os.path.join(os.path.dirname(base or self.path), p))

    def header(self, node):
        s = Scope()
        major = self.value(node, "revMajor", s, "unsignedShort")
        if major != 1:
            raise node.error("revMajor: only OpenSCENARIO 1.x is supported, got %d" % major)
        return m.FileHeader(major, self.value(node, "revMinor", s, "unsignedShort"),
                            self.value(node, "date", s, default=""),
                            self.value(node, "description", s, default=""),
                            self.value(node, "author", s, default=""))

    # --- entities --------------------------------------------------------------------------

    def scenario_object(self, node, scope):
        name = self.value(node, "name", scope)
        if name in self.entities:
            raise node.error("name: entity %r is declared twice" % name)
        child = node.only_child(("Vehicle", "Pedestrian", "CatalogReference"))
        source = None
        if child.tag == "CatalogReference":
            child, entry_scope, source = self.catalog_entry(child, scope)
        else:
            entry_scope = scope
        if child.tag == "Vehicle":
            entity = m.Entity(name, "vehicle", self.vehicle(child, entry_scope), source)
        else:
            entity = m.Entity(name, "pedestrian", self.pedestrian(child, entry_scope), source)
        self.entities[name] = entity
        return entity

    def bounding_box(self, node, scope):
        c, d = node.need("Center"), node.need("Dimensions")
        return m.BoundingBox(
            (self.number(c, "x", scope), self.number(c, "y", scope), self.number(c, "z", scope)),
            self.number(d, "length", scope, minimum=0), self.number(d, "width", scope, minimum=0),
            self.number(d, "height", scope, minimum=0))

    def properties(self, node, scope):
        if node is None:
            return ()
        out = [(self.value(p, "name", scope), self.value(p, "value", scope))
               for p in node.findall("Property")]
        out += [("file", self.value(f, "filepath", scope)) for f in node.findall("File")]
        return tuple(out)

    def vehicle(self, node, scope):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        perf = node.need("Performance")
        axles = []
        if node.find("Axles") is not None:
            for a in node.find("Axles").children:
                axles.append((a.tag, tuple((k, self.number(a, k, scope))
                                           for k in schema.SCHEMA[a.tag][0])))
        return m.Vehicle(
            name=self.value(node, "name", scope),
            category=self.value(node, "vehicleCategory", scope, "enum",
                                choices=VEHICLE_CATEGORIES),
            bounding_box=self.bounding_box(node.need("BoundingBox"), scope),
            performance=m.Performance(self.number(perf, "maxSpeed", scope, minimum=0),
                                      self.number(perf, "maxAcceleration", scope, minimum=0),
                                      self.number(perf, "maxDeceleration", scope, minimum=0)),
            axles=tuple(axles), properties=self.properties(node.find("Properties"), scope),
            model3d=self.value(node, "model3d", scope, default=None))

    def pedestrian(self, node, scope):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        return m.Pedestrian(
            name=self.value(node, "name", scope), model=self.value(node, "model", scope, default=""),
            mass=self.number(node, "mass", scope, minimum=0),
            category=self.value(node, "pedestrianCategory", scope, "enum",
                                choices=("pedestrian", "wheelchair", "animal")),
            bounding_box=self.bounding_box(node.need("BoundingBox"), scope),
            properties=self.properties(node.find("Properties"), scope),
            model3d=self.value(node, "model3d", scope, default=None))

    def catalog_entry(self, ref, scope):
        """(entry node, its scope, CatalogSource) of a CatalogReference to a vehicle or
        pedestrian."""
        catalog = self.value(ref, "catalogName", scope)
        entry = self.value(ref, "entryName", scope)
        assignments = {}
        if ref.find("ParameterAssignments") is not None:
            for a in ref.find("ParameterAssignments").findall("ParameterAssignment"):
                name = self.value(a, "parameterRef", scope)
                assignments[name] = (self.value(a, "value", scope), a)
        dirs = [(k, d, n) for k, d, n in self.catalog_dirs
                if k in ("VehicleCatalog", "PedestrianCatalog")]
        if not dirs:
            raise ref.error("catalogName: %r: the file has no VehicleCatalog or "
                            "PedestrianCatalog directory in <CatalogLocations>" % catalog)
        searched = []
        for kind, directory, dnode in dirs:
            if not os.path.isdir(directory):
                raise ref.error("catalogName: %r: the catalog directory %s (%s) does not exist"
                                % (catalog, directory, dnode.where()))
            for fname in sorted(os.listdir(directory)):
                if not fname.endswith(".xosc"):
                    continue
                fpath = os.path.join(directory, fname)
                searched.append(fpath)
                root = self.catalog_root(fpath)
                cat = root.find("Catalog")
                if cat is None or self.value(cat, "name", Scope()) != catalog:
                    continue
                names = []
                for item in cat.children:
                    item_name = item.attrib.get("name", "")
                    names.append(item_name)
                    if item_name == entry:
                        inner = self.declare(item.find("ParameterDeclarations"), Scope(),
                                             assignments)
                        # the entry reads its own declarations only once: pass the filled scope
                        item = _without_declarations(item)
                        return item, inner, m.CatalogSource(
                            catalog, entry, fpath, tuple(sorted(inner.flat().items())))
                raise ref.error("entryName: no entry %r in catalog %r (%s; entries: %s)" % (
                    entry, catalog, fpath, ", ".join(names)))
        raise ref.error("catalogName: no catalog named %r in %s" % (
            catalog, ", ".join(searched) if searched else
            "the catalog directories (%s): no .xosc files" % ", ".join(d for _, d, _ in dirs)))

    def catalog_root(self, fpath):
        if fpath not in self.catalog_files:
            root = parse_file(fpath)
            if root.tag != "OpenSCENARIO":
                raise root.error("is not an OpenSCENARIO catalog")
            schema.check(root)
            self.catalog_files[fpath] = root
        return self.catalog_files[fpath]

    # --- positions and actions -------------------------------------------------------------

    def position(self, node, scope, world_only=None):
        p = node.only_child(("WorldPosition", "LanePosition"))
        if p.tag == "WorldPosition":
            return m.WorldPosition(self.number(p, "x", scope), self.number(p, "y", scope),
                                   self.number(p, "z", scope, 0.0),
                                   self.number(p, "h", scope, None),
                                   self.number(p, "p", scope, 0.0), self.number(p, "r", scope, 0.0))
        if world_only:
            raise p.error("is not supported in %s (needs the road network): use WorldPosition"
                          % world_only)
        orientation = None
        o = p.find("Orientation")
        if o is not None:
            orientation = (self.value(o, "type", scope, "enum", "relative",
                                      ("relative", "absolute")),
                           self.number(o, "h", scope, 0.0), self.number(o, "p", scope, 0.0),
                           self.number(o, "r", scope, 0.0))
        lane = self.value(p, "laneId", scope)
        try:
            int(lane)
        except ValueError:
            raise p.error("laneId: expected an integer lane id, got %r" % lane) from None
        return m.LanePosition(self.value(p, "roadId", scope), lane, self.number(p, "s", scope),
                              self.number(p, "offset", scope, 0.0), orientation)

    def dynamics(self, node, scope, dimensions):
        shape = self.value(node, "dynamicsShape", scope, "enum",
                           choices=("step", "linear", "cubic", "sinusoidal"))
        dim = self.value(node, "dynamicsDimension", scope, "enum",
                         choices=("time", "rate", "distance"))
        value = self.number(node, "value", scope)
        if shape != "step":
            if dim not in dimensions.get(shape, ()):
                raise node.error("dynamicsDimension: %s is not supported with dynamicsShape %s "
                                 "(supported: %s)" % (dim, shape, ", ".join(dimensions[shape])))
            if dim == "rate" and value == 0:
                raise node.error("value: a rate must not be 0")
            if dim != "rate" and value <= 0:
                raise node.error("value: a %s must be > 0, got %g" % (dim, value))
        return m.Dynamics(shape, dim, value)

    def private_action(self, node, scope):
        child = node.only_child(("LongitudinalAction", "LateralAction", "RoutingAction",
                                 "TeleportAction"))
        if child.tag == "TeleportAction":
            return m.TeleportAction(self.position(child.need("Position"), scope))
        if child.tag == "LongitudinalAction":
            sa = child.need("SpeedAction")
            dyn = self.dynamics(sa.need("SpeedActionDynamics"), scope,
                                {"linear": ("time", "rate", "distance"),
                                 "cubic": ("time",), "sinusoidal": ("time",)})
            target = sa.need("SpeedActionTarget").only_child(
                ("AbsoluteTargetSpeed", "RelativeTargetSpeed"))
            if target.tag == "AbsoluteTargetSpeed":
                t = m.AbsoluteTargetSpeed(self.number(target, "value", scope))
            else:
                t = m.RelativeTargetSpeed(
                    self.entity_ref(target, scope), self.number(target, "value", scope),
                    self.value(target, "speedTargetValueType", scope, "enum",
                               choices=("delta", "factor")),
                    self.value(target, "continuous", scope, "boolean"))
            return m.SpeedAction(dyn, t)
        if child.tag == "LateralAction":
            lc = child.need("LaneChangeAction")
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
        routing = child.only_child(("AssignRouteAction", "FollowTrajectoryAction"))
        if routing.tag == "AssignRouteAction":
            route = routing.need("Route")
            rscope = self.declare(route.find("ParameterDeclarations"), scope)
            points = route.findall("Waypoint")
            if len(points) < 2:
                raise route.error("needs at least 2 <Waypoint>s, got %d" % len(points))
            return m.AssignRouteAction(
                self.value(route, "name", rscope), self.value(route, "closed", rscope, "boolean"),
                tuple(m.Waypoint(self.position(w.need("Position"), rscope),
                                 self.value(w, "routeStrategy", rscope, "enum",
                                            choices=("fastest", "shortest", "leastIntersections",
                                                     "random")))
                      for w in points))
        return self.follow_trajectory(routing, scope)

    def follow_trajectory(self, node, scope):
        traj = node.find("Trajectory")
        if traj is None:
            traj = node.need("TrajectoryRef").need("Trajectory")
        tscope = self.declare(traj.find("ParameterDeclarations"), scope)
        if self.value(traj, "closed", tscope, "boolean"):
            raise traj.error("closed: closed trajectories are not supported")
        poly = traj.need("Shape").need("Polyline")
        ref = node.need("TimeReference").only_child(("None", "Timing"))
        timing = None
        if ref.tag == "Timing":
            timing = m.Timing(self.value(ref, "domainAbsoluteRelative", tscope, "enum",
                                         choices=("absolute", "relative")),
                              self.number(ref, "scale", tscope, positive=True),
                              self.number(ref, "offset", tscope))
        vertices = []
        for v in poly.findall("Vertex"):
            time = self.number(v, "time", tscope, None)
            if timing is not None:
                if time is None:
                    raise v.error("needs attribute time (the TimeReference is a Timing)")
                if vertices and time < vertices[-1].time:
                    raise v.error("time: %g comes before the previous vertex's %g"
                                  % (time, vertices[-1].time))
            vertices.append(m.Vertex(self.position(v.need("Position"), tscope,
                                                   world_only="a trajectory's Vertex"), time))
        if len(vertices) < 2:
            raise poly.error("needs at least 2 <Vertex>es, got %d" % len(vertices))
        mode = "follow"
        if node.find("TrajectoryFollowingMode") is not None:
            mode = self.value(node.find("TrajectoryFollowingMode"), "followingMode", tscope,
                              "enum", choices=("position", "follow"))
        return m.FollowTrajectoryAction(self.value(traj, "name", tscope), tuple(vertices),
                                        timing, mode)

    def environment(self, node, scope):
        env = node.need("Environment")
        scope = self.declare(env.find("ParameterDeclarations"), scope)
        tod = None
        if env.find("TimeOfDay") is not None:
            t = env.find("TimeOfDay")
            stamp = self.value(t, "dateTime", scope, "dateTime")
            match = _DATETIME.match(stamp)
            if not match or int(match.group(1)) > 23 or int(match.group(2)) > 59 \
                    or int(match.group(3)) > 59:
                raise t.error("dateTime: expected YYYY-MM-DDThh:mm:ss, got %r" % stamp)
            tod = (self.value(t, "animation", scope, "boolean"), stamp)
        weather = None
        w = env.find("Weather")
        if w is not None:
            sun = fog = precip = wind = None
            if w.find("Sun") is not None:
                s = w.find("Sun")
                lux = self.number(s, "illuminance", scope, None, minimum=0)
                if lux is None:
                    lux = self.number(s, "intensity", scope, None, minimum=0)
                sun = m.Sun(self.number(s, "azimuth", scope), self.number(s, "elevation", scope),
                            lux)
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
            weather = m.Weather(sun, fog, precip, wind,
                                cloud if cloud is not None else
                                self.value(w, "cloudState", scope, default=None),
                                self.number(w, "temperature", scope, None),
                                self.number(w, "atmosphericPressure", scope, None))
        friction = None
        if env.find("RoadCondition") is not None:
            friction = self.number(env.find("RoadCondition"), "frictionScaleFactor", scope,
                                   minimum=0)
        return m.EnvironmentAction(m.Environment(self.value(env, "name", scope), tod, weather,
                                                 friction))

    def init(self, node, scope):
        out = []
        actions = node.find("Actions")
        for child in (actions.children if actions is not None else []):
            if child.tag == "GlobalAction":
                env = child.need("EnvironmentAction")
                out.append(m.InitAction(None, self.environment(env, scope), child.where()))
            else:
                name = self.entity_ref(child, scope)
                for pa in child.findall("PrivateAction"):
                    out.append(m.InitAction(name, self.private_action(pa, scope), pa.where()))
        return tuple(out)

    # --- storyboard ------------------------------------------------------------------------

    def register(self, node, etype, path):
        if path in self.elements[etype]:
            raise node.error("name: another %s is named %r" % (etype, path))
        self.elements[etype].append(path)

    def find_element(self, node, etype, ref):
        hits = [p for p in self.elements[etype] if p == ref or p.endswith("::" + ref)]
        if not hits:
            raise node.error("storyboardElementRef: no %s named %r" % (etype, ref))
        if len(hits) > 1:
            raise node.error("storyboardElementRef: %r names %d %ss (%s): give its path"
                             % (ref, len(hits), etype, ", ".join(hits)))
        return hits[0]

    def named(self, node, scope, parent_path, etype):
        name = self.value(node, "name", scope)
        if not name or "::" in name:
            raise node.error("name: %r is not a usable name" % name)
        path = parent_path + "::" + name if parent_path else name
        self.register(node, etype, path)
        return name, path

    def story(self, node, scope):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        name, path = self.named(node, scope, "", "story")
        acts = tuple(self.act(a, scope, path) for a in node.findall("Act"))
        if not acts:
            raise node.error("needs at least one <Act>")
        return m.Story(name, path, acts, node.where())

    def act(self, node, scope, parent):
        name, path = self.named(node, scope, parent, "act")
        groups = tuple(self.group(g, scope, path) for g in node.findall("ManeuverGroup"))
        if not groups:
            raise node.error("needs at least one <ManeuverGroup>")
        return m.Act(name, path, groups, self.trigger(node.find("StartTrigger"), scope),
                     self.trigger(node.find("StopTrigger"), scope), node.where())

    def group(self, node, scope, parent):
        name, path = self.named(node, scope, parent, "maneuverGroup")
        count = self.value(node, "maximumExecutionCount", scope, "unsignedInt", 1)
        if count < 1:
            raise node.error("maximumExecutionCount: must be >= 1, got %d" % count)
        actors = []
        a = node.find("Actors")
        if a is not None:
            if self.value(a, "selectTriggeringEntities", scope, "boolean", False):
                raise a.error("selectTriggeringEntities: true is not supported")
            actors = [self.entity_ref(e, scope) for e in a.findall("EntityRef")]
        maneuvers = tuple(self.maneuver(mn, scope, path, actors)
                          for mn in node.findall("Maneuver"))
        return m.ManeuverGroup(name, path, count, tuple(actors), maneuvers, node.where())

    def maneuver(self, node, scope, parent, actors):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        name, path = self.named(node, scope, parent, "maneuver")
        events = tuple(self.event(e, scope, path, actors) for e in node.findall("Event"))
        if not events:
            raise node.error("needs at least one <Event>")
        return m.Maneuver(name, path, events, node.where())

    def event(self, node, scope, parent, actors):
        name, path = self.named(node, scope, parent, "event")
        priority = self.value(node, "priority", scope, "enum",
                              choices=("overwrite", "override", "skip", "parallel"))
        count = self.value(node, "maximumExecutionCount", scope, "unsignedInt", 1)
        if count < 1:
            raise node.error("maximumExecutionCount: must be >= 1, got %d" % count)
        actions = []
        for a in node.findall("Action"):
            aname, apath = self.named(a, scope, path, "action")
            child = a.only_child(("GlobalAction", "PrivateAction"))
            if child.tag == "GlobalAction":
                spec, private = self.environment(child.need("EnvironmentAction"), scope), False
            else:
                if not actors:
                    raise a.error("is a PrivateAction, but its ManeuverGroup has no actors")
                spec, private = self.private_action(child, scope), True
            actions.append(m.Action(aname, apath, spec, private, a.where()))
        if not actions:
            raise node.error("needs at least one <Action>")
        return m.Event(name, path, "overwrite" if priority == "override" else priority, count,
                       tuple(actions), self.trigger(node.find("StartTrigger"), scope),
                       node.where())

    # --- triggers and conditions -----------------------------------------------------------

    def trigger(self, node, scope):
        if node is None:
            return None
        groups = []
        for g in node.findall("ConditionGroup"):
            conds = tuple(self.condition(c, scope) for c in g.findall("Condition"))
            if not conds:
                raise g.error("needs at least one <Condition>")
            groups.append(conds)
        return m.Trigger(tuple(groups))

    def rule(self, node, scope):
        return self.value(node, "rule", scope, "enum", choices=RULES)

    def distance_common(self, node, scope, types, systems=("entity",)):
        if self.value(node, "alongRoute", scope, "boolean", False):
            raise node.error("alongRoute: true is not supported")
        dtype = self.value(node, "relativeDistanceType", scope, "enum", types[0], types)
        system = self.value(node, "coordinateSystem", scope, "enum", "entity",
                            ("entity", "road", "lane", "trajectory"))
        if system not in systems:
            raise node.error("coordinateSystem: %s is not supported here (supported: %s)"
                             % (system, ", ".join(systems)))
        return (self.number(node, "value", scope, minimum=0),
                self.value(node, "freespace", scope, "boolean"), dtype, self.rule(node, scope),
                system)

    def condition(self, node, scope):
        name = self.value(node, "name", scope)
        delay = self.number(node, "delay", scope, 0.0, minimum=0)
        edge = self.value(node, "conditionEdge", scope, "enum",
                          choices=("rising", "falling", "risingOrFalling", "none"))
        child = node.only_child(("ByEntityCondition", "ByValueCondition"))
        triggering, trule = (), "any"
        if child.tag == "ByValueCondition":
            c = child.only_child(("SimulationTimeCondition", "StoryboardElementStateCondition"))
            if c.tag == "SimulationTimeCondition":
                test = m.SimulationTimeCondition(self.number(c, "value", scope),
                                                 self.rule(c, scope))
            else:
                test = m.StoryboardElementStateCondition(
                    self.value(c, "storyboardElementType", scope, "enum", choices=ELEMENT_TYPES),
                    self.value(c, "storyboardElementRef", scope),
                    self.value(c, "state", scope, "enum", choices=STATES))
                self.state_conditions.append((c, test))
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

    def entity_condition(self, c, scope):
        both = ("euclidianDistance", "cartesianDistance", "longitudinal", "lateral")
        if c.tag == "RelativeDistanceCondition":
            ref = self.entity_ref(c, scope)
            v, free, dtype, rule, system = self.distance_common(
                c, scope, ("euclidianDistance",) + both[1:], ("entity", "road"))
            if "relativeDistanceType" not in c.attrib:
                raise c.error("needs attribute relativeDistanceType")
            return m.RelativeDistanceCondition(ref, v, free, dtype, rule, system)
        if c.tag == "TimeHeadwayCondition":
            ref = self.entity_ref(c, scope)
            v, free, _, rule, system = self.distance_common(c, scope, ("longitudinal",),
                                                            ("entity", "road"))
            return m.TimeHeadwayCondition(ref, v, free, rule, system)
        if c.tag == "TimeToCollisionCondition":
            target = c.need("TimeToCollisionConditionTarget").need("EntityRef")
            ref = self.entity_ref(target, scope)
            v, free, dtype, rule, system = self.distance_common(c, scope, both)
            return m.TimeToCollisionCondition(ref, v, free, rule, dtype, system)
        if c.tag == "ReachPositionCondition":
            return m.ReachPositionCondition(
                self.position(c.need("Position"), scope, world_only="ReachPositionCondition"),
                self.number(c, "tolerance", scope, minimum=0))
        if c.tag == "DistanceCondition":
            v, free, dtype, rule, _ = self.distance_common(c, scope, both)
            return m.DistanceCondition(
                self.position(c.need("Position"), scope, world_only="DistanceCondition"),
                v, free, rule, dtype)
        return m.SpeedCondition(self.number(c, "value", scope), self.rule(c, scope))


class _Override:
    """Stands for the node of a parameter override given to load() (for its messages)."""

    def __init__(self, path, name):
        self.path, self.name = path, name

    def error(self, message):
        return ScenarioError("%s: parameter override %s: %s" % (
            os.path.basename(self.path), self.name, message))


def _without_declarations(node):
    """A catalog entry's node without its ParameterDeclarations (already applied): a copy of
    it (same tag, attributes, file and line) with the other children."""
    stripped = Node(node.tag, node.attrib, node.path, node.line)
    stripped.text = node.text
    stripped.children = [c for c in node.children if c.tag != "ParameterDeclarations"]
    return stripped
