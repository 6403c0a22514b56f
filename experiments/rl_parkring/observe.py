"""The status function: the car's observation for the client, every step.

From the car's pose it tracks the Parkring waypoints (the autonomous-driving experiment's
Trajectory) and returns, as one JsonRawData: the time, the pose, the speed, the heading error
towards the waypoint a few points ahead, the distance from the path, the waypoints reached,
and whether the episode is over (lap done, or more than OFF_TRACK m from the path). It
returns done=True every step, so that each run_loop(1) brings its observation back."""
import math
import os
import sys

from nrp_core import *
from nrp_core.data.nrp_json import JsonRawData

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "autonomous_driving"))
import relateAngle_computation  # noqa: E402
from euler_from_quaternion import euler_from_quaternion  # noqa: E402

OFF_TRACK = 3.0  # m
track = None


def distance_to_path(points, index, x, y):
    near = [points[i % len(points)] for i in range(max(index - 2, 0), index + 3)]
    return min(math.hypot(px - x, py - y) for px, py in near)


@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@SimulationIteration(keyword='iteration')
@SimulationTime(keyword='time_ns')
@StatusFunction()
def observe(car, iteration, time_ns):
    global track
    if iteration == 0 or track is None:  # a new episode (start, or after reset())
        track = relateAngle_computation.Trajectory()
    if car.isEmpty():
        return True, []
    x, y = float(car.data.pos[0]), float(car.data.pos[1])
    _, _, yaw = euler_from_quaternion(*[float(v) for v in car.data.rot])
    heading_error, _ = track.update(x, y, yaw)
    off_path = distance_to_path(track.points, track.index, x, y)
    speed = math.hypot(float(car.data.lin_vel[0]), float(car.data.lin_vel[1]))
    return True, [JsonRawData({
        "t": time_ns * 1e-9, "x": x, "y": y, "yaw": yaw, "speed": speed,
        "heading_error": heading_error, "off_path": off_path,
        "waypoint": track.index, "waypoints": len(track.points),
        "episode_over": track.finished or off_path > OFF_TRACK})]
