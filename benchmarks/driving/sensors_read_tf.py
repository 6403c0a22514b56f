"""driving_bench.py --sensors: reads the roof LiDAR's scan and the front radar's returns every
step, so that the world engine produces them (a sensor nobody reads is not scanned), and
keeps a count of what came (no output: the benchmark measures the camera's frames/s with the
sensors' work beside it)."""
from nrp_core import *

seen = {"points": 0, "detections": 0}


@EngineDataPack(keyword="lidar", id=DataPackIdentifier("smart_car::base_link::lidar", "gazebo"))
@EngineDataPack(keyword="radar", id=DataPackIdentifier("smart_car::base_link::radar", "gazebo"))
@TransceiverFunction("gazebo")
def sensors_read_tf(lidar, radar):
    if not lidar.isEmpty():
        seen["points"] += 1
    if not radar.isEmpty():
        seen["detections"] += len(radar.data.detections)
    return []
