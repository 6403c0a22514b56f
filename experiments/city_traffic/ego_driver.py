"""The ego's PID waypoint follower on the city map: the report's follower (section 3.4.2,
experiments/autonomous_driving/car_ctl_engine.py, whose trajectory module it uses unchanged)
on an open route instead of the Parkring's lap. The waypoints are ego_route.csv (convoy-odr
route 1:-1 -> 3:-1, straight through both junctions); the car stops at the route's end.

It publishes the same `actors` datapack as the report's engine (steering angles, rear wheel
speeds at the follower's fixed cruising speed); motor_tf.py (experiments/ego_planner) replaces
that speed with the planner's target."""
import csv
import os
import sys

from nrp_core.engines.python_json import EngineScript

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "autonomous_driving"))
import relateAngle_computation  # noqa: E402
from euler_from_quaternion import euler_from_quaternion  # noqa: E402

WHEEL_RADIUS = 0.3   # m, as the report's engine
MAX_STEER = 0.55     # rad
STEER_GAIN = 1.2
START_X = -150.0     # the ego's start in city_world.sdf: the route is followed from there


def load_route(path, skip=None):
    """The route's points from the ego's start: past START_X (the shipped route), or after
    `skip` points (another route, $CONVOY_EGO_ROUTE_SKIP)."""
    with open(path) as f:
        pts = [(float(r["x"]), float(r["y"])) for r in csv.DictReader(f)]
    if skip is not None:
        return pts[skip:]
    return [p for p in pts if p[0] >= START_X]


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("actors")
        self._setDataPack("actors", {"angular_L": 0, "angular_R": 0, "linear_L": 0, "linear_R": 0})
        self._registerDataPack("state_location")
        self._setDataPack("state_location", {"location_x": 0, "location_y": 0, "qtn_x": 0, "qtn_y": 0,
                                             "qtn_z": 0, "qtn_w": 0})
        # $CONVOY_EGO_ROUTE: another route (a CSV as convoy-odr route writes), e.g. the
        # held-out camera path of tools/dataset (city_world_west.sdf starts the car on it).
        route = os.environ.get("CONVOY_EGO_ROUTE")
        self.points = (load_route(os.path.join(HERE, route), int(os.environ.get("CONVOY_EGO_ROUTE_SKIP", "0")))
                       if route else load_route(os.path.join(HERE, "ego_route.csv")))
        self.trajectory = relateAngle_computation.Trajectory(self.points)
        self.arrived_s = None

    def runLoop(self, timestep_ns):
        state = self._getDataPack("state_location")
        x, y = state["location_x"], state["location_y"]
        yaw = 0.0
        if state["qtn_w"] != 0 or state["qtn_z"] != 0:
            _, _, yaw = euler_from_quaternion(state["qtn_x"], state["qtn_y"], state["qtn_z"], state["qtn_w"])
        rel, _ = self.trajectory.update(x, y, yaw)
        # An open route: the follower's look-ahead would wrap to the start, so the last
        # LOOKAHEAD points end the drive.
        done = self.trajectory.finished or \
            self.trajectory.index >= len(self.points) - relateAngle_computation.LOOKAHEAD
        if done and self.arrived_s is None:
            self.arrived_s = self._time_ns * 1e-9
            print("ego: end of its route at t = %.1f s" % self.arrived_s, flush=True)
        steer = 0.0 if done else max(-MAX_STEER, min(MAX_STEER, STEER_GAIN * rel))
        speed = 0.0 if done else relateAngle_computation.SPEED
        self._setDataPack("actors", {"angular_L": steer, "angular_R": steer,
                                     "linear_L": speed / WHEEL_RADIUS, "linear_R": speed / WHEEL_RADIUS})
