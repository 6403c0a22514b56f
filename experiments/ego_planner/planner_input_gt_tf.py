"""Ground-truth input of the ego planner: the ego's RoadUser from the world engine and the other
road users' states (python_json JSON RoadUsers), in the ego's frame, labelled "ground_truth".
Also poses the road users in the world (actors) and hands the road user the ego's state and the world's collisions."""
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.ego_planner import ego_state, objects_from_road_users
from convoy_traffic.neighbours import road_users


@EngineDataPack(keyword='ego', id=DataPackIdentifier('smart_car::road_user', 'gazebo'))
@EngineDataPack(keyword='road_user', id=DataPackIdentifier('state', 'traffic'))
@EngineDataPack(keyword='collisions', id=DataPackIdentifier('collisions', 'gazebo'))
@TransceiverFunction("planner")
def planner_input(ego, road_user, collisions):
    out = []
    if not collisions.isEmpty():  # the road user records them (the tests assert on them)
        out.append(JsonDataPack("collisions", "traffic", {"list": list(collisions.data)}))
    others = road_users([road_user])
    if not road_user.isEmpty():
        out.append(JsonDataPack("road_users", "gazebo", {"users": [dict(road_user.data)]}))
    if ego.isEmpty():
        return out
    e = ego_state(ego.data)
    out.append(JsonDataPack("ego", "traffic", e))
    out.append(JsonDataPack("planner_input", "planner", {
        "source": "ground_truth", "ego": e, "objects": objects_from_road_users(e, others)}))
    return out
