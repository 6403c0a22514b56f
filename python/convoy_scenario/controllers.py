"""What a scenario's controllers mean in Convoy (docs/scenarios.md, "Controllers").

An entity's controller is its ObjectController, else the first AssignControllerAction of its
Init. Its type is the controller's Property `esminiController` when it has one, else its name
(esmini's convention; a ControllerCatalog entry keeps the name of the entry). The kinds:

- none, or a type not below: "default": the scenario moves the entity exactly (the player);
- esmini's driver models (ACCController, ALKSController, ALKS_R157SM_Controller,
  FollowRouteController, SloppyDriverController, NaturalDriver, OffroadFollower,
  FollowGhostController, ...) and any `convoy.*` controller: "driver": the entity is a
  `vehicle_agent` engine, its own AI between the scenario's actions; the controller's
  Properties named `convoy.<Key>` set that key of the agent, and the driver model's own
  parameters that have a counterpart are mapped (AGENT_KEYS);
- InteractiveController, ExternalController, UDPDriverController...: "external": on the ego,
  the system under test drives; on another entity Convoy has no such input and the scenario
  moves it (default) — reported.

`convoy run --scenario FILE --ego scenario` moves every entity with the player whatever its
controller (as esmini with --disable_controllers); the default run honours the kinds."""

DRIVER_TYPES = {"ACCController", "ALKSController", "ALKS_R157SM_Controller", "FollowRouteController",
                "SloppyDriverController", "NaturalDriver", "OffroadFollower", "FollowGhostController",
                "HIDController", "LooMController", "ControllerRel2Abs", "SumoController"}
EXTERNAL_TYPES = {"InteractiveController", "ExternalController", "UDPDriverController"}
# the driver models' parameters with a vehicle_agent counterpart: (property, agent key, scale)
AGENT_KEYS = (("timeGap", "T", 1.0), ("setSpeed", "v0", 1.0))


def controller_of(scenario, entity):
    """The entity's Controller (ObjectController, else its Init AssignControllerAction), or
    None."""
    ent = scenario.entity(entity)
    for _, c in getattr(ent, "controllers", ()):
        if c is not None:
            return c
    for a in scenario.init:
        if a.entity == entity and type(a.spec).__name__ == "AssignControllerAction":
            if a.spec.controller is not None:
                return a.spec.controller
    return None


def controller_type(controller):
    props = dict(controller.properties or ())
    return props.get("esminiController") or controller.name


def kind(controller):
    """"default", "driver" or "external"."""
    if controller is None:
        return "default"
    ctype = controller_type(controller)
    if ctype.startswith("convoy.") or any(k.startswith("convoy.") for k, _ in controller.properties or ()):
        return "driver"
    if ctype in DRIVER_TYPES:
        return "driver"
    if ctype in EXTERNAL_TYPES or "external" in ctype.lower() or "interactive" in ctype.lower():
        return "external"
    return "default"


def agent_keys(controller):
    """vehicle_agent config keys from a driver controller's Properties."""
    out = {}
    props = dict(controller.properties or ())
    for name, key, scale in AGENT_KEYS:
        if name in props:
            try:
                out[key] = float(props[name]) * scale
            except ValueError:
                pass
    for name, value in props.items():
        if name.startswith("convoy."):
            try:
                out[name[len("convoy."):]] = float(value)
            except ValueError:
                out[name[len("convoy."):]] = value
    return out
