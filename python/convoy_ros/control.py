"""The ros_bridge's control messages as the smart car's joint targets.

Two inputs, as the bridge gives them (JSON datapacks named like their topics):
- convoy_msgs/Control {"throttle", "brake", "steer", "reverse", "stamp"}: a longitudinal model
  turns pedals into a target speed. The speed integrates throttle * A_MAX (in the direction
  of travel chosen by `reverse`) and brake * B_MAX (towards standstill, never past it) over
  the time between two messages' stamps, clamped to [-V_REVERSE, V_MAX]; no pedal keeps the
  speed. The steer is the front-wheel angle, clamped to +-MAX_STEER.
- geometry_msgs/Twist {"linear": [x, y, z], "angular": [x, y, z]}: the speed is linear.x and
  the steer the bicycle model's angle for the yaw rate angular.z,
  atan(WHEELBASE * angular.z / max(|speed|, 0.5)), clamped to +-MAX_STEER.

The smart car (experiments/autonomous_driving/models/smart_car) steers both front wheels to
the same angle and drives both rear wheels at speed / WHEEL_RADIUS (the joints of
experiments/rl_parkring/drive_tf.py)."""
import math

WHEEL_RADIUS = 0.3  # m
WHEELBASE = 2.6     # m, front axle x = 1.3, rear axle x = -1.3
MAX_STEER = 0.55    # rad
A_MAX = 3.0         # m/s^2 at full throttle
B_MAX = 6.0         # m/s^2 at full brake
V_MAX = 15.0        # m/s
V_REVERSE = 3.0     # m/s, the most in reverse
MIN_TWIST_SPEED = 0.5  # m/s, the speed under which a yaw rate is steered as at this speed

STEERING_JOINTS = ("front_left_steering_joint", "front_right_steering_joint")
WHEEL_JOINTS = ("rear_left_wheel_joint", "rear_right_wheel_joint")
JOINT_PREFIX = "smart_car_joint_plugin::"


def clamp(value, low, high):
    return max(low, min(high, value))


def clamp_steer(steer):
    return clamp(float(steer), -MAX_STEER, MAX_STEER)


def integrate_speed(speed, throttle, brake, reverse, dt):
    """The target speed after `dt` s of the pedals (throttle, brake in [0, 1], clamped)."""
    throttle = clamp(float(throttle), 0.0, 1.0)
    brake = clamp(float(brake), 0.0, 1.0)
    dt = max(0.0, float(dt))
    v = speed + (-1.0 if reverse else 1.0) * throttle * A_MAX * dt
    slow = brake * B_MAX * dt
    if v > 0.0:
        v = max(0.0, v - slow)
    elif v < 0.0:
        v = min(0.0, v + slow)
    return clamp(v, -V_REVERSE, V_MAX)


def twist_to_drive(twist):
    """(speed m/s, steer rad) of a Twist datapack {"linear": [...], "angular": [...]}."""
    speed = float(twist["linear"][0])
    yaw_rate = float(twist["angular"][2])
    steer = math.atan(WHEELBASE * yaw_rate / max(abs(speed), MIN_TWIST_SPEED))
    return clamp(speed, -V_REVERSE, V_MAX), clamp_steer(steer)


class ControlModel:
    """Integrates Control messages into a target speed. update() takes each step's datapack.
    A stamped message integrates over the time since the previous stamp, and not at all when
    seen before (same stamp: no new message came). The first message, and an unstamped one
    (stamp 0: in synchronous mode, one per step), integrate over `step_dt` (the loop's step)."""

    def __init__(self, step_dt=0.02):
        self.step_dt = step_dt
        self.speed = 0.0
        self.steer = 0.0
        self.stamp = None

    def _dt(self, stamp):
        if stamp <= 0.0 or self.stamp is None:
            return self.step_dt
        return stamp - self.stamp if stamp > self.stamp else 0.0

    def update(self, control):
        """(speed, steer) after the Control datapack `control` (a dict)."""
        stamp = float(control.get("stamp", 0.0))
        dt = self._dt(stamp)
        if stamp > 0.0 and (self.stamp is None or stamp > self.stamp):
            self.stamp = stamp
        self.speed = integrate_speed(self.speed, control.get("throttle", 0.0),
                                     control.get("brake", 0.0), bool(control.get("reverse")), dt)
        self.steer = clamp_steer(control.get("steer", 0.0))
        return self.speed, self.steer


def joint_targets(speed, steer):
    """{full joint name: (field, value)}: the steering joints' position, the rear wheels'
    angular velocity."""
    out = {}
    for joint in STEERING_JOINTS:
        out[JOINT_PREFIX + joint] = ("position", clamp_steer(steer))
    for joint in WHEEL_JOINTS:
        out[JOINT_PREFIX + joint] = ("velocity", float(speed) / WHEEL_RADIUS)
    return out
