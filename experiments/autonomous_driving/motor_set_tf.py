from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboJointDataPack


@EngineDataPack(keyword='actors', id=DataPackIdentifier('actors', 'car_ctl_engine'))  
@TransceiverFunction("gazebo")  
def car_control(actors):  
    rear_left_wheel_joint = GazeboJointDataPack("smart_car_joint_plugin::rear_left_wheel_joint", "gazebo")  
    rear_right_wheel_joint = GazeboJointDataPack("smart_car_joint_plugin::rear_right_wheel_joint", "gazebo")  
    front_left_steering_joint = GazeboJointDataPack("smart_car_joint_plugin::front_left_steering_joint", "gazebo")  
    front_right_steering_joint = GazeboJointDataPack("smart_car_joint_plugin::front_right_steering_joint", "gazebo") 

    rear_left_wheel_joint.data.velocity = actors.data['linear_L']
    rear_right_wheel_joint.data.velocity = actors.data['linear_R']
    front_left_steering_joint.data.position = actors.data['angular_L']
    front_right_steering_joint.data.position = actors.data['angular_R']
    return [rear_left_wheel_joint, rear_right_wheel_joint, front_left_steering_joint, front_right_steering_joint]
