"""Reads the sensors the config's Sensors list mounts on the smart car (issue 27): the LiDAR's
bird's-eye view (lidar_lidar.png, coloured by class) and last scan (lidar_lidar.npy) go to the
run folder every simulated second, each IMU and GNSS reading to sensors.csv."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from nrp_core import *  # noqa: E402,F401
from convoy_sensors.birds_eye import RunFolderView  # noqa: E402

VIEW = RunFolderView("lidar", period=1.0)
CSV = os.path.join(os.environ.get("CONVOY_RUN_DIR", "."), "sensors.csv")
with open(CSV, "w") as f:
    f.write("sensor,time_s,a,b,c\n")


def _empty(dp):
    return dp is None or dp.isEmpty()


@EngineDataPack(keyword="scan", id=DataPackIdentifier("smart_car::base_link::lidar", "gazebo"))
@EngineDataPack(keyword="imu", id=DataPackIdentifier("smart_car::base_link::imu", "gazebo"))
@EngineDataPack(keyword="gnss", id=DataPackIdentifier("smart_car::base_link::gnss", "gazebo"))
@TransceiverFunction("car_ctl_engine")
def sensors_tf(scan, imu, gnss):
    if not _empty(scan):
        VIEW.update(scan)
    with open(CSV, "a") as f:
        if not _empty(imu):
            a = imu.data.linear_acceleration
            f.write("imu,%.3f,%.4f,%.4f,%.4f\n" % (imu.data.time_ns * 1e-9, a[0], a[1], a[2]))
        if not _empty(gnss):
            g = gnss.data
            f.write("gnss,%.3f,%.9f,%.9f,%.3f\n" % (g.time_ns * 1e-9, g.latitude_deg,
                                                    g.longitude_deg, g.altitude))
    return []
