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
  file they are written in. The LogicFile must exist; when its path does not, its file name
  is looked for in the scenario's folder and in ../xodr beside it (as esmini does).
- CatalogReference (xosc_catalogs): every ``*.xosc`` file of the catalog directories of the
  referenced kind is searched (sorted by name) for ``<Catalog name=catalogName>`` and in it
  the entry named entryName. The entry's ParameterDeclarations see only themselves;
  ParameterAssignments (evaluated where the reference stands) set them.
- Storyboard element names: each element's path is its name and its ancestors' joined by
  ``::`` (Story::Act::Group::Maneuver::Event::Action) and must be unique. A
  StoryboardElementStateCondition's storyboardElementRef is a name or a ``::`` path suffix
  and must match exactly one element of its type.
- Entity references (Private, Actors, TriggeringEntities, conditions, relative targets and
  positions) must name a ScenarioObject.
- A ParameterValueDistribution file is read as its ScenarioFile with the distribution's
  first variant (xosc_distribution).

The reader is split by topic: xosc_catalogs, xosc_entities, xosc_positions, xosc_actions,
xosc_global (global actions and the environment), xosc_conditions.
"""

import os
import re

from . import model as m
from . import schema
from .params import ParameterError, Scope, TYPES, convert, resolve
from .xmltree import ScenarioError, parse_bytes, parse_file
from .xosc_actions import ActionsReader
from .xosc_catalogs import CatalogReader
from .xosc_conditions import ConditionsReader, ELEMENT_TYPES, RULES, STATES  # noqa: F401
from .xosc_distribution import first_variant
from .xosc_entities import EntitiesReader, VEHICLE_CATEGORIES  # noqa: F401
from .xosc_global import GlobalReader
from .xosc_positions import PositionsReader

_REQUIRED = object()


_LOADED = {}          # (path, mtime, size, parameters) -> Scenario: read once per process
_LOADED_MAX = 8


def load(path, parameters=None):
    """The Scenario of the .xosc file at path; ScenarioError when it is outside the subset
    or wrong. parameters ({name: value}) override the values of global parameters (as a
    ParameterAssignment does: the value is converted to the declared type). A file read
    before in this process (same path, modification time, size and parameters) is not read
    again: the Scenario is immutable, so it is shared."""
    path = os.path.abspath(path)
    key = _load_key(path, parameters)
    if key is not None and key in _LOADED:
        return _LOADED[key]
    scenario = _read(path, parse_file(path), parameters)
    if key is not None:
        if len(_LOADED) >= _LOADED_MAX:
            _LOADED.pop(next(iter(_LOADED)))
        _LOADED[key] = scenario
    return scenario


def _load_key(path, parameters):
    try:
        st = os.stat(path)
        return (path, st.st_mtime_ns, st.st_size, repr(sorted((parameters or {}).items())))
    except OSError:
        return None


def loads(text, path, parameters=None):
    """The Scenario of the .xosc text, as if read from path (for messages and relative
    paths)."""
    path = os.path.abspath(path)
    data = text.encode("utf-8") if isinstance(text, str) else text
    return _read(path, parse_bytes(data, path), parameters)


def _read(path, root, parameters):
    if root.tag == "OpenSCENARIO" and root.find("ParameterValueDistribution") is not None:
        schema.check(root)
        scenario_path, variant = first_variant(root.find("ParameterValueDistribution"), path)
        values = dict(variant)
        values.update(parameters or {})
        return _read(scenario_path, parse_file(scenario_path), values)
    return _Reader(path).read(root, parameters)


class _Reader(EntitiesReader, CatalogReader, PositionsReader, ActionsReader, GlobalReader,
              ConditionsReader):
    def __init__(self, path):
        self.path = path
        self.catalog_dirs = []       # (kind, absolute directory, Directory node)
        self.catalog_files = {}      # path -> root Node
        self.entities = {}
        self.elements = {t: [] for t in ELEMENT_TYPES}
        self.state_conditions = []   # (node, condition) resolved once all elements are known
        self.deferred = []           # checks run once every entity is known
        self.global_types = {}       # global parameter -> type (ParameterAction/Condition)
        self.variable_types = {}     # variable -> type
        self.signal_controllers = {}
        self.global_scope = Scope()
        self.context = ""            # the path whose trigger is being read

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

    def boolean(self, node, attr, scope, default=_REQUIRED):
        return self.value(node, attr, scope, "boolean", default)

    def entity_ref(self, node, scope, attr="entityRef"):
        name = self.value(node, attr, scope)
        if name not in self.entities:
            raise node.error("%s: no entity %r (entities: %s)" % (
                attr, name, ", ".join(self.entities) or "none"))
        return name

    def declare(self, decls, scope, assignments=None, lenient=False):
        """A new scope under scope with the ParameterDeclarations node decls (may be None);
        assignments (name -> (value, node)) replace declared values. A name declared twice
        takes the later declaration (esmini reads such files). lenient (catalog entries): a
        value that is not of the declared type is kept as a string parameter (esmini does
        not check the types; its controller catalog declares a double 'FollowMode' =
        "time")."""
        inner = Scope(scope)
        assignments = dict(assignments or {})
        for d in (decls.findall("ParameterDeclaration") if decls is not None else []):
            name = self.value(d, "name", inner)
            if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
                raise d.error("name: %r is not a parameter name" % name)
            ptype = self.value(d, "parameterType", inner, "enum", choices=TYPES)
            if name in assignments:
                raw, anode = assignments.pop(name)
            else:
                raw, anode = self.value(d, "value", inner), d
            try:
                inner.values[name] = (ptype, convert(raw, ptype))
            except ParameterError as e:
                if not lenient:
                    raise anode.error("value: %s" % e) from None
                inner.values[name] = ("string", convert(raw, "string"))
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
        scope = self.globals(root.find("ParameterDeclarations"), overrides)
        variables = self.variables(root.find("VariableDeclarations"), scope)
        locations = root.find("CatalogLocations")
        if locations is not None:
            for kind_node in locations.children:
                for d in kind_node.findall("Directory"):
                    self.catalog_dirs.append((kind_node.tag,
                                              self.catalog_dir(self.value(d, "path", scope)), d))
        logic, scene, controllers = self.road_network(root.find("RoadNetwork"), scope)
        entities = [self.scenario_object(obj, scope)
                    for obj in root.need("Entities").findall("ScenarioObject")]
        for check in self.deferred:
            check()
        board = root.need("Storyboard")
        init = self.init(board.need("Init"), scope)
        stories = tuple(self.story(s, scope) for s in board.findall("Story"))
        self.context = ""
        stop = self.trigger(board.find("StopTrigger"), scope)
        for node, cond, context in self.state_conditions:
            object.__setattr__(cond, "element_path", self.find_element(
                node, cond.element_type, cond.element_ref, context))
        return m.Scenario(path=self.path, header=header,
                          parameters=tuple(sorted(scope.flat().items())), logic_file=logic,
                          scene_graph_file=scene, entities=tuple(entities), init=init,
                          stories=stories, stop_trigger=stop,
                          catalog_dirs=tuple((k, d) for k, d, _ in self.catalog_dirs),
                          variables=variables, traffic_signal_controllers=controllers,
                          parameter_types=tuple(sorted(self.global_types.items())))

    def globals(self, decls, overrides):
        overrides = {name: (value if isinstance(value, str) else
                            ("true" if value is True else "false") if isinstance(value, bool)
                            else repr(value), _Override(self.path, name))
                     for name, value in (overrides or {}).items()}
        declared = {d.attrib.get("name") for d in
                    (decls.findall("ParameterDeclaration") if decls is not None else [])}
        for name in overrides:
            if name not in declared:
                raise ScenarioError("%s: parameter override %s: the file declares no global "
                                    "parameter %s (it declares: %s)" % (
                                        os.path.basename(self.path), name, name,
                                        ", ".join(sorted(n for n in declared if n)) or "none"))
        scope = self.declare(decls, Scope(), overrides)
        self.global_types = {k: t for k, (t, _) in scope.values.items()}
        self.global_scope = scope
        return scope

    def variables(self, decls, scope):
        out = []
        for d in (decls.findall("VariableDeclaration") if decls is not None else []):
            name = self.value(d, "name", scope)
            if name in self.variable_types:
                raise d.error("name: variable %s is declared twice" % name)
            vtype = self.value(d, "variableType", scope, "enum", choices=TYPES)
            self.variable_types[name] = vtype
            out.append((name, vtype, self.value(d, "value", scope, vtype)))
        return tuple(out)

    def road_network(self, network, scope):
        logic = scene = None
        if network is None:
            return None, None, ()
        if network.find("LogicFile") is not None:
            node = network.find("LogicFile")
            given = self.value(node, "filepath", scope)
            logic = self.locate_map(given)
            if logic is None:
                raise node.error("filepath: no such file %s" % self.rel(given))
        if network.find("SceneGraphFile") is not None:
            scene = self.rel(self.value(network.find("SceneGraphFile"), "filepath", scope))
        signals = network.find("TrafficSignals")
        controllers = ()
        if signals is not None:
            controllers = tuple(self.signal_controller(c, scope)
                                for c in signals.findall("TrafficSignalController"))
        return logic, scene, controllers

    def locate_map(self, given):
        """The LogicFile's path: as given (relative to the scenario), else its file name in
        the scenario's folder or in ../xodr beside it (esmini's layout); None if none."""
        first = self.rel(given)
        if os.path.isfile(first):
            return first
        name = os.path.basename(given.replace("\\", "/"))
        for d in (".", os.path.join("..", "xodr")):
            candidate = self.rel(os.path.join(d, name))
            if os.path.isfile(candidate):
                return candidate
        return None

    def catalog_dir(self, given):
        """A catalog Directory: as given (relative to the scenario), else, when that does not
        exist, Catalogs/<its last folder> beside the scenario (esmini's resources layout)."""
        first = self.rel(given)
        if os.path.isdir(first):
            return first
        alt = self.rel(os.path.join("Catalogs", os.path.basename(first.rstrip("/\\"))))
        return alt if os.path.isdir(alt) else first

    def rel(self, p, base=None):
        return os.path.normpath(os.path.join(os.path.dirname(base or self.path), p))

    def header(self, node):
        s = Scope()
        major = self.value(node, "revMajor", s, "unsignedShort")
        if major != 1:
            raise node.error("revMajor: only OpenSCENARIO 1.x is supported, got %d" % major)
        lic = node.find("License")
        license_ = None
        if lic is not None:
            license_ = tuple(self.value(lic, a, s, default="")
                             for a in ("name", "resource", "spdxId", "text"))
            if not license_[0]:
                raise lic.error("needs attribute name")
        return m.FileHeader(major, self.value(node, "revMinor", s, "unsignedShort"),
                            self.value(node, "date", s, default=""),
                            self.value(node, "description", s, default=""),
                            self.value(node, "author", s, default=""), license_,
                            self.properties(node.find("Properties"), s))

    def init(self, node, scope):
        out = []
        actions = node.find("Actions")
        for child in (actions.children if actions is not None else []):
            if child.tag == "GlobalAction":
                out.append(m.InitAction(None, self.global_action(child, scope), child.where()))
            else:
                name = self.entity_ref(child, scope)
                for pa in child.findall("PrivateAction"):
                    out.append(m.InitAction(name, self.private_action(pa, scope), pa.where()))
        return tuple(out)

    # --- storyboard ------------------------------------------------------------------------

    def register(self, node, etype, path):
        """The element's unique path: a second element of the same type and path (esmini
        accepts such files) gets ``#2`` appended, a third ``#3``..."""
        unique, n = path, 1
        while unique in self.elements[etype]:
            n += 1
            unique = "%s#%d" % (path, n)
        self.elements[etype].append(unique)
        return unique

    def find_element(self, node, etype, ref, context=""):
        """The path of the element of type etype that ref names (a name or a path suffix);
        of several, those nearest to the referring condition (context: the path of the
        element whose trigger holds it; a catalog maneuver used by several groups refers to
        its own events), which must be one."""
        hits = [p for p in self.elements[etype]
                if re.sub(r"#\d+$", "", p) == ref or re.sub(r"#\d+$", "", p).endswith("::" + ref)
                or p == ref or p.endswith("::" + ref)]
        if not hits:
            raise node.error("storyboardElementRef: no %s named %r" % (etype, ref))
        if len(hits) > 1 and context:
            near = max(_shared(p, context) for p in hits)
            hits = [p for p in hits if _shared(p, context) == near]
        if len(hits) > 1:
            raise node.error("storyboardElementRef: %r names %d %ss (%s): give its path"
                             % (ref, len(hits), etype, ", ".join(hits)))
        return hits[0]

    def named(self, node, scope, parent_path, etype):
        name = self.value(node, "name", scope)
        if not name or "::" in name:
            raise node.error("name: %r is not a usable name" % name)
        path = parent_path + "::" + name if parent_path else name
        return name, self.register(node, etype, path)

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
        self.context = path
        return m.Act(name, path, groups, self.trigger(node.find("StartTrigger"), scope),
                     self.trigger(node.find("StopTrigger"), scope), node.where())

    def group(self, node, scope, parent):
        name, path = self.named(node, scope, parent, "maneuverGroup")
        count = self.value(node, "maximumExecutionCount", scope, "unsignedInt", 1)
        if count < 1:
            raise node.error("maximumExecutionCount: must be >= 1, got %d" % count)
        actors, select = [], False
        a = node.find("Actors")
        if a is not None:
            select = self.boolean(a, "selectTriggeringEntities", scope, False)
            actors = [self.entity_ref(e, scope) for e in a.findall("EntityRef")]
        has_actors = bool(actors) or select
        maneuvers = []
        for child in node.children:
            if child.tag == "Maneuver":
                maneuvers.append(self.maneuver(child, scope, path, has_actors))
            elif child.tag == "CatalogReference":
                entry, escope, _ = self.catalog_entry(child, scope, ("Maneuver",))
                maneuvers.append(self.maneuver(entry, escope, path, has_actors))
        return m.ManeuverGroup(name, path, count, tuple(actors), tuple(maneuvers), node.where(),
                               select)

    def maneuver(self, node, scope, parent, has_actors):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        name, path = self.named(node, scope, parent, "maneuver")
        events = tuple(self.event(e, scope, path, has_actors) for e in node.findall("Event"))
        if not events:
            raise node.error("needs at least one <Event>")
        return m.Maneuver(name, path, events, node.where())

    def event(self, node, scope, parent, has_actors):
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
                spec, private = self.global_action(child, scope), False
            else:
                if not has_actors:
                    raise a.error("is a PrivateAction, but its ManeuverGroup has no actors")
                spec, private = self.private_action(child, scope), True
            actions.append(m.Action(aname, apath, spec, private, a.where()))
        if not actions:
            raise node.error("needs at least one <Action>")
        self.context = path
        return m.Event(name, path, "overwrite" if priority == "override" else priority, count,
                       tuple(actions), self.trigger(node.find("StartTrigger"), scope),
                       node.where())


def _shared(path, context):
    """How many leading ``::`` segments path and context share."""
    n = 0
    for a, b in zip(re.sub(r"#\d+$", "", path).split("::"),
                    re.sub(r"#\d+$", "", context).split("::")):
        if a != b:
            break
        n += 1
    return n


class _Override:
    """Stands for the node of a parameter override given to load() (for its messages)."""

    def __init__(self, path, name):
        self.path, self.name = path, name

    def error(self, message):
        return ScenarioError("%s: parameter override %s: %s" % (
            os.path.basename(self.path), self.name, message))
