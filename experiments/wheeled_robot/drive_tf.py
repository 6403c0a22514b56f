"""Drives the robot through waypoints: differential steering of the four wheels' velocity
targets from the chassis pose."""
import math

from nrp_core import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack, GazeboLinkDataPack

WAYPOINTS = [(2.0, 1.0), (0.5, 2.5), (-1.5, 0.5), (0.0, -1.0)]
RADIUS = 0.1      # wheel radius (m)
TRACK = 0.4       # distance between left and right wheels (m)
state = {"target": 0}


@EngineDataPack(keyword='chassis', id=DataPackIdentifier('robot_link_plugin::chassis', 'gazebo'))
@TransceiverFunction("gazebo")
def drive(chassis):
    if chassis.isEmpty():
        return []
    x, y = float(chassis.data.pos[0]), float(chassis.data.pos[1])
    qx, qy, qz, qw = (float(v) for v in chassis.data.rot)
    yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
    tx, ty = WAYPOINTS[state["target"] % len(WAYPOINTS)]
    if math.hypot(tx - x, ty - y) < 0.3:
        state["target"] += 1
        tx, ty = WAYPOINTS[state["target"] % len(WAYPOINTS)]
    heading = math.atan2(ty - y, tx - x)
    err = math.atan2(math.sin(heading - yaw), math.cos(heading - yaw))
    v = 0.6 * max(0.0, math.cos(err))      # m/s, slow down while turning
    w = 2.5 * err                           # rad/s
    left = (v - w * TRACK / 2) / RADIUS
    right = (v + w * TRACK / 2) / RADIUS
    out = []
    for joint, omega in (("j_fl", left), ("j_rl", left), ("j_fr", right), ("j_rr", right)):
        dp = GazeboJointDataPack("robot_joint_plugin::" + joint, "gazebo")
        dp.data.velocity = omega
        out.append(dp)
    return out
