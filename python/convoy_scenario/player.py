"""The player: the scenario's default controller for the entities the scenario engine moves
itself (exact scenario control, as esmini's default controller; docs/scenarios.md "The
player"). It keeps every such entity's state, gives the storyboard its world, and applies
the storyboard's actions over each step:

    player = Player(scenario, roads, names, dt)       # Init positions and speeds applied
    world = player.world()                            # states at t
    result = board.step(t, dict(world, **others))
    player.advance(result, t, dt)                     # states at t + dt

Order within a step (esmini's): the actions started at t act on the step from t to t + dt;
actions that move an entity themselves (a lane change, a trajectory) carry it; the others
leave it to travel speed x dt along its lane. Velocities and accelerations are the
differences over the step."""

import math

from . import model as m
from .geometry import _separated
from .player_follow import (LaneOffsetMove, LateralDistanceMove, LongDistanceMove,
                            SpeedProfileMove, SynchronizeMove)
from .player_moves import LaneChangeMove, SpeedMove, TrajectoryMove, perf_limits
from .player_positions import resolve
from .player_routes import RoutePath
from .player_shapes import shape_points
from .player_state import EntityState, LaneMover, angle_diff, wrap


def _box(entity):
    bb = entity.object.bounding_box
    return bb.length, bb.width, bb.center[0]


def box_collisions(world):
    """{entity: [entities whose bounding boxes overlap its own]} of world states (x, y, yaw,
    length, width, length_offset)."""
    boxes = {}
    for n, w in world.items():
        c, s = math.cos(w["yaw"]), math.sin(w["yaw"])
        off = w.get("length_offset", 0.0)
        cx, cy = w["x"] + off * c, w["y"] + off * s
        hl, hw = w.get("length", 0.0) / 2.0, w.get("width", 0.0) / 2.0
        boxes[n] = [(cx + a * c - b * s, cy + a * s + b * c)
                    for a, b in ((hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw))]
    out = {n: [] for n in boxes}
    names = sorted(boxes)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if not _separated(boxes[a], boxes[b]):
                out[a].append(b)
                out[b].append(a)
    return out


# the order moves act in within a step: speeds, then lateral offsets, then moves that carry the
# entity along their own path
SPEED_MOVES = (SpeedMove, LongDistanceMove, SynchronizeMove, SpeedProfileMove)
LATERAL_MOVES = (LaneOffsetMove, LateralDistanceMove)
PATH_MOVES = (LaneChangeMove, TrajectoryMove)


