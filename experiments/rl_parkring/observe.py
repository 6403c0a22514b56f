"""The status function: the car's observation for the client, every step.

From the car's pose it tracks the Parkring waypoints (the autonomous-driving experiment's
Trajectory) and returns, as one JsonRawData: the time, the pose, the speed, the heading error
towards the waypoint a few points ahead, the distance from the path, the waypoints reached,
a few route points ahead in the car's frame (`ahead`, for convoy_gym's DrivingEnv) and
whether the episode is over (lap done, or more than OFF_TRACK m from the path). It returns
done=True every step, so that each run_loop(1) brings its observation back.
The computation is parkring_observation.py's (observe_camera.py adds the camera frame)."""
import os
import sys

from nrp_core import *

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from parkring_observation import OFF_TRACK, observation  # noqa: E402,F401


@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@SimulationIteration(keyword='iteration')
@SimulationTime(keyword='time_ns')
@StatusFunction()
def observe(car, iteration, time_ns):
    return observation(car, iteration, time_ns)
