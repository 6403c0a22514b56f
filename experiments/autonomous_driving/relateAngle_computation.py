"""The pre-defined trajectory and the target relative steering angle (report section 3.4.2).

The trajectory is the list of waypoints along the driving lane, generated from
parkring.xodr by the project's OpenDRIVE tool (`convoy-odr waypoints --lane -1`, done by the
build into share/convoy/models/parkring_road/waypoints_lane-1.csv). When the car comes
within ARRIVAL_RADIUS (0.8 m) of the current target point, or has passed it, the index jumps
to the next point, until the final destination (one lap)."""
import csv
import math
import os

ARRIVAL_RADIUS = 0.8  # m
SPEED = 6.0           # m/s, the fixed cruising speed
LOOKAHEAD = 3         # steer towards the point this many waypoints ahead of the target


def default_waypoint_file():
    share = os.environ.get("CONVOY_SHARE_DIR", "")
    return os.path.join(share, "models", "parkring_road", "waypoints_lane-1.csv")


def load_waypoints(path=None):
    path = path or default_waypoint_file()
    with open(path) as f:
        return [(float(r["x"]), float(r["y"])) for r in csv.DictReader(f)]


class Trajectory:
    def __init__(self, waypoints=None):
        self.points = waypoints if waypoints is not None else load_waypoints()
        self.index = 1  # the first point is the start
        self.finished = False

    def update(self, x, y, yaw):
        """Returns (relative angle to the target in rad, distance to it in m)."""
        n = len(self.points)
        while not self.finished:
            tx, ty = self.points[self.index % n]
            dx, dy = tx - x, ty - y
            ahead = dx * math.cos(yaw) + dy * math.sin(yaw)
            if math.hypot(dx, dy) < ARRIVAL_RADIUS or ahead < 0:
                self.index += 1
                if self.index >= n + 1:  # back at the start: the lap is complete
                    self.finished = True
                continue
            break
        if self.finished:
            return 0.0, 0.0
        lx, ly = self.points[min(self.index + LOOKAHEAD, n) % n]
        target = math.atan2(ly - y, lx - x)
        rel = math.atan2(math.sin(target - yaw), math.cos(target - yaw))
        tx, ty = self.points[self.index % n]
        return rel, math.hypot(tx - x, ty - y)
