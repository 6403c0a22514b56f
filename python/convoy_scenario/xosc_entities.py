"""Entities for the reader (xosc.py): ScenarioObjects (Vehicle, Pedestrian, MiscObject or a
CatalogReference to one), their ObjectControllers, controllers, trailers, bounding boxes
and Properties."""

from . import model as m
from . import schema

VEHICLE_CATEGORIES = ("car", "van", "truck", "trailer", "semitrailer", "bus", "motorbike",
                      "bicycle", "train", "tram")
MISC_CATEGORIES = ("none", "obstacle", "pole", "tree", "vegetation", "barrier", "building",
                   "parkingSpace", "patch", "railing", "trafficIsland", "crosswalk",
                   "streetLamp", "gantry", "soundBarrier", "wind", "roadMark")
ROLES = ("none", "ambulance", "civil", "fire", "military", "police", "publicTransport",
         "roadAssistance")


class EntitiesReader:
    def scenario_object(self, node, scope):
        name = self.value(node, "name", scope)
        if name in self.entities:
            raise node.error("name: entity %r is declared twice" % name)
        child = node.only_child(("Vehicle", "Pedestrian", "MiscObject", "CatalogReference"))
        source = None
        if child.tag == "CatalogReference":
            child, entry_scope, source = self.catalog_entry(
                child, scope, ("Vehicle", "Pedestrian", "MiscObject"))
        else:
            entry_scope = scope
        if child.tag == "Vehicle":
            kind, obj = "vehicle", self.vehicle(child, entry_scope)
        elif child.tag == "Pedestrian":
            kind, obj = "pedestrian", self.pedestrian(child, entry_scope)
        else:
            kind, obj = "misc", self.misc_object(child, entry_scope)
        controllers = tuple(self.object_controller(c, scope)
                            for c in node.findall("ObjectController"))
        entity = m.Entity(name, kind, obj, source, controllers)
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
        hitch, coupler = node.find("TrailerHitch"), node.find("TrailerCoupler")
        return m.Vehicle(
            name=self.value(node, "name", scope),
            category=self.value(node, "vehicleCategory", scope, "enum",
                                choices=VEHICLE_CATEGORIES),
            bounding_box=self.bounding_box(node.need("BoundingBox"), scope),
            performance=m.Performance(self.number(perf, "maxSpeed", scope, minimum=0),
                                      self.number(perf, "maxAcceleration", scope, minimum=0),
                                      self.number(perf, "maxDeceleration", scope, minimum=0)),
            axles=tuple(axles), properties=self.properties(node.find("Properties"), scope),
            model3d=self.value(node, "model3d", scope, default=None),
            mass=self.number(node, "mass", scope, None, minimum=0),
            role=self.value(node, "role", scope, "enum", None, ROLES),
            trailer_hitch=self.number(hitch, "dx", scope) if hitch is not None else None,
            trailer_coupler=self.number(coupler, "dx", scope) if coupler is not None else None,
            trailer=self.trailer(node.find("Trailer"), scope))

    def trailer(self, node, scope):
        """A Vehicle's Trailer: TrailerRef (an entity, checked once all are read; an empty
        entityRef is no trailer), an inline Trailer with its Vehicle, or a CatalogReference
        to a vehicle."""
        if node is None:
            return None
        child = node.only_child(("Trailer", "TrailerRef", "CatalogReference"))
        if child.tag == "TrailerRef":
            name = self.value(child, "entityRef", scope)
            if not name:
                return None
            self.deferred.append(lambda: self.entity_ref(child, scope))
            return m.Trailer(entity=name)
        if child.tag == "CatalogReference":
            entry, escope, _ = self.catalog_entry(child, scope, ("Vehicle",))
            return m.Trailer(vehicle=self.vehicle(entry, escope))
        inner = child.only_child(("Vehicle", "CatalogReference"))
        if inner.tag == "CatalogReference":
            inner, escope, _ = self.catalog_entry(inner, scope, ("Vehicle",))
        else:
            escope = scope
        return m.Trailer(entity=self.value(child, "name", scope),
                         vehicle=self.vehicle(inner, escope))

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

    def misc_object(self, node, scope):
        scope = self.declare(node.find("ParameterDeclarations"), scope)
        return m.MiscObject(
            name=self.value(node, "name", scope),
            category=self.value(node, "miscObjectCategory", scope, "enum",
                                choices=MISC_CATEGORIES),
            mass=self.number(node, "mass", scope, minimum=0),
            bounding_box=self.bounding_box(node.need("BoundingBox"), scope),
            properties=self.properties(node.find("Properties"), scope),
            model3d=self.value(node, "model3d", scope, default=None))

    # --- controllers -----------------------------------------------------------------------

    def controller(self, node, scope, source=None):
        """A Controller element, or a CatalogReference to one."""
        if node.tag == "CatalogReference":
            node, scope, source = self.catalog_entry(node, scope, ("Controller",))
        else:
            scope = self.declare(node.find("ParameterDeclarations"), scope)
        return m.Controller(self.value(node, "name", scope),
                            self.value(node, "controllerType", scope, default=None),
                            self.properties(node.find("Properties"), scope), source)

    def object_controller(self, node, scope):
        child = node.only_child(("Controller", "CatalogReference"))
        ctrl = self.controller(child, scope)
        return (self.value(node, "name", scope, default=ctrl.name), ctrl)