class Player:
    def __init__(self, scenario, roads, names, dt=0.05):
        self.scenario, self.roads = scenario, roads
        self.movers = LaneMover(roads)
        self.names = sorted(names)
        # every entity an action may refer to: the player's own (states) and the others, which
        # start where their Init puts them and then are where observe() says
        self.everyone = {e.name: EntityState(e.name, *_box(e)) for e in scenario.entities}
        self.states = {n: self.everyone[n] for n in self.names}
        self.moves = {}            # (action, actor) -> move
        self.routes = {}           # (closed, waypoints) -> RoutePath
        self.settling = set()      # speed moves whose runs ended before their speed settled
        self.perf = {e.name: getattr(e.object, "performance", None) for e in scenario.entities}
        for a in scenario.init:
            if a.entity in self.everyone:
                self._instant(a.spec, self.everyone[a.entity])

    # --- the world -------------------------------------------------------------------------

    def world(self):
        """Every entity's state for the storyboard; `finished`: the actions whose moves are
        done (actions.MoveRun ends them)."""
        done = {}
        for (action, actor), mv in self.moves.items():
            if getattr(mv, "done", False):
                done.setdefault(actor, []).append(action)
        out = {}
        for n, st in self.states.items():
            out[n] = st.as_world()
            out[n]["finished"] = done.get(n, [])
        return out

    def controls(self, name):
        return name in self.states

    def observe(self, world):
        """The states of the entities other engines move (the ego, agents), for the actions
        that refer to them: {name: state dict (x, y, yaw, speed, road, lane, s, t...)}."""
        for name, w in world.items():
            if name in self.states:
                continue
            ref = self.everyone.get(name)
            if ref is None:
                ref = self.everyone[name] = EntityState(name, *_box(self.scenario.entity(name)))
            ref.x, ref.y, ref.z, ref.h = w["x"], w["y"], w.get("z", 0.0), w["yaw"]
            ref.speed, ref.vx, ref.vy = w["speed"], w.get("vx", 0.0), w.get("vy", 0.0)
            ref.placed = True
            ref.road = w.get("road")
            if ref.road is not None:
                ref.lane, ref.s, ref.road_t = int(w["lane"]), float(w["s"]), float(w.get("t", 0.0))
                try:
                    ref.offset = ref.road_t - self.roads.lane_info(ref.road, ref.lane, ref.s)["centre_t"]
                    ref.h_rel = angle_diff(ref.h, self.roads.lane_pose(ref.road, ref.lane, ref.s)[3])
                except Exception:  # noqa: BLE001 - a lane the map does not have: off the lanes
                    ref.road = None

    # --- actions ---------------------------------------------------------------------------

    def _instant(self, spec, st):
        """Actions with an immediate effect: teleports, step speed changes, routes."""
        if isinstance(spec, m.TeleportAction):
            self.place(st, spec.position)
        elif isinstance(spec, m.SpeedAction) and spec.dynamics.shape == "step":
            st.speed = SpeedMove(spec, st, self.everyone, self.perf[st.name]).target()
        elif isinstance(spec, m.AssignRouteAction):
            st.route = self._route_lanes(st, spec)
        elif isinstance(spec, m.FollowTrajectoryAction) and not st.placed:
            # an entity that only follows a trajectory starts at its beginning
            pts = shape_points(spec, self.world_pose_of, (st.x, st.y, st.z, st.h))
            if pts:
                x, y, z, h, _ = pts[0]
                self.movers.place_world(st, x, y, z, h)

    def driving_lanes(self, road, s):
        """Ids of the driving lanes of road at s (conditions that need the map)."""
        try:
            return [ln for ln in self.roads.lanes_at(road, s)
                    if ln != 0 and self.roads.lane_info(road, ln, s)["type"] == "driving"]
        except Exception:  # noqa: BLE001 - no such road (or no map): no lanes
            return []

    def resolve_xy(self, position, world=None):
        """(x, y) of a model position now (the storyboard's resolve_position)."""
        p = resolve(position, self.everyone, self.roads, self)
        if p.get("road") is None:
            return p["x"], p["y"]
        x, y = self.roads.lane_pose(p["road"], p["lane"], p["s"], p.get("offset", 0.0))[:2]
        return x, y

    def acquire(self, st, position):
        """AcquirePositionAction: a route from where the entity is to the position."""
        p = resolve(position, self.everyone, self.roads, self)
        if st.road is None:
            return
        if p.get("road") is None:
            loc = self.roads.locate(p["x"], p["y"], heading=p.get("h"))
            if loc is None:
                return
            p = {"road": loc["road"], "lane": loc["lane"], "s": loc["s"]}
        st.route = RoutePath(self.roads, [(st.road, st.lane, st.s),
                                          (str(p["road"]), int(p["lane"]), float(p["s"]))])

    def world_pose_of(self, position):
        """(x, y, z, h or None) of a model position now."""
        p = resolve(position, self.everyone, self.roads, self)
        if p.get("road") is None:
            return p["x"], p["y"], p.get("z") or 0.0, p.get("h")
        x, y, z, h, _ = self.roads.lane_pose(p["road"], p["lane"], p["s"], p.get("offset", 0.0))
        return x, y, z, h + p.get("h_rel", 0.0)

    def place(self, st, position):
        p = resolve(position, self.everyone, self.roads, self)
        if p.get("road") is not None:
            self.movers.place_lane(st, p["road"], p["lane"], p["s"], p.get("offset", 0.0),
                                   p.get("h_rel", 0.0))
        else:
            self.movers.place_world(st, p["x"], p["y"], p.get("z"), p.get("h"))

    def route_path(self, route):
        """The RoutePath of a Route (or AssignRouteAction: its waypoints), made once."""
        key = (route.closed, route.waypoints)   # by value (frozen model objects)
        if key not in self.routes:
            pts = []
            for w in route.waypoints:
                p = resolve(w.position, self.everyone, self.roads, self)
                if p.get("road") is None:
                    loc = self.roads.locate(p["x"], p["y"], heading=p.get("h"))
                    if loc is None:
                        continue
                    p = {"road": loc["road"], "lane": loc["lane"], "s": loc["s"]}
                pts.append((str(p["road"]), int(p["lane"]), float(p["s"])))
            self.routes[key] = RoutePath(self.roads, pts)
        return self.routes[key]

    def _route_lanes(self, st, spec):
        return self.route_path(spec)

    def _start(self, c, t):
        st = self.states[c.actor]
        spec = c.spec
        key = (c.action, c.actor)
        if isinstance(spec, m.SpeedAction):
            continuous = isinstance(spec.target, m.RelativeTargetSpeed) and spec.target.continuous
            if not c.action.startswith("Init[") or spec.dynamics.shape != "step" or continuous:
                self.moves[key] = SpeedMove(spec, st, self.everyone, self.perf[c.actor])
        elif isinstance(spec, m.LaneChangeAction):
            self.moves[key] = LaneChangeMove(spec, st, self.everyone, self.movers, self.roads)
        elif isinstance(spec, m.FollowTrajectoryAction):
            pts = shape_points(spec, self.world_pose_of, (st.x, st.y, st.z, st.h))
            self.moves[key] = TrajectoryMove(spec, st, t, self.movers, pts)
        elif isinstance(spec, m.LaneOffsetAction):
            self.moves[key] = LaneOffsetMove(spec, st, self.everyone, self.roads)
        elif isinstance(spec, m.LongitudinalDistanceAction):
            self.moves[key] = LongDistanceMove(spec, st, self.everyone, self.movers)
        elif isinstance(spec, m.LateralDistanceAction):
            self.moves[key] = LateralDistanceMove(spec, st, self.everyone, self.roads)
        elif isinstance(spec, m.SynchronizeAction):
            self.moves[key] = SynchronizeMove(spec, st, self.everyone, self.world_pose_of)
        elif isinstance(spec, m.SpeedProfileAction):
            self.moves[key] = SpeedProfileMove(spec, st, self.everyone, perf_limits(self.perf[c.actor]))
        elif isinstance(spec, m.AcquirePositionAction):
            self.acquire(st, spec.position)
        elif not c.action.startswith("Init["):
            self._instant(spec, st)

    def advance(self, result, t, dt):
        """Applies a StepResult of the storyboard at t and moves every entity to t + dt."""
        for action, actor, how in result.ended:
            mv = self.moves.get((action, actor))
            if how == "end" and isinstance(mv, SpeedMove) and not mv.done:
                continue   # ended within the storyboard's tolerance: the speed still settles
            self.moves.pop((action, actor), None)
        for c in result.started:
            if c.actor in self.states:
                self._start(c, t)
        before = {n: (st.x, st.y, st.vx, st.vy) for n, st in self.states.items()}
        moved = {n: set() for n in self.states}
        for group in SPEED_MOVES, LATERAL_MOVES, PATH_MOVES:
            for (action, actor), mv in list(self.moves.items()):
                if isinstance(mv, group) and "longitudinal" not in moved[actor]:
                    moved[actor].update(mv.step(self.states[actor], dt))
        for n, st in self.states.items():
            if "longitudinal" not in moved[n] and st.placed and abs(st.speed) > 1e-9:
                left = self.movers.move_along(st, st.speed * dt)
                if st.end_of_road and abs(left) > 1e-9:
                    st.speed = 0.0
            self._derive(st, before[n], dt)
        self._collisions()
        # lane changes that are done no longer move the entity; a speed change that is done
        # and whose run the storyboard ended is dropped
        ended = {(a, b) for a, b, _ in result.ended}
        for key, mv in list(self.moves.items()):
            if (isinstance(mv, LaneChangeMove) and mv.done) or \
                    (isinstance(mv, SpeedMove) and mv.done and key in ended | self.settling):
                self.moves.pop(key)
                self.settling.discard(key)
            elif isinstance(mv, SpeedMove) and key in ended:
                self.settling.add(key)

    def _collisions(self):
        """Each entity's `collisions`: the entities whose bounding boxes overlap its own."""
        placed = {n: st.as_world() for n, st in self.states.items() if st.placed}
        touching = box_collisions(placed)
        for n, st in self.states.items():
            st.collisions = touching.get(n, [])

    @staticmethod
    def _derive(st, before, dt):
        x0, y0, vx0, vy0 = before
        if dt <= 0:
            return
        step = math.hypot(st.x - x0, st.y - y0)
        st.odometer += step
        st.vx, st.vy = (st.x - x0) / dt, (st.y - y0) / dt
        if step > 20.0 * max(1.0, abs(st.speed) * dt):   # a teleport: velocity from heading
            st.vx, st.vy = st.speed * math.cos(st.h), st.speed * math.sin(st.h)
        st.ax, st.ay = (st.vx - vx0) / dt, (st.vy - vy0) / dt
        st.h = wrap(st.h)
