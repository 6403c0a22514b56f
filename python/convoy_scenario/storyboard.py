"""Executing an OpenSCENARIO storyboard over simulated time (docs/scenarios.md, "Execution").

``Storyboard(scenario).step(t, world)`` advances to time t (strictly increasing) given every
entity's state in ``world`` ({name: {"x", "y", "yaw", "speed"[, "vx", "vy", "length",
"width", "length_offset", "road", "lane", "s", "t"]}}; the box defaults to the scenario's
BoundingBox) and returns a StepResult: the actions started, running and ended, and the
state transitions, in a deterministic order. The executor moves no entity.

Rules:
- States standbyState, runningState, completeState; transitions startTransition
  (standby -> running), endTransition (running -> complete, or -> standby while executions
  are left), stopTransition (standby or running -> complete), skipTransition (standby ->
  standby, an Event of priority skip triggered while another Event of its Maneuver runs).
  A Transition records (time, type, element path, transition, from, to).
- The storyboard starts at the first step (its Init actions start then); a Story starts
  with it; an Act when its StartTrigger is true (at once without one); a ManeuverGroup and a
  Maneuver when their parent runs; an Event when its StartTrigger is true (at once without
  one) while its Maneuver runs. A start resets the element's descendants to standby with
  no executions. Events of priority overwrite (override) end the running Events of their
  Maneuver (endTransition, as esmini: back to standby while executions are left; their
  actions end, their runs are stopped); skip does not start while one runs; parallel starts
  regardless.
- Goals: an Action ends when all its runs (one per actor) have reached their goal
  (convoy_scenario.actions); an Event when all its Actions are complete, and so on up to the
  storyboard. maximumExecutionCount (ManeuverGroup, Event) counts starts: an element that
  ends with executions left goes back to standby and starts again by the rules above (the
  next step at the earliest).
- StopTriggers: the storyboard's stops every element (stopTransition, parents before
  children) and every run; an Act's stops the Act and its descendants, when it is true
  while the Act is in standby or running.
- A run on an actor stops the actor's runs of other actions sharing a control domain; an
  Action left without runs by such overrides takes the stopTransition.
- Conditions are evaluated as esmini does: a trigger when the storyboard reaches it in its
  walk of the tree at each step (the storyboard's StopTrigger first, then each Act's
  StopTrigger while it runs and StartTrigger while in standby, then its Events' StartTriggers
  while their Maneuver runs), against the world at t and the states as they are at that point
  of the walk: a StoryboardElementStateCondition sees every transition made since it was last
  evaluated, this step's earlier ones included (so a chain of elements triggered by each
  other's start moves within one step); with a state it is true when one of those changes
  went to the state, else while the element is in it; with a transition, when one of those
  changes was that transition. A condition is evaluated at most once a step. Then the edge: none passes the value; rising is true when it is true
  and was false at the previous step, falling the opposite, risingOrFalling on either; an
  edge is never detected at the first evaluation. Then the delay: each step whose edge
  output is true fires the condition once, at the first step with time >= its time +
  delay. A trigger is the OR of its ConditionGroups, each the AND of its conditions.
- Entity conditions: each triggering entity's value, combined by triggeringEntitiesRule
  (any / all). Rules treat values within EQUAL_TOLERANCE (1e-6) as equal: greaterThan
  is a > b and not equal, greaterOrEqual a > b or equal, and so on.
"""

import math
from dataclasses import dataclass, field
from typing import List, Optional

from . import conditions as conds
from .storyboard_triggers import EQUAL_TOLERANCE, TriggerEvaluation, _Cond, _Outputs, compare  # noqa: F401
from . import geometry as g
from . import model as m
from .actions import ActionRun, InstantRun, make_run
from .xmltree import ScenarioError

STANDBY, RUNNING, COMPLETE = "standbyState", "runningState", "completeState"
TIME_EPS = 1e-9


class ScenarioRuntimeError(ScenarioError):
    """The world does not give what the storyboard needs (an entity, or a key of its state)."""


