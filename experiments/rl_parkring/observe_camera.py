"""observe.py's status function with the ego camera's latest frame: returns done=True and
[the JSON observation, the camera datapack (GazeboCameraDataPack)] every step, for convoy_gym's
DrivingEnv(camera=(H, W)), which runs this file instead of observe.py (the config's status
function file name with "_camera") in a copy of the world whose camera renders H x W pixels
once per step (convoy_gym/world_variant.py). Reading the camera here is what makes the world
engine render it: observe.py does not, so an environment without a camera renders nothing."""
import os
import sys

from nrp_core import *
from nrp_core.data.nrp_protobuf import GazeboCameraDataPack

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from parkring_observation import observation  # noqa: E402


@EngineDataPack(keyword='camera', id=DataPackIdentifier('smart_camera::camera', 'gazebo'))
@EngineDataPack(keyword='car', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo'))
@SimulationIteration(keyword='iteration')
@SimulationTime(keyword='time_ns')
@StatusFunction()
def observe_camera(camera, car, iteration, time_ns):
    done, out = observation(car, iteration, time_ns)
    if out and not camera.isEmpty():
        frame = GazeboCameraDataPack("camera", "gazebo")
        frame.data = camera.data
        out.append(frame)
    return done, out
