"""The planner's target speed applied to the report's PID waypoint follower: steering is the
follower's (car_ctl_engine's `actors`); the rear wheels turn at the planner's target speed,
which replaces the follower's fixed cruising speed (0 once the follower has finished its lap).

The smart car's wheel joints are velocity-controlled with P = 10 only, so alone the car's
speed follows the wheels' with a 1.6 s lag (0.6 m/s^2 per m/s of difference). A proportional
speed loop on the ego's measured speed (SPEED_GAIN) shortens it to about 0.55 s; the wheel
target stays within [target - MAX_UNDER, target + MAX_OVER], and is 0 once the car is (nearly)
stopped with a target of 0, so it never drives backwards. While the planner changes lanes its
target carries "steer" (rad), which replaces the follower's steering (convoy_traffic.lane_change)."""
from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack

WHEEL_RADIUS = 0.3  # m, as car_ctl_engine.py
SPEED_GAIN = 2.0
MAX_OVER = 3.0      # m/s
MAX_UNDER = 8.0     # m/s


@EngineDataPack(keyword='actors', id=DataPackIdentifier('actors', 'car_ctl_engine'))
@EngineDataPack(keyword='target', id=DataPackIdentifier('target', 'planner'))
@EngineDataPack(keyword='ego', id=DataPackIdentifier('smart_car::road_user', 'gazebo'))
@TransceiverFunction("gazebo")
def car_control(actors, target, ego):
    out = []
    wheel = 0.0
    if not target.isEmpty() and not actors.isEmpty() and actors.data['linear_L'] > 0:
        v_t = max(0.0, float(target.data['speed']))
        v = 0.0 if ego.isEmpty() else float(ego.data.speed)
        wheel = v_t + SPEED_GAIN * (v_t - v)
        wheel = min(max(wheel, v_t - MAX_UNDER), v_t + MAX_OVER)
        if v_t == 0.0 and v < 0.3:
            wheel = 0.0
    for j in ("rear_left_wheel_joint", "rear_right_wheel_joint"):
        dp = GazeboJointDataPack("smart_car_joint_plugin::" + j, "gazebo")
        dp.data.velocity = wheel / WHEEL_RADIUS
        out.append(dp)
    # the planner steers while it changes lanes (off the route the follower follows)
    steer = None if target.isEmpty() else target.data.get('steer')
    for j, k in (("front_left_steering_joint", 'angular_L'), ("front_right_steering_joint", 'angular_R')):
        dp = GazeboJointDataPack("smart_car_joint_plugin::" + j, "gazebo")
        if steer is not None and not actors.isEmpty() and actors.data['linear_L'] > 0:
            dp.data.position = float(steer)
        else:
            dp.data.position = actors.data[k] if not actors.isEmpty() else 0.0
        out.append(dp)
    return out
