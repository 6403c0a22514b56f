"""The pooled city's information flow (simulation_config_pooled.json), one transceiver function
at the pool's rate (20 Hz):

- the world engine gets every pooled vehicle as an actor: the pool's convoy.data.RoadUsers
  datapack is copied whole (binary protobuf, no JSON) to the world engine as `pool_users`;
- the ego's planner gets its ground-truth input: the pooled vehicles within PLANNER_RADIUS m
  of the ego, in the ego's frame;
- the recorder gets the ego and the pooled vehicles within RECORD_RADIUS m of it (its per-user
  checks are Python; the whole pool is in the world engine, not in tracks.jsonl).

The pool does not see the ego (road_user_pool takes no external road users yet)."""
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from nrp_core.data.nrp_protobuf import RoadUsersDataPack

from convoy_traffic.ego_planner import ego_state, objects_from_road_users

PLANNER_RADIUS = 100.0  # m
RECORD_RADIUS = 60.0    # m


@EngineDataPack(keyword="pool", id=DataPackIdentifier("road_users", "pool"))
@EngineDataPack(keyword="ego", id=DataPackIdentifier("smart_car::road_user", "gazebo"))
@TransceiverFunction("pool")
def pool_traffic(pool, ego):
    if pool.isEmpty():
        return []
    world = RoadUsersDataPack("pool_users", "gazebo")
    world.data.CopyFrom(pool.data)
    out = [world]
    if ego.isEmpty():
        return out
    e = ego_state(ego.data)
    ex, ey = e["x"], e["y"]
    r2 = PLANNER_RADIUS * PLANNER_RADIUS
    near = [u for u in pool.data.users if (u.x - ex) ** 2 + (u.y - ey) ** 2 < r2]
    out.append(JsonDataPack("planner_input", "planner", {
        "source": "ground_truth", "ego": e, "objects": objects_from_road_users(e, near)}))
    rr2 = RECORD_RADIUS * RECORD_RADIUS
    rec = {"signals": {}, "users": []}
    for u in [v for v in near if (v.x - ex) ** 2 + (v.y - ey) ** 2 < rr2] + [ego.data]:
        rec["users"].append([u.id, u.category, round(u.x, 3), round(u.y, 3), round(u.yaw, 4),
                             round(u.speed, 3), round(u.length, 2), round(u.length_offset, 2)])
    rec["pool_size"] = len(pool.data.users)
    out.append(JsonDataPack("traffic", "recorder", rec))
    return out
