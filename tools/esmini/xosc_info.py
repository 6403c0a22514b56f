"""What the recording needs to know about an OpenSCENARIO file before running esmini on it:
its entities, the controllers assigned to each (esmini's controller type, resolved through the
ControllerCatalog), and whether it is a ParameterValueDistribution. Standard library only;
this reads the files, it does not interpret the storyboard."""

import os
import xml.etree.ElementTree as ET

# Controllers whose input comes from outside the scenario: headless they get none.
INPUT_CONTROLLERS = ("InteractiveController", "ExternalController")


def parse(path):
    with open(path, "rb") as f:
        return ET.fromstring(f.read())


def top_parameters(root):
    decls = root.find("ParameterDeclarations")
    if decls is None:
        return {}
    return {d.get("name"): d.get("value") for d in decls.findall("ParameterDeclaration")}


def resolve(value, params):
    if value and value.startswith("$"):
        return params.get(value[1:], value)
    return value


def catalog_dirs(root, xosc_dir, kind):
    dirs = []
    locations = root.find("CatalogLocations")
    if locations is not None:
        for d in locations.findall("%s/Directory" % kind):
            dirs.append(os.path.normpath(os.path.join(xosc_dir, d.get("path", ""))))
    return dirs


def catalog_entries(dirs, tag):
    """name -> element of every <tag> entry in the catalog files of `dirs`."""
    entries = {}
    for d in dirs:
        if not os.path.isdir(d):
            continue
        for name in sorted(os.listdir(d)):
            if not name.endswith(".xosc"):
                continue
            catalog = parse(os.path.join(d, name)).find("Catalog")
            if catalog is None:
                continue
            for e in catalog.findall(tag):
                entries.setdefault(e.get("name"), e)
    return entries


def controller_type(controller):
    """esmini's controller type of a <Controller>: its esminiController property, else
    its name."""
    for p in controller.iter("Property"):
        if p.get("name") == "esminiController":
            return p.get("value")
    return controller.get("name")


def _controller_of(node, catalog, params):
    """The controller type named by an ObjectController / AssignControllerAction node."""
    inline = node.find("Controller")
    if inline is not None:
        return controller_type(inline)
    ref = node.find("CatalogReference")
    if ref is not None:
        entry = resolve(ref.get("entryName"), params)
        found = catalog.get(entry)
        return controller_type(found) if found is not None else "catalog:%s" % entry
    return None


def _actors(node, parents):
    """Entities an action node applies to: its Private's entityRef, or its ManeuverGroup's
    Actors."""
    while node is not None:
        if node.tag == "Private":
            return [node.get("entityRef")]
        if node.tag == "ManeuverGroup":
            return [e.get("entityRef") for e in node.findall("Actors/EntityRef")]
        node = parents.get(node)
    return []


def scenario_info(path):
    """dict: entities (ScenarioObject names, in file order), controllers (entity -> sorted
    controller types, from ObjectController and AssignControllerAction), distribution (the
    ScenarioFile of a ParameterValueDistribution, else None)."""
    root = parse(path)
    dist = root.find("ParameterValueDistribution")
    if dist is not None:
        scenario_file = dist.find("ScenarioFile")
        return {"entities": [], "controllers": {},
                "distribution": scenario_file.get("filepath") if scenario_file is not None
                else ""}
    params = top_parameters(root)
    xosc_dir = os.path.dirname(os.path.abspath(path))
    catalog = catalog_entries(catalog_dirs(root, xosc_dir, "ControllerCatalog"), "Controller")
    entities = [o.get("name") for o in root.findall("Entities/ScenarioObject")]
    controllers = {}
    for obj in root.findall("Entities/ScenarioObject"):
        for oc in obj.findall("ObjectController"):
            kind = _controller_of(oc, catalog, params)
            if kind:
                controllers.setdefault(obj.get("name"), set()).add(kind)
    parents = {child: parent for parent in root.iter() for child in parent}
    for action in root.iter("AssignControllerAction"):
        kind = _controller_of(action, catalog, params)
        if kind:
            for entity in _actors(action, parents):
                controllers.setdefault(entity, set()).add(kind)
    return {"entities": entities,
            "controllers": {k: sorted(v) for k, v in sorted(controllers.items())},
            "distribution": None}


def has_input_controller(info):
    return any(kind in INPUT_CONTROLLERS for kinds in info["controllers"].values()
               for kind in kinds)


def figure_entities(info):
    """The scenario-controlled entities: named in the file, with no controller or only an
    input controller (which `--ego scenario` replaces by the scenario's own motion)."""
    return [e for e in info["entities"]
            if all(k in INPUT_CONTROLLERS for k in info["controllers"].get(e, ()))]
