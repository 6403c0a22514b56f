from nrp_core import *
from nrp_core.data.nrp_json import *
from nrp_core.data.nrp_protobuf import GazeboLinkDataPack


@EngineDataPack(keyword='state_gazebo', id=DataPackIdentifier('smart_car_link_plugin::base_link', 'gazebo')) 
@TransceiverFunction("car_ctl_engine")  
def car_control(state_gazebo):
    car_state = JsonDataPack("state_location", "car_ctl_engine")  
  
    car_state.data['location_x'] = state_gazebo.data.position[0]  
    car_state.data['location_y'] = state_gazebo.data.position[1]  
    car_state.data['qtn_x'] = state_gazebo.data.rotation[0]  
    car_state.data['qtn_y'] = state_gazebo.data.rotation[1]  
    car_state.data['qtn_z'] = state_gazebo.data.rotation[2]  
    car_state.data['qtn_w'] = state_gazebo.data.rotation[3]
    return [car_state]