@dataclass(frozen=True)
class Transition:
    time: float
    element_type: str        # storyboard, story, act, maneuverGroup, maneuver, event, action
    element: str             # its path (Story::Act::...), "Storyboard" for the storyboard
    transition: str          # startTransition, endTransition, stopTransition, skipTransition
    from_state: str
    to_state: str


@dataclass(frozen=True)
class ActionCommand:
    action: str              # the Action's path, or "Init[i]" for the i-th Init action
    kind: str                # SpeedAction, LaneChangeAction, ...
    actor: Optional[str]     # None for a global action
    start_time: float
    target: dict             # at this step's time (convoy_scenario.actions)
    spec: object


@dataclass
class StepResult:
    time: float
    started: List[ActionCommand] = field(default_factory=list)
    running: List[ActionCommand] = field(default_factory=list)
    ended: List[tuple] = field(default_factory=list)   # (action, actor, "end" or "stop")
    transitions: List[Transition] = field(default_factory=list)
    done: bool = False


class _Element:
    def __init__(self, etype, path, spec, max_count=1, parent=None):
        self.type, self.path, self.spec = etype, path, spec
        self.max_count, self.parent = max_count, parent
        self.children = []
        self.state = STANDBY
        self.count = 0


_LEGACY_INSTANT = (m.TeleportAction, m.AssignRouteAction, m.EnvironmentAction)


class _DoneRun(ActionRun):
    """An action that ends at once with no target from the executor: one the storyboard
    executed itself (ParameterAction, VariableAction, traffic signal actions), or one whose
    run the player has yet to give (controllers, appearance, trailers, traffic...). The
    command still carries the spec."""

    def update(self, t, env):
        return {}, True


class _Env:
    """The world at one step, as Bodies, with errors that name who needed what."""

    def __init__(self, scenario, world, t):
        self.scenario, self.world, self.t = scenario, world, t
        self.bodies = {}

    def error(self, user, message):
        where = getattr(user, "where", "") or ""
        name = getattr(user, "name", "")
        return ScenarioRuntimeError("t=%g: %s%s: %s" % (
            self.t, name, " (%s)" % where if where else "", message))

    def body(self, name, user):
        if name in self.bodies:
            return self.bodies[name]
        state = self.world.get(name)
        if state is None:
            raise self.error(user, "the world has no state for entity %r" % name)
        for key in ("x", "y", "yaw", "speed"):
            if key not in state:
                raise self.error(user, "entity %r's state has no %r" % (name, key))
        bbox = self.scenario.entity(name).object.bounding_box
        speed, yaw = float(state["speed"]), float(state["yaw"])
        opt = lambda k, conv: conv(state[k]) if state.get(k) is not None else None  # noqa: E731
        body = g.Body(
            name, float(state["x"]), float(state["y"]), yaw, speed,
            float(state.get("vx", speed * math.cos(yaw))),
            float(state.get("vy", speed * math.sin(yaw))),
            float(state.get("length", bbox.length)), float(state.get("width", bbox.width)),
            float(state.get("length_offset", bbox.center[0])), bbox.center[1],
            opt("road", str), opt("lane", lambda v: str(int(v))), opt("s", float),
            opt("t", float))
        self.bodies[name] = body
        return body

    def need(self, body, key, user):
        value = getattr(body, key)
        if value is None:
            raise self.error(user, "entity %r's state has no %r" % (body.name, key))
        return value


