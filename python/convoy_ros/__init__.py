"""Convoy's ROS 1 side in plain Python (no rospy needed to import it): what the ros_bridge
engine's messages mean for the smart car, and the route follower of experiments/ros_drive.

    from convoy_ros.control import ControlModel, twist_to_drive, joint_targets
    model = ControlModel()
    speed, steer = model.update(control_json)          # the bridge's "/convoy/control" datapack
    speed, steer = twist_to_drive(twist_json)          # the bridge's "/cmd_vel" datapack
    joint_targets(speed, steer)                        # {joint: ("position"|"velocity", value)}

    from convoy_ros.pursuit import Route, PurePursuit  # driver_node.py's controller

Pure functions and small state objects; unit tests in tests/unit/test_ros_control.py and
tests/unit/test_ros_pursuit.py. The bridge: engines/ros_bridge; the example: experiments/ros_drive.
"""
