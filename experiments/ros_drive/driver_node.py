#!/usr/bin/python3
"""A ROS 1 driver for Convoy's ros_bridge (rospy, Debian's python3): follows the route by pure
pursuit at a target speed (convoy_ros.pursuit) and answers each simulation step with a
convoy_msgs/Control stamped with that step's odometry stamp.

Subscribes   /convoy/route (nav_msgs/Path, latched: waited for before the first answer),
             /convoy/camera/image_raw (sensor_msgs/Image) and /convoy/odom (nav_msgs/Odometry),
             paired by stamp (message_filters.TimeSynchronizer): one answer per pair
Publishes    /convoy/control (convoy_msgs/Control)
Parameters   ~target_speed (m/s, 7.0); ~step (s, 0.02: the simulation's step, for the first
             answer; later ones take the time between stamps); ~use_camera (true; false:
             answer each odometry alone); ~log (a CSV file of the answers, "" none);
             ~odom, ~image, ~route, ~control (the topics)

Each step is answered once, from that step's messages only, in stamp order: two runs of the
same simulation get the same answers. Run (the bridge's master in ROS_MASTER_URI):
    /usr/bin/python3 experiments/ros_drive/driver_node.py _target_speed:=6.0
"""
import os
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
BIN_DIR = os.environ.get("CONVOY_BIN_DIR") or os.path.join(REPO, "build", "bin")
sys.path[:0] = [os.path.join(REPO, "python"), os.path.join(os.path.dirname(BIN_DIR), "python")]

import message_filters  # noqa: E402
import rospy  # noqa: E402
from convoy_msgs.msg import Control  # noqa: E402
from nav_msgs.msg import Odometry, Path  # noqa: E402
from sensor_msgs.msg import Image  # noqa: E402

from convoy_ros.pursuit import PurePursuit, Route, yaw_of_quaternion  # noqa: E402

CONNECT_WAIT_S = 10.0  # the longest an answer waits for the bridge to subscribe


class Driver:
    def __init__(self):
        self.target_speed = float(rospy.get_param("~target_speed", 7.0))
        self.step = float(rospy.get_param("~step", 0.02))
        self.lock = threading.Lock()
        self.pursuit = None
        self.pending = []  # steps that came before the route
        self.last_stamp = None
        self.images = 0
        log = rospy.get_param("~log", "")
        self.log = open(log, "w") if log else None
        if self.log:
            self.log.write("stamp,x,y,yaw,speed,throttle,brake,steer\n")
        self.pub = rospy.Publisher(rospy.get_param("~control", "/convoy/control"), Control,
                                   queue_size=10, tcp_nodelay=True)
        rospy.Subscriber(rospy.get_param("~route", "/convoy/route"), Path, self.on_route,
                         queue_size=1, tcp_nodelay=True)
        odom_topic = rospy.get_param("~odom", "/convoy/odom")
        if rospy.get_param("~use_camera", True):
            image_topic = rospy.get_param("~image", "/convoy/camera/image_raw")
            image = message_filters.Subscriber(image_topic, Image, queue_size=5,
                                               tcp_nodelay=True, buff_size=1 << 24)
            odom = message_filters.Subscriber(odom_topic, Odometry, queue_size=5,
                                              tcp_nodelay=True)
            message_filters.TimeSynchronizer([image, odom], 10).registerCallback(self.on_step)
        else:
            rospy.Subscriber(odom_topic, Odometry, lambda m: self.on_step(None, m),
                             queue_size=5, tcp_nodelay=True)

    def on_route(self, msg):
        points = [(p.pose.position.x, p.pose.position.y) for p in msg.poses]
        with self.lock:
            if self.pursuit is not None:
                return  # the same latched route again
            self.pursuit = PurePursuit(Route(points), self.target_speed)
            rospy.loginfo("route of %d points (%s)", len(points),
                          "a loop" if self.pursuit.route.closed else "open")
            pending, self.pending = sorted(self.pending, key=lambda p: p[1].header.stamp), []
            for image, odom in pending:
                self.answer(image, odom)

    def on_step(self, image, odom):
        with self.lock:
            if self.pursuit is None:
                self.pending.append((image, odom))
            else:
                self.answer(image, odom)

    def answer(self, image, odom):
        stamp = odom.header.stamp
        if self.last_stamp is not None and stamp <= self.last_stamp:
            return  # answered already
        dt = self.step if self.last_stamp is None else (stamp - self.last_stamp).to_sec()
        self.last_stamp = stamp
        if image is not None:
            if self.images == 0:
                rospy.loginfo("camera %dx%d %s", image.width, image.height, image.encoding)
            self.images += 1
        p, q = odom.pose.pose.position, odom.pose.pose.orientation
        yaw = yaw_of_quaternion(q.x, q.y, q.z, q.w)
        speed = odom.twist.twist.linear.x  # the child frame's: forward
        throttle, brake, steer = self.pursuit.step(p.x, p.y, yaw, speed, dt)
        msg = Control(throttle=throttle, brake=brake, steer=steer, reverse=False)
        msg.header.stamp = stamp
        msg.header.frame_id = odom.child_frame_id
        self.wait_for_bridge()
        self.pub.publish(msg)
        if self.log:
            self.log.write("%s,%r,%r,%r,%r,%r,%r,%r\n" % (
                stamp.to_sec(), p.x, p.y, yaw, speed, throttle, brake, steer))

    def wait_for_bridge(self):
        """A message published before the bridge's subscription is connected would be lost,
        and the bridge would wait for it until its SyncTimeout."""
        deadline = time.monotonic() + CONNECT_WAIT_S
        while self.pub.get_num_connections() == 0 and time.monotonic() < deadline \
                and not rospy.is_shutdown():
            time.sleep(0.002)

    def close(self):
        with self.lock:
            if self.log:
                self.log.close()
                self.log = None


def main():
    rospy.init_node("convoy_driver")
    driver = Driver()
    rospy.on_shutdown(driver.close)
    rospy.loginfo("convoy_driver: target speed %.1f m/s", driver.target_speed)
    rospy.spin()


if __name__ == "__main__":
    main()
