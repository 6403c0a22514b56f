"""Pure pursuit along a route, and the pedals that hold a target speed: the controller of
experiments/ros_drive/driver_node.py, apart from ROS.

    route = Route([(x, y), ...])                 # closed when its ends are < 5 m apart
    driver = PurePursuit(route, target_speed=7.0)
    throttle, brake, steer = driver.step(x, y, yaw, speed, dt)

The car's pose (x, y, yaw) is its base_link's, the middle between the axles; pure pursuit
works from the rear axle, WHEELBASE / 2 behind. Each step finds the route point nearest to
the rear axle among the next SEARCH points from the last one (so a route that passes near
itself is followed in order), walks LOOKAHEAD metres along the route from there and steers
the bicycle model's angle onto the circle through that point: atan(2 L sin(alpha) / d).
The pedals drive the speed the car is commanded (the longitudinal model of
convoy_ros.control, which the driver runs alongside: the wheels lag behind it, and a pedal
controller on the measured speed would overshoot) to the target speed as fast as A_MAX and
B_MAX allow, lowered in curves so that the lateral acceleration stays under LATERAL_ACCEL."""
import math

from convoy_ros.control import A_MAX, B_MAX, MAX_STEER, WHEELBASE, clamp, integrate_speed

SEARCH = 40               # route points searched ahead of the last nearest one
CLOSED_GAP = 5.0          # m: a route whose ends are closer is a loop
LOOKAHEAD_MIN = 4.0       # m
LOOKAHEAD_PER_SPEED = 0.6  # s: the look-ahead grows with the speed
LOOKAHEAD_MAX = 12.0      # m
LATERAL_ACCEL = 3.0       # m/s^2


def wrap_angle(a):
    return math.atan2(math.sin(a), math.cos(a))


def yaw_of_quaternion(x, y, z, w):
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Route:
    """A polyline of (x, y) points; closed (a loop) when its ends are near each other."""

    def __init__(self, points):
        self.points = [(float(p[0]), float(p[1])) for p in points]
        if len(self.points) < 2:
            raise ValueError("a route needs at least 2 points, got %d" % len(self.points))
        (x0, y0), (x1, y1) = self.points[0], self.points[-1]
        self.closed = math.hypot(x1 - x0, y1 - y0) < CLOSED_GAP

    def __len__(self):
        return len(self.points)

    def point(self, i):
        n = len(self.points)
        return self.points[i % n] if self.closed else self.points[min(i, n - 1)]

    def nearest(self, x, y, start, count=SEARCH):
        """Index (unwrapped: it grows past len() on a loop) of the point nearest (x, y) among
        start .. start + count."""
        best, best_d = start, float("inf")
        last = start + count if self.closed else min(start + count, len(self.points) - 1)
        for i in range(start, last + 1):
            px, py = self.point(i)
            d = (px - x) ** 2 + (py - y) ** 2
            if d < best_d:
                best, best_d = i, d
        return best

    def ahead(self, index, distance):
        """The point `distance` m along the route from point `index` (interpolated)."""
        left = distance
        i = index
        limit = index + len(self.points)
        while i < limit:
            (ax, ay), (bx, by) = self.point(i), self.point(i + 1)
            seg = math.hypot(bx - ax, by - ay)
            if seg >= left and seg > 0.0:
                f = left / seg
                return ax + f * (bx - ax), ay + f * (by - ay)
            if not self.closed and i + 1 >= len(self.points) - 1:
                return bx, by
            left -= seg
            i += 1
        return self.point(i)


def lookahead_distance(speed):
    return clamp(LOOKAHEAD_MIN + LOOKAHEAD_PER_SPEED * abs(speed), LOOKAHEAD_MIN, LOOKAHEAD_MAX)


def pursuit_steer(rear_x, rear_y, yaw, target_x, target_y):
    """The front-wheel angle that puts the rear axle on the circle through the target (full
    lock towards a target behind)."""
    dx, dy = target_x - rear_x, target_y - rear_y
    d = math.hypot(dx, dy)
    if d < 1e-6:
        return 0.0
    alpha = wrap_angle(math.atan2(dy, dx) - yaw)
    if abs(alpha) > 0.5 * math.pi:  # behind: turn round as tightly as the car can
        return math.copysign(MAX_STEER, alpha)
    return clamp(math.atan2(2.0 * WHEELBASE * math.sin(alpha), d), -MAX_STEER, MAX_STEER)


def pedals(commanded, target, dt):
    """(throttle, brake) in [0, 1] that bring the commanded speed to `target` (m/s) within
    `dt` s, or as close as full throttle / brake get."""
    if dt <= 0.0:
        return 0.0, 0.0
    error = target - commanded
    return clamp(error / (A_MAX * dt), 0.0, 1.0), clamp(-error / (B_MAX * dt), 0.0, 1.0)


def curve_speed(steer, target_speed):
    """The target speed, lowered so that v^2 * tan(steer) / L <= LATERAL_ACCEL."""
    k = abs(math.tan(steer)) / WHEELBASE
    if k < 1e-6:
        return target_speed
    return min(target_speed, math.sqrt(LATERAL_ACCEL / k))


class PurePursuit:
    """Follows `route` at `target_speed`; step() once per control step, in time order."""

    def __init__(self, route, target_speed=7.0):
        self.route = route
        self.target_speed = float(target_speed)
        self.index = None
        self.finished = False
        self.commanded = 0.0  # the speed the pedals so far command (convoy_ros.control)

    def step(self, x, y, yaw, speed, dt):
        """(throttle, brake, steer) for the pose (m, m, rad) and forward speed (m/s), `dt` s
        after the previous step (the first: the loop's step)."""
        rear_x = x - 0.5 * WHEELBASE * math.cos(yaw)
        rear_y = y - 0.5 * WHEELBASE * math.sin(yaw)
        if self.index is None:  # the first step: search the whole route
            self.index = self.route.nearest(rear_x, rear_y, 0, len(self.route) - 1)
        else:
            self.index = self.route.nearest(rear_x, rear_y, self.index)
        n = len(self.route)
        if not self.route.closed and self.index >= n - 1:
            self.finished = True
        if self.finished:
            steer, target = 0.0, 0.0
        else:
            tx, ty = self.route.ahead(self.index, lookahead_distance(speed))
            steer = pursuit_steer(rear_x, rear_y, yaw, tx, ty)
            target = curve_speed(steer, self.target_speed)
        throttle, brake = pedals(self.commanded, target, dt)
        self.commanded = integrate_speed(self.commanded, throttle, brake, False, dt)
        return throttle, brake, steer
