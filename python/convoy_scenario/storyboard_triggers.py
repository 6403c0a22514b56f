"""The storyboard's triggers (docs/scenarios.md, "Execution"): each condition evaluated when the
storyboard's walk reaches it, at most once a step, through its edge and delay; triggers as ORs
of ConditionGroups, ANDs within (esmini's order). A mixin of storyboard.Storyboard, which owns
the state it reads (elements, the log of state changes, parameters, signals)."""

from . import conditions as conds
from . import model as m
from .conditions_geometry import geometric_value

TIME_EPS = 1e-9
EQUAL_TOLERANCE = 1e-6

_ISSUE25_CONDITIONS = (m.TraveledDistanceCondition, m.EndOfRoadCondition, m.OffroadCondition,
                       m.StandStillCondition, m.CollisionCondition, m.AccelerationCondition,
                       m.RelativeSpeedCondition, m.RelativeClearanceCondition)


class _Cond:
    def __init__(self, spec):
        self.spec = spec
        self.seen = 0              # state conditions: changes of the log already seen
        self.previous = None
        self.pending = []          # (fire time, the entities that made it true)
        self.entities = ()         # the entities that made it true at this step
        self.fired_entities = ()


class _Outputs:
    """The conditions' outputs at one step, each evaluated when first asked for."""

    def __init__(self, board, t, env):
        self.board, self.t, self.env = board, t, env
        self.values = {}

    def __getitem__(self, i):
        if i not in self.values:
            self.values[i] = self.board._evaluate(self.board.conditions[i], self.t, self.env)
        return self.values[i]


def compare(a, rule, b):
    """a rule b, where values within EQUAL_TOLERANCE of each other are equal."""
    equal = a == b or abs(a - b) <= EQUAL_TOLERANCE
    if rule == "greaterThan":
        return a > b and not equal
    if rule == "lessThan":
        return a < b and not equal
    if rule == "greaterOrEqual":
        return a > b or equal
    if rule == "lessOrEqual":
        return a < b or equal
    return equal if rule == "equalTo" else not equal


class TriggerEvaluation:
    def _state_condition(self, cs, test):
        """A StoryboardElementStateCondition on the changes since cs was last evaluated."""
        key = (test.element_type, test.element_path)
        new = [c for c in self.log[cs.seen:] if c[0] == key]
        cs.seen = len(self.log)
        if test.state.endswith("State"):
            if new:
                return any(c[2] == test.state for c in new)
            return self.state(*key) == test.state
        return any(c[1] == test.state for c in new)

    def _raw(self, cs, t, env):
        """(value, the triggering entities whose value is true)."""
        c = cs.spec
        test = c.test
        if isinstance(test, m.SimulationTimeCondition):
            return compare(t, test.rule, test.value), ()
        if isinstance(test, m.StoryboardElementStateCondition):
            return self._state_condition(cs, test), ()
        if not c.triggering:
            return conds.value_condition(self, test, t, env, c, compare), ()
        values = [self._entity_value(c, test, name, env) for name in c.triggering]
        true = tuple(n for n, v in zip(c.triggering, values) if v)
        return (any(values) if c.triggering_rule == "any" else all(values)), true

    def signal_state(self, signal, t):
        return conds.signal_state(self, signal, t)

    def controller_phase(self, name, t):
        return conds.controller_phase(self, name, t)

    def _entity_value(self, c, test, name, env):
        if isinstance(test, _ISSUE25_CONDITIONS):
            return conds.entity_value(self, c, test, name, env, compare)
        return geometric_value(self, c, test, name, env, compare)

    def _evaluate(self, cs, t, env):
        """The condition's output at this step: its value through its edge and delay."""
        c = cs.spec
        value, entities = self._raw(cs, t, env)
        value = bool(value)
        prev = cs.previous
        if c.edge == "none":
            edged = value
        elif prev is None:
            edged = False
        elif c.edge == "rising":
            edged = value and not prev
        elif c.edge == "falling":
            edged = prev and not value
        else:
            edged = value != prev
        cs.previous = value
        if edged:
            cs.pending.append((t + c.delay, entities))
        due = [p for p in cs.pending if p[0] <= t + TIME_EPS]
        fired = bool(due)
        cs.fired_entities = tuple(dict.fromkeys(e for p in due for e in p[1]))
        cs.pending = [p for p in cs.pending if p[0] > t + TIME_EPS]
        return fired

    def _triggering_entities(self, trigger, outputs):
        """The entities that made trigger true this step: of every ConditionGroup that is
        true, its entity conditions' triggering entities whose value was true (document
        order, each once)."""
        if trigger is None:
            return ()
        out = []
        for group in trigger.groups:
            if all(outputs.values.get(self._cond_index[id(c)]) for c in group):
                for c in group:
                    out.extend(self.conditions[self._cond_index[id(c)]].fired_entities)
        return tuple(dict.fromkeys(out))

    def _trigger(self, trigger, outputs, default):
        """OR of the groups (every group evaluated), AND within a group (after a false
        condition only those with a delay are evaluated: their timers run), as esmini."""
        if trigger is None:
            return default
        result = False
        for group in trigger.groups:
            value = bool(group)
            for c in group:
                if value or c.delay > 0:
                    value = outputs[self._cond_index[id(c)]] and value
            result = result or value
        return result
