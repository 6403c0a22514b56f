"""An OpenSCENARIO EnvironmentAction as the `weather` engine's state keys (docs/weather.md,
docs/scenarios.md "Weather").

Rules (only what the Environment gives is set; the engine keeps the rest):
- Precipitation: type ``dry`` -> Precipitation 0; ``rain`` / ``snow`` -> PrecipitationType and
  Precipitation = the 1.0 ``intensity`` (0-1), else the 1.1 ``precipitationIntensity`` in mm/h
  over MM_H_HEAVY (10 mm/h, heavy rain) capped at 1.
- Fog visualRange (m) -> Visibility (m).
- Sun elevation (rad) -> SunAltitude (degrees, clamped to [-90, 90]); azimuth (rad, 0 north,
  pi/2 east) -> SunAzimuth (compass degrees, [0, 360)).
- TimeOfDay dateTime -> TimeOfDay (hours of its clock time), only when no Sun is given (the
  engine takes one or the other; the Sun's angles are the more exact).
- Wind direction (rad, where it blows towards, from world +x) -> WindDirection (degrees);
  speed -> WindSpeed (m/s).
- RoadCondition frictionScaleFactor f -> Surface whose friction is nearest f x 0.8 (the
  engine's dry asphalt): dry 0.8, wet 0.5, snow 0.25, ice 0.1 (ties go to the wetter one).
- Cloud state, temperature, pressure and sun illuminance have no engine key and are dropped.
"""

import math
import re

MM_H_HEAVY = 10.0
DRY_MU = 0.8
SURFACES = (("dry", 0.8), ("wet", 0.5), ("snow", 0.25), ("ice", 0.1))


def surface_for_friction(factor):
    """The weather engine's surface nearest in friction to factor x dry asphalt."""
    mu = factor * DRY_MU
    best = None
    for name, value in SURFACES:
        if best is None or abs(mu - value) <= abs(mu - best[1]):
            best = (name, value)
    return best[0]


def hours_of(date_time):
    """Clock time of an xsd:dateTime as hours (``2025-06-13T18:30:00`` -> 18.5)."""
    m = re.search(r"T(\d\d):(\d\d):(\d\d(?:\.\d+)?)", date_time)
    if not m:
        raise ValueError("not a dateTime: %r" % date_time)
    return int(m.group(1)) + int(m.group(2)) / 60.0 + float(m.group(3)) / 3600.0


def environment_to_weather(env):
    """The weather engine's keys for a model.Environment (a dict, keys in a fixed order)."""
    out = {}
    w = env.weather
    if w is not None and w.precipitation is not None:
        p = w.precipitation
        if p.type == "dry":
            out["Precipitation"] = 0.0
        else:
            value = p.intensity if p.intensity is not None else p.intensity_mm_h / MM_H_HEAVY
            out["Precipitation"] = min(1.0, max(0.0, value))
            out["PrecipitationType"] = p.type
    if w is not None and w.fog_visual_range is not None:
        out["Visibility"] = w.fog_visual_range
    if w is not None and w.sun is not None:
        out["SunAltitude"] = max(-90.0, min(90.0, math.degrees(w.sun.elevation)))
        out["SunAzimuth"] = math.degrees(w.sun.azimuth) % 360.0
    elif env.time_of_day is not None:
        out["TimeOfDay"] = hours_of(env.time_of_day[1])
    if w is not None and w.wind is not None:
        out["WindDirection"] = math.degrees(w.wind[0])
        out["WindSpeed"] = w.wind[1]
    if env.friction_scale_factor is not None:
        out["Surface"] = surface_for_friction(env.friction_scale_factor)
    return out


def weather_config(scenario):
    """The weather engine's initial keys from the scenario's Init EnvironmentActions (later
    ones override earlier keys)."""
    out = {}
    for action in scenario.init:
        if action.entity is None and hasattr(action.spec, "environment"):
            out.update(environment_to_weather(action.spec.environment))
    return out


def schedule_entry(env, time_s, transition_s=0.0):
    """A weather engine `Schedule` entry applying env at time_s (seconds of simulated time)."""
    entry = {"Time": float(time_s)}
    if transition_s:
        entry["Transition"] = float(transition_s)
    entry.update(environment_to_weather(env))
    return entry
