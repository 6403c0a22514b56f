"""The Parkring observation of rl_parkring's status functions (observe.py, and
observe_camera.py, which adds the ego camera's frame for convoy_gym's DrivingEnv(camera=...)).

From the car's pose it tracks the Parkring waypoints (the autonomous-driving experiment's
Trajectory) and returns, as one JsonRawData: the time, the pose, the speed, the heading error
towards the waypoint a few points ahead, the distance from the path, the waypoints reached,
a few route points ahead in the car's frame (`ahead`, for convoy_gym's DrivingEnv) and
whether the episode is over (lap done, or more than OFF_TRACK m from the path). It returns
done=True every step, so that each run_loop(1) brings its observation back."""
import math
import os
import sys

from nrp_core.data.nrp_json import JsonRawData

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "autonomous_driving"))
import relateAngle_computation  # noqa: E402
from euler_from_quaternion import euler_from_quaternion  # noqa: E402

OFF_TRACK = 3.0  # m
AHEAD = (1, 2, 4, 8, 12)  # the route points returned, in waypoints (2 m apart) after the target
track = None


def distance_to_path(points, index, x, y):
    """The distance from the route's segments near the target waypoint `index`."""
    n = len(points)
    segments = _segments(points)
    best = math.inf
    for i in range(max(index - 2, 0), index + 2):
        ax, ay, dx, dy, length2 = segments[i % n]
        u = 0.0
        if length2 != 0:  # u = max(0.0, min(1.0, ...)), as the builtins choose
            u = ((x - ax) * dx + (y - ay) * dy) / length2
            u = u if u < 1.0 else 1.0
            u = u if u > 0.0 else 0.0
        d = math.hypot(ax + u * dx - x, ay + u * dy - y)
        if d < best:
            best = d
    return best


_segments_of = (None, None)  # (the points, their segments)


def _segments(points):
    """[(ax, ay, dx, dy, dx * dx + dy * dy)] of the segment from each point to the next (the
    last to the first), computed once per list of points."""
    global _segments_of
    if _segments_of[0] is not points:
        n = len(points)
        out = []
        for i, (ax, ay) in enumerate(points):
            bx, by = points[(i + 1) % n]
            dx, dy = bx - ax, by - ay
            out.append((ax, ay, dx, dy, dx * dx + dy * dy))
        _segments_of = (points, out)
    return _segments_of[1]


def route_ahead(points, index, x, y, yaw):
    """The route points AHEAD waypoints after `index`, in the car's frame ([forward, left] m);
    past the lap's end, the last point."""
    c, s = math.cos(yaw), math.sin(yaw)
    out = []
    for k in AHEAD:
        px, py = points[min(index + k, len(points) - 1)]
        dx, dy = px - x, py - y
        out.append([c * dx + s * dy, -s * dx + c * dy])
    return out


def observation(car, iteration, time_ns):
    """(done, [JsonRawData observation]) for the car's link datapack `car`."""
    global track
    if iteration == 0 or track is None:  # a new episode (start, or after reset())
        track = relateAngle_computation.Trajectory()
    if car.isEmpty():
        return True, []
    link = car.data
    # tolist(): the float32 values as Python floats at once (what float() of each gives)
    x, y = link.pos.tolist()[:2]
    _, _, yaw = euler_from_quaternion(*link.rot.tolist())
    heading_error, _ = track.update(x, y, yaw)
    off_path = distance_to_path(track.points, track.index, x, y)
    vx, vy = link.lin_vel.tolist()[:2]
    speed = math.hypot(vx, vy)
    return True, [JsonRawData({
        "t": time_ns * 1e-9, "x": x, "y": y, "yaw": yaw, "speed": speed,
        "heading_error": heading_error, "off_path": off_path,
        "waypoint": track.index, "waypoints": len(track.points),
        "ahead": route_ahead(track.points, track.index, x, y, yaw),
        "episode_over": track.finished or off_path > OFF_TRACK})]
