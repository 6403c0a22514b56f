"""Each agent's view of its neighbours, built in a transceiver function.

Road users see each other only through their inputs (docs/road_users.md). A TF gathers every
participant's state (RoadUser datapacks of agents, a RoadUsers datapack of a crowd engine such
as sumo, or a python_json road user's JSON) and gives each agent the road users within a radius
of it as a convoy.data.RoadUsers datapack (name "neighbours" by default):

    from convoy_traffic.neighbours import neighbour_datapacks

    @EngineDataPack(keyword="a", id=DataPackIdentifier("state", "car_a"))
    @EngineDataPack(keyword="b", id=DataPackIdentifier("state", "car_b"))
    @TransceiverFunction("car_a")
    def neighbours(a, b):
        return neighbour_datapacks([a, b], agents=["car_a", "car_b"], radius=100.0)

Users are listed sorted by id, so the view does not depend on the order of the inputs.
"""

import math

import _convoy_datapack  # the Convoy program running this Python

from google.protobuf import json_format

from nrp_core.data.nrp_protobuf import RoadUsersDataPack

_RoadUser = None


def _road_user_class():
    global _RoadUser
    if _RoadUser is None:
        from nrp_core.data.nrp_protobuf import RoadUserDataPack
        _RoadUser = type(RoadUserDataPack("_", "_").data)
    return _RoadUser


def road_users(datapacks):
    """The RoadUser messages in a list of datapacks (RoadUser, RoadUsers or JSON; empty ones
    are skipped)."""
    out = []
    for dp in datapacks:
        if dp is None or dp.isEmpty():
            continue
        data = dp.data
        if hasattr(data, "users") and not isinstance(data, dict):
            out.extend(data.users)
        elif isinstance(data, dict) or isinstance(data, list):
            items = data if isinstance(data, list) else data.get("users", [data])
            for item in items:
                u = _road_user_class()()
                json_format.ParseDict(item, u, ignore_unknown_fields=True)
                out.append(u)
        else:
            out.append(data)
    return out


def neighbour_view(me, users, radius=100.0):
    """Road users (other than `me`, present) whose reference point is within `radius` m of
    `me`'s, sorted by id."""
    near = [u for u in users
            if u.id != me.id and not u.absent
            and math.hypot(u.x - me.x, u.y - me.y) <= radius]
    near.sort(key=lambda u: u.id)
    return near


_ONE_BYTE = [bytes((n,)) for n in range(0x80)]


def _varint(n):
    if n < 0x80:
        return _ONE_BYTE[n]
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        if n:
            out.append(b | 0x80)
        else:
            out.append(b)
            return bytes(out)


def neighbour_datapacks(datapacks, agents, radius=100.0, name="neighbours", state_id=None):
    """One RoadUsers datapack `name` for each engine in `agents`, holding its neighbours among
    all road users in `datapacks` (the same as neighbour_view). An agent is found by its id
    (`state_id(engine)` if given, else the engine's name); an agent with no state yet gets an
    empty view.

    Built for many agents: each user is serialised once, and the views are put together in
    C++ (a grid of cells the size of `radius`, each agent looking at its 3x3 cells) as the
    concatenated bytes (field 1 of RoadUsers, repeated, then time_ns), sent without being
    parsed (RoadUsersDataPack.from_bytes)."""
    every = road_users(datapacks)
    users = [u for u in every if not u.absent]
    users.sort(key=lambda u: u.id)  # views sorted by id
    by_id = {u.id: i for i, u in enumerate(users)}
    # An absent agent (its route ended) still gets the view around where it says it is: one
    # that respawns checks its start with it.
    gone = {u.id: u for u in every if u.absent}
    xs = [u.x for u in users]
    ys = [u.y for u in users]
    frames = []
    for u in users:
        payload = u.SerializeToString()
        frames.append(b"\x0a" + _varint(len(payload)) + payload)
    # Each agent's position: its own, or where it says it is when absent.
    centres, wanted = [], []
    for engine in agents:
        key = state_id(engine) if state_id else engine
        me = by_id.get(key)
        u = users[me] if me is not None else gone.get(key)
        wanted.append(u is not None)
        if u is not None:
            centres.append((u.x, u.y, -1 if me is None else me, u.time_ns))
    views = iter(_convoy_datapack.neighbour_views(frames, xs, ys, centres, float(radius)))
    return [RoadUsersDataPack.from_bytes(name, engine, next(views)) if want
            else RoadUsersDataPack(name, engine) for engine, want in zip(agents, wanted)]
