"""Catalog references for the reader (xosc.py): finding an entry of a catalog by its
catalog's name and the entry's name, with its parameters set by the reference."""

import os

from . import model as m
from . import schema
from .params import Scope
from .xmltree import Node, parse_file

# entry element -> the CatalogLocations kind whose directories hold it
CATALOG_KIND = {"Vehicle": "VehicleCatalog", "Pedestrian": "PedestrianCatalog",
                "MiscObject": "MiscObjectCatalog", "Controller": "ControllerCatalog",
                "Environment": "EnvironmentCatalog", "Maneuver": "ManeuverCatalog",
                "Trajectory": "TrajectoryCatalog", "Route": "RouteCatalog"}


class CatalogReader:
    def assignments(self, ref, scope):
        """name -> (value, node) of a reference's ParameterAssignments. A parameterRef
        written as ``$name`` names the parameter name (esmini's examples do this)."""
        out = {}
        if ref.find("ParameterAssignments") is not None:
            for a in ref.find("ParameterAssignments").findall("ParameterAssignment"):
                raw = a.attrib.get("parameterRef", "")
                if raw.startswith("$") and not raw.startswith("${"):
                    name = raw[1:]
                else:
                    name = self.value(a, "parameterRef", scope)
                out[name] = (self.value(a, "value", scope), a)
        return out

    def catalog_entry(self, ref, scope, tags):
        """(entry node, its scope, CatalogSource) of a CatalogReference to an entry whose
        element is one of tags (Vehicle, Pedestrian, Controller, Route, ...)."""
        catalog = self.value(ref, "catalogName", scope)
        entry = self.value(ref, "entryName", scope)
        assignments = self.assignments(ref, scope)
        kinds = [CATALOG_KIND[t] for t in tags]
        dirs = [(k, d, n) for k, d, n in self.catalog_dirs if k in kinds]
        if not dirs:
            raise ref.error("catalogName: %r: the file has no %s directory in "
                            "<CatalogLocations>" % (catalog, _either(kinds)))
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
                if cat is None or (self.value(cat, "name", Scope()) != catalog
                                   and fname != catalog + ".xosc"):
                    continue
                names = []
                for item in cat.children:
                    if item.tag not in tags:
                        continue
                    item_name = item.attrib.get("name", "")
                    names.append(item_name)
                    if item_name == entry:
                        inner = self.declare(item.find("ParameterDeclarations"),
                                             Scope(self.global_scope), assignments,
                                             lenient=True)
                        # the entry reads its own declarations only once: pass the filled scope
                        item = _without_declarations(item)
                        return item, inner, m.CatalogSource(
                            catalog, entry, fpath,
                            tuple(sorted((k, v) for k, (_, v) in inner.values.items())))
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


def _either(kinds):
    return kinds[0] if len(kinds) == 1 else "%s or %s" % (", ".join(kinds[:-1]), kinds[-1])


def _without_declarations(node):
    """A catalog entry's node without its ParameterDeclarations (already applied): a copy of
    it (same tag, attributes, file and line) with the other children."""
    stripped = Node(node.tag, node.attrib, node.path, node.line)
    stripped.text = node.text
    stripped.children = [c for c in node.children if c.tag != "ParameterDeclarations"]
    return stripped