class Storyboard(TriggerEvaluation):
    """The mutable execution state of one scenario's storyboard (the Scenario is not
    changed)."""

    def __init__(self, scenario, end_on_complete=True, resolve_position=None):
        """end_on_complete False: the storyboard stays running when all its stories are
        complete and ends by its StopTrigger only (as esmini plays it). resolve_position
        (model position, world) -> (x, y): the player's resolver of road, lane and route
        positions in conditions (the storyboard resolves world and entity-relative ones)."""
        self.scenario = scenario
        self.end_on_complete = end_on_complete
        self.resolve_position = resolve_position
        self.parameters = dict(scenario.parameters)
        self.variables = {name: value for name, _, value in scenario.variables}
        self.signals = {}              # traffic signal id -> state set by an action
        self.controller_start = {c.name: (c.delay, 0)
                                 for c in scenario.traffic_signal_controllers}
        self.since = {}                # (condition, entity) -> time its state began to hold
        self.group_actors = {}         # maneuverGroup path -> its actors this execution
        self.act_entities = {}         # act path -> the entities that made it start
        self.root = _Element("storyboard", "Storyboard", None)
        self.elements = {}
        self.conditions = []
        self._cond_index = {}
        for story in scenario.stories:
            s = self._add("story", story, self.root)
            for act in story.acts:
                a = self._add("act", act, s)
                for grp in act.groups:
                    gr = self._add("maneuverGroup", grp, a, grp.maximum_execution_count)
                    for man in grp.maneuvers:
                        mn = self._add("maneuver", man, gr)
                        for ev in man.events:
                            e = self._add("event", ev, mn, ev.maximum_execution_count)
                            for action in ev.actions:
                                self._add("action", action, e)
        self._collect(scenario.stop_trigger)
        for story in scenario.stories:
            for act in story.acts:
                self._collect(act.start_trigger)
                self._collect(act.stop_trigger)
                for grp in act.groups:
                    for man in grp.maneuvers:
                        for ev in man.events:
                            self._collect(ev.start_trigger)
        self.runs = []                # active runs, in start order
        self.last_time = None
        self.log = []                 # (element key, transition, to state) of every change
        self.done = False

    def _add(self, etype, spec, parent, max_count=1):
        el = _Element(etype, spec.path, spec, max_count, parent)
        parent.children.append(el)
        self.elements[(etype, spec.path)] = el
        return el

    def _collect(self, trigger):
        if trigger is None:
            return
        for group in trigger.groups:
            for cond in group:
                self._cond_index[id(cond)] = len(self.conditions)
                self.conditions.append(_Cond(cond))

    def state(self, etype, path):
        """The state of the element of type etype at path ("Storyboard" for the storyboard)."""
        if etype == "storyboard":
            return self.root.state
        return self.elements[(etype, path)].state

    def execution_count(self, etype, path):
        return self.elements[(etype, path)].count

    # --- conditions ------------------------------------------------------------------------

    # --- transitions -----------------------------------------------------------------------

    def _record(self, el, transition, to_state):
        self._result.transitions.append(Transition(self._t, el.type, el.path, transition,
                                                   el.state, to_state))
        self.log.append(((el.type, el.path), transition, to_state))
        el.state = to_state

    def _reset(self, el):
        for c in el.children:
            c.state, c.count = STANDBY, 0
            self._reset(c)

    def _start(self, el):
        self._record(el, "startTransition", RUNNING)
        el.count += 1
        self._reset(el)

    def _end(self, el):
        self._record(el, "endTransition", STANDBY if el.count < el.max_count else COMPLETE)

    def _stop(self, el):
        if el.state != COMPLETE:
            self._record(el, "stopTransition", COMPLETE)
        if el.type == "action":
            self._drop_runs(lambda r: r.element is el, "stop")
        for c in el.children:
            if c.state != COMPLETE:
                self._stop(c)

    def _drop_runs(self, match, reason):
        keep = []
        for r in self.runs:
            if match(r):
                r.active = False
                self._result.ended.append((r.name, r.actor, reason))
            else:
                keep.append(r)
        self.runs = keep

    def _start_run(self, name, spec, actor, element, where, env):
        if isinstance(spec, m.STORYBOARD_ACTIONS):
            conds.execute(self, spec, self._t)
            run = _DoneRun(name, spec, actor, self._t, env, where)
        else:
            run = make_run(name, spec, actor, self._t, env, where)
            if type(run) is InstantRun and not isinstance(spec, _LEGACY_INSTANT):
                run = _DoneRun(name, spec, actor, self._t, env, where)
        run.element = element
        if actor is not None and run.domains:
            clash = [r for r in self.runs if r.actor == actor and r.domains & run.domains
                     and (element is None or r.element is not element)]
            for r in clash:
                r.overridden = True
            self._drop_runs(lambda r: r in clash, "stop")
            for r in clash:
                el = r.element
                if el is not None and el.state == RUNNING and \
                        not any(x.element is el for x in self.runs):
                    self._stop(el)
        self.runs.append(run)
        self._started.append(run)

    # --- stepping --------------------------------------------------------------------------

    def step(self, t, world):
        """Advance to time t with the entities' states in world; a StepResult."""
        t = float(t)
        if self.last_time is not None and not t > self.last_time:
            raise ValueError("step times must increase: %g after %g" % (t, self.last_time))
        self.last_time = t
        self._t = t
        self._result = result = StepResult(t)
        self._started = []
        self._commands = {}
        if self.done:
            result.done = True
            return result
        env = _Env(self.scenario, world, t)
        outputs = _Outputs(self, t, env)
        if self.root.state == STANDBY:
            self._start(self.root)
            for i, action in enumerate(self.scenario.init):
                self._start_run("Init[%d]" % i, action.spec, action.entity, None, action.where,
                                env)
        if self._trigger(self.scenario.stop_trigger, outputs, False):
            self._stop(self.root)
            self._drop_runs(lambda r: True, "stop")
        else:
            for story in self.root.children:
                if story.state == STANDBY:
                    self._start(story)
                if story.state == RUNNING:
                    for act in story.children:
                        self._act(act, outputs, env)
        self._update_runs(env)
        self._settle(self.root)
        self.done = self.root.state == COMPLETE
        if self.done:
            self._drop_runs(lambda r: True, "stop")
        result.done = self.done
        result.started = [self._commands[id(r)] for r in self._started
                          if id(r) in self._commands]
        return result

    def _act(self, act, outputs, env):
        spec = act.spec
        if act.state != COMPLETE and self._trigger(spec.stop_trigger, outputs, False):
            self._stop(act)
            return
        if act.state == STANDBY and self._trigger(spec.start_trigger, outputs, True):
            self._start(act)
            self.act_entities[act.path] = self._triggering_entities(spec.start_trigger, outputs)
        if act.state != RUNNING:
            return
        for group in act.children:
            if group.state == STANDBY:
                self._start(group)
                actors = group.spec.actors
                if group.spec.select_triggering_entities:
                    actors = tuple(dict.fromkeys(actors + self.act_entities.get(act.path, ())))
                self.group_actors[group.path] = actors
            if group.state != RUNNING:
                continue
            for man in group.children:
                if man.state == STANDBY:
                    self._start(man)
                if man.state != RUNNING:
                    continue
                for ev in man.children:
                    if ev.state == STANDBY and self._trigger(ev.spec.start_trigger, outputs, True):
                        self._start_event(ev, man, group, env)

    def _start_event(self, ev, man, group, env):
        others = [o for o in man.children if o is not ev and o.state == RUNNING]
        if ev.spec.priority == "skip" and others:
            self._record(ev, "skipTransition", STANDBY)
            return
        if ev.spec.priority == "overwrite":
            for o in others:
                self._end_overridden(o)
        self._start(ev)
        for action in ev.children:
            self._start(action)
            spec = action.spec
            actors = self.group_actors.get(group.path, group.spec.actors) \
                if spec.private else (None,)
            for actor in actors:
                self._start_run(spec.path, spec.spec, actor, action, spec.where, env)

    def _end_overridden(self, ev):
        """An Event overwritten by another of its Maneuver ends (as esmini: it can run again
        while it has executions left); its running actions end, their runs are stopped."""
        for action in ev.children:
            if action.state == RUNNING:
                self._drop_runs(lambda r: r.element is action, "stop")
                self._record(action, "endTransition", COMPLETE)
        self._end(ev)

    def _update_runs(self, env):
        finished = []
        self._commands = {}
        for r in self.runs:
            target, done = r.update(self._t, env)
            cmd = ActionCommand(r.name, type(r.spec).__name__, r.actor, r.t0, target, r.spec)
            self._commands[id(r)] = cmd
            self._result.running.append(cmd)
            if done:
                finished.append(r)
        self._drop_runs(lambda r: r in finished, "end")

    def _settle(self, el):
        for c in el.children:
            self._settle(c)
        if el.state != RUNNING:
            return
        if el.type == "action":
            if not any(r.element is el for r in self.runs):
                self._end(el)
        elif el is self.root and not self.end_on_complete:
            return
        elif all(c.state == COMPLETE for c in el.children):
            self._end(el)
