"""Convoy's OpenSCENARIO 1.x subset: reading .xosc files (xosc), executing their storyboard
(storyboard) and mapping EnvironmentActions onto the weather engine (weather).
docs/scenarios.md describes the subset and the semantics."""

from .storyboard import (ActionCommand, ScenarioRuntimeError, StepResult, Storyboard,
                         Transition)
from .weather import environment_to_weather, schedule_entry, weather_config
from .xmltree import ScenarioError
from .xosc import load, loads

__all__ = ["ActionCommand", "ScenarioError", "ScenarioRuntimeError", "StepResult", "Storyboard",
           "Transition", "environment_to_weather", "load", "loads", "schedule_entry",
           "weather_config"]
