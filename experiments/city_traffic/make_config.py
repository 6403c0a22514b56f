#!/usr/bin/python3
"""Writes experiments/city_traffic's generated files, deterministically:

  simulation_config.json   the world (city road, the ego with its camera), the ego's follower,
                           planner and detector, 20 vehicle agents, 10 pedestrian agents (6 of
                           them crossing at crosswalks or mid-block), the traffic lights, SUMO's
                           background traffic and the recorder
  simulation_config_density.json   the 10-minute density run: the same road users respawning,
                           SUMO's flows doubled, no ego
  simulation_config_pooled.json   the ego (camera, detector, planner) among POOLED vehicles
                           driven by one road_user_pool engine (issue 26), drawn by the world
                           engine as actors (pool_tf.py), under the traffic_lights engine's
                           signals (the pool's TrafficLightsDataPack; the ego's planner gets a
                           red light's stop line as in simulation_config.json);
                           -o EngineConfigs/5/Density=D sets the vehicles a km of lane (or
                           Density=0 and Count=N)
  simulation_config_pooled_large.json   the same with 1,000 pooled road users on the large grid
                           city (large_city.xodr, city_world_large.sdf; make_large_city.py)
  sumo/city.rou.xml        SUMO's demand: flows between the map's entry and exit edges
  sumo/city_dense.rou.xml  the same, doubled
  ego_route.csv            the ego's waypoints (convoy-odr route, straight through both
                           junctions); written only when --odr names the convoy-odr binary

Usage: /usr/bin/python3 make_config.py [--odr build/bin/convoy-odr]
The same script always writes the same bytes. The config is long because every road user is
its own engine, as in NRP-Core; edit this script rather than the JSON.
"""
import argparse
import json
import os
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
MAP = "city.xodr"
AGENT_DT = 0.05      # vehicle and pedestrian agents, lights, SUMO: 20 Hz
WORLD_DT = 0.02      # world engine (physics at 1 ms; the camera renders at 30 Hz of simulated time)
DETECTOR_DT = 0.1    # detection at 10 Hz simulated: every third camera frame

# Vehicle agents: (from lane, start s, to lane, model). Right-hand traffic: lanes -1/-2 of
# roads 1 and 5, 7 run towards the junctions along s, lanes 1/2 of roads 3, 4, 6 against it.
# Starts are at least 25 m apart on a lane, and clear of the ego (road 1 lane -1, s 100).
# Every route keeps its lane (turns from the proper lane), and the agents do not change lanes
# here (LaneChanges false): a lane change that a route needs is not yet gap-checked by
# vehicle_agent (docs/roadmap.md), and dense junction approaches are where it would matter.
VEHICLES = [
    ("1:-1", 140.0, "3:-1", "sedan"), ("1:-1", 175.0, "6:-1", "hatchback"),
    ("1:-1", 60.0, "3:-1", "suv"), ("1:-2", 90.0, "3:-2", "van"),
    ("1:-2", 130.0, "5:1", "sedan"), ("1:-2", 170.0, "3:-2", "hatchback"),
    ("3:1", 200.0, "1:1", "sedan"), ("3:1", 160.0, "5:1", "suv"),
    ("3:2", 180.0, "1:2", "van"), ("3:2", 120.0, "1:2", "sedan"),
    ("3:1", 100.0, "1:1", "hatchback"), ("4:1", 40.0, "5:1", "sedan"),
    ("4:1", 80.0, "3:-1", "suv"), ("5:-1", 90.0, "4:-1", "hatchback"),
    ("5:-1", 50.0, "1:1", "sedan"), ("6:1", 90.0, "7:1", "van"),
    ("6:1", 50.0, "1:2", "sedan"), ("7:-1", 90.0, "6:-1", "suv"),
    ("7:-1", 50.0, "3:-2", "hatchback"), ("2:1", 120.0, "5:1", "sedan"),
]

# Pedestrian agents: routes on sidewalks and crosswalks (crosswalk ids from city.xodr).
PEDESTRIANS = [
    {"crosswalk": "1"}, {"crosswalk": "2", "reverse": True}, {"crosswalk": "5"},
    {"crosswalk": "6", "reverse": True}, {"crosswalk": "3"},
    {"from": "2:-3", "from_s": 40.0, "to": "2:-3", "to_s": 150.0},
    {"from": "2:3", "from_s": 150.0, "to": "2:3", "to_s": 30.0},
    {"from": "1:-3", "from_s": 150.0, "to": "1:-3", "to_s": 225.0},
    {"from": "3:3", "from_s": 60.0, "to": "3:3", "to_s": 10.0},
    # crosses mid-block at s = 190 (x = -60), in a gap in front of the ego
    {"from": "1:-3", "from_s": 186.0, "to": "1:3", "to_s": 186.0},
]
MIDBLOCK = {9: (1.0, 42.84)}  # (probability, MidBlockDistance)

# SUMO's background traffic: (from edge, to edge, vehicles per hour); edges are netconvert's
# names for the roads ("-R": along s, "R": against it).
FLOWS = [
    ("-1", "-3", 120), ("-1", "-4", 60), ("3", "1", 120), ("3", "7", 60),
    ("4", "5", 60), ("-5", "-6", 60), ("6", "1", 60), ("-7", "-3", 60),
]


def vehicle(i, frm, s, to, model, respawn=False):
    e = {"EngineType": "vehicle_agent", "EngineName": "car_%d" % i, "EngineTimestep": AGENT_DT,
         "Map": MAP, "Route": {"from": frm, "to": to}, "StartS": s, "InitialSpeed": 6.0,
         "Model": model, "LaneChanges": False, "Seed": i}
    if respawn:
        e["Respawn"] = True
    return e


def pedestrian(i, route, respawn=False):
    e = {"EngineType": "pedestrian_agent", "EngineName": "ped_%d" % i, "EngineTimestep": AGENT_DT,
         "Map": MAP, "Route": route, "Seed": 100 + i, "Speed": 1.35, "CriticalGap": 4.0,
         "MidBlockProbability": MIDBLOCK.get(i, (0.0, 25.0))[0],
         "MidBlockDistance": MIDBLOCK.get(i, (0.0, 25.0))[1]}
    if respawn:
        e["Respawn"] = True
    return e


def weather(dt):
    """The weather engine, clear by default (-o EngineConfigs/1/Precipitation=0.8 and so on)."""
    return {"EngineType": "weather", "EngineName": "weather", "EngineTimestep": dt, "Seed": 0,
            "Surface": "dry", "Precipitation": 0.0, "Visibility": 20000.0, "WindSpeed": 0.0}


WEATHER_TF = {"Name": "weather_tf", "FileName": "../common/weather_tf.py"}


def density_config():
    """The density run (benchmarks/traffic_bench.py --section density): the same road users,
    each starting its route again when it ends, SUMO's flows doubled, for 10 simulated minutes;
    the world engine (no ego) records every contact between them."""
    engines = [
        {"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "city_world_no_ego.sdf",
         "EngineTimestep": AGENT_DT, "ActorTimeout": 1.0},
        weather(AGENT_DT),
        {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": AGENT_DT,
         "Map": MAP, "Leader": "self", "Green": 15.0, "Yellow": 3.0, "AllRed": 2.0},
        {"EngineType": "sumo", "EngineName": "sumo", "EngineTimestep": AGENT_DT,
         "OpenDriveFile": MAP, "RouteFiles": ["sumo/city_dense.rou.xml"], "Seed": 42,
         "TrafficLightsLeader": "external"},
        {"EngineType": "python_json", "EngineName": "recorder", "PythonFileName": "recorder.py",
         "EngineTimestep": AGENT_DT},
    ]
    engines += [vehicle(i, *v, respawn=True) for i, v in enumerate(VEHICLES)]
    engines += [pedestrian(i, r, respawn=True) for i, r in enumerate(PEDESTRIANS)]
    return {
        "SimulationName": "city_traffic_density",
        "SimulationDescription": (
            "10 simulated minutes of dense city traffic: the 20 vehicle agents and 10 pedestrian "
            "agents of city_traffic, each starting its route again when it ends, and SUMO's "
            "flows doubled, without the ego. summary.json's collisions must stay empty. "
            "Generated by make_config.py."),
        "SimulationTimeout": 600,
        "EngineConfigs": engines,
        "DataPackProcessingFunctions": [
            WEATHER_TF,
            {"Name": "traffic_tf", "FileName": "traffic_tf.py"},
            {"Name": "recorder_tf", "FileName": "recorder_tf.py"},
        ],
    }


def config():
    engines = [
        {"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "city_world.sdf",
         "GazeboRNGSeed": 7, "EngineTimestep": WORLD_DT, "ActorTimeout": 1.0},
        weather(AGENT_DT),
        {"EngineType": "python_json", "EngineName": "car_ctl_engine", "PythonFileName": "ego_driver.py",
         "EngineTimestep": WORLD_DT},
        {"EngineType": "python_json", "EngineName": "planner",
         "PythonFileName": "../ego_planner/ego_planner_engine.py", "EngineTimestep": WORLD_DT,
         "EngineEnvParams": ["CONVOY_EGO_PLANNER_CONFIG=../city_traffic/ego_planner.json"]},
        {"EngineType": "detector", "EngineName": "yolo_detector", "Backend": "convoy",
         "EngineTimestep": DETECTOR_DT},
        {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": AGENT_DT,
         "Map": MAP, "Leader": "self", "Green": 15.0, "Yellow": 3.0, "AllRed": 2.0},
        {"EngineType": "sumo", "EngineName": "sumo", "EngineTimestep": AGENT_DT,
         "OpenDriveFile": MAP, "RouteFiles": ["sumo/city.rou.xml"], "Seed": 42,
         "TrafficLightsLeader": "external"},
        {"EngineType": "python_json", "EngineName": "recorder", "PythonFileName": "recorder.py",
         "EngineTimestep": WORLD_DT},
    ]
    engines += [vehicle(i, *v) for i, v in enumerate(VEHICLES)]
    engines += [pedestrian(i, r) for i, r in enumerate(PEDESTRIANS)]
    return {
        "SimulationName": "city_traffic",
        "SimulationDescription": (
            "The report's smart car with camera, detector and longitudinal planner drives through "
            "both junctions of the generated city map, among 20 vehicle agents, 10 pedestrian "
            "agents and SUMO's background traffic, under the traffic_lights engine's signals "
            "(SUMO kept in step). Outputs: camera.mp4, birds_eye.png, tracks.jsonl and "
            "summary.json in the run folder. Generated by make_config.py."),
        "SimulationTimeout": 110,
        "EngineConfigs": engines,
        "DataPackProcessingFunctions": [
            WEATHER_TF,
            {"Name": "state_tf", "FileName": "../autonomous_driving/state_tf.py"},
            {"Name": "motor_tf", "FileName": "../ego_planner/motor_tf.py"},
            {"Name": "camera_tf", "FileName": "../autonomous_driving/camera_tf.py"},
            {"Name": "truth_tf", "FileName": "../autonomous_driving/truth_tf.py"},
            {"Name": "traffic_tf", "FileName": "traffic_tf.py"},
            {"Name": "recorder_tf", "FileName": "recorder_tf.py"},
            {"Name": "score_tf", "FileName": "score_tf.py"},
        ],
    }


POOLED_DENSITY = 50.0  # vehicles per km of driving lane (city.xodr: 3.7 km, ~185 vehicles)
EGO_START = (-150.0, -1.75)  # city_world.sdf's smart_car: no pooled vehicle spawns near it


# The large pooled city (make_large_city.py): 1,000 pooled road users on a 4x4 grid city, 800
# vehicles and 200 walkers on its sidewalks (13 per km of sidewalk), the ego on
# ego_route_large.csv from its 20th point (city_world_large.sdf's smart_car).
LARGE = {"world": "city_world_large.sdf", "map": "large_city.xodr", "count": 800, "pedestrians": 200,
         "ego_start": (-110.0, 248.25), "route": "ego_route_large.csv", "skip": 20,
         "road_model": "large_city_road", "timeout": 150}


def pooled_config(density=POOLED_DENSITY, large=None):
    """The ego among `density` vehicles a km of one road_user_pool engine (its own IDM, MOBIL and
    junction yielding), no SUMO, no agent engines, under the traffic_lights engine's signals:
    pool_tf.py hands the pool's RoadUsers datapack to the world engine, which draws them, the
    nearby ones to the planner and the ego to the pool (its vehicles follow it), and the signals
    to the pool (TrafficLightsDataPack), the recorder and, as a red light's stop line, the
    planner. `large` (LARGE): `count` vehicles on the large city. The lights engine comes after
    the pool (the pool stays EngineConfigs/5)."""
    world, pool_map, ego = "city_world.sdf", MAP, EGO_START
    count, pedestrians, ctl_env, rec_env = 0, 0, [], []
    if large:
        world, pool_map, ego = large["world"], large["map"], large["ego_start"]
        count, density, pedestrians = large["count"], 0.0, large["pedestrians"]
        ctl_env = ["CONVOY_EGO_ROUTE=%s" % large["route"], "CONVOY_EGO_ROUTE_SKIP=%d" % large["skip"]]
        rec_env = ["CONVOY_CITY_MAP=%s" % large["map"], "CONVOY_CITY_ROAD=%s" % large["road_model"]]
    ctl = {"EngineType": "python_json", "EngineName": "car_ctl_engine", "PythonFileName": "ego_driver.py",
           "EngineTimestep": WORLD_DT}
    recorder = {"EngineType": "python_json", "EngineName": "recorder", "PythonFileName": "recorder.py",
                "EngineTimestep": WORLD_DT}
    if ctl_env:
        ctl["EngineEnvParams"] = ctl_env
        recorder["EngineEnvParams"] = rec_env
    engines = [
        {"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": world,
         "GazeboRNGSeed": 7, "EngineTimestep": WORLD_DT, "ActorTimeout": 1.0},
        weather(AGENT_DT),
        ctl,
        {"EngineType": "python_json", "EngineName": "planner",
         "PythonFileName": "../ego_planner/ego_planner_engine.py", "EngineTimestep": WORLD_DT,
         "EngineEnvParams": ["CONVOY_EGO_PLANNER_CONFIG=../city_traffic/ego_planner.json"]},
        {"EngineType": "detector", "EngineName": "yolo_detector", "Backend": "convoy",
         "EngineTimestep": DETECTOR_DT},
        {"EngineType": "road_user_pool", "EngineName": "pool", "EngineTimestep": AGENT_DT,
         "Map": pool_map, "Density": density, "Count": count, "Pedestrians": pedestrians,
         "Seed": 1, "Policy": "idm_mobil",
         "DesiredSpeed": 11.0, "TrafficLightsDataPack": "traffic_lights",
         "KeepClear": [{"X": ego[0], "Y": ego[1], "Radius": 40.0}]},
        {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": AGENT_DT,
         "Map": pool_map, "Leader": "self", "Green": 15.0, "Yellow": 3.0, "AllRed": 2.0},
        recorder,
    ]
    if large:
        name = "city_traffic_pooled_large"
        description = (
            "The smart car with camera, detector and planner drives along a row of the large grid "
            "city (large_city.xodr, 4x4 junctions, 30 km of lane) among %d vehicles and %d "
            "pedestrians of ONE road_user_pool engine (EngineConfigs/5/Count, "
            "EngineConfigs/5/Pedestrians), which the world engine draws as actors; the pool sees "
            "the ego, and all obey the traffic_lights engine's signals. Outputs: camera.mp4, birds_eye.png, summary.json. Generated by "
            "make_config.py." % (count, pedestrians))
    else:
        name = "city_traffic_pooled"
        description = (
            "The smart car with camera, detector and planner drives through the city among "
            "vehicles of ONE road_user_pool engine, %g a km of driving lane "
            "(EngineConfigs/5/Density; or Density=0 and Count=N), which the world engine draws "
            "as actors; the pool sees the ego, and all obey the traffic_lights engine's signals. "
            "Outputs: camera.mp4, birds_eye.png (the ego and "
            "the pooled vehicles near it), summary.json. Generated by make_config.py." % density)
    return {
        "SimulationName": name,
        "SimulationDescription": description,
        "SimulationTimeout": large["timeout"] if large else 110,
        "EngineConfigs": engines,
        "DataPackProcessingFunctions": [
            WEATHER_TF,
            {"Name": "state_tf", "FileName": "../autonomous_driving/state_tf.py"},
            {"Name": "motor_tf", "FileName": "../ego_planner/motor_tf.py"},
            {"Name": "camera_tf", "FileName": "../autonomous_driving/camera_tf.py"},
            # No truth_tf: the detector's "convoy" backend ignores ground-truth boxes, and
            # asking for them would make the world draw an instance-id pass with every frame.
            {"Name": "pool_tf", "FileName": "pool_tf.py"},
            {"Name": "recorder_tf", "FileName": "recorder_tf.py"},
        ],
    }


def routes(scale=1):
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             "<!-- generated by make_config.py: SUMO's background traffic on city.xodr -->",
             "<routes>",
             '    <vType id="passenger" vClass="passenger" length="4.5" width="1.8" sigma="0.5"/>',
             '    <vType id="bus" vClass="bus" length="12.0" width="2.5" sigma="0.5"/>']
    for i, (f, t, vph) in enumerate(FLOWS):
        vtype = "bus" if i == 2 else "passenger"
        lines.append('    <flow id="f%d" type="%s" from="%s" to="%s" begin="0" end="3600" '
                     'vehsPerHour="%d" departLane="best" departSpeed="max"/>' % (i, vtype, f, t, vph * scale))
    lines.append("</routes>")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--odr", help="convoy-odr binary: also write ego_route.csv")
    args = ap.parse_args()
    with open(os.path.join(HERE, "simulation_config.json"), "w") as f:
        json.dump(config(), f, indent=2)
        f.write("\n")
    with open(os.path.join(HERE, "simulation_config_density.json"), "w") as f:
        json.dump(density_config(), f, indent=2)
        f.write("\n")
    with open(os.path.join(HERE, "simulation_config_pooled.json"), "w") as f:
        json.dump(pooled_config(), f, indent=2)
        f.write("\n")
    with open(os.path.join(HERE, "simulation_config_pooled_large.json"), "w") as f:
        json.dump(pooled_config(large=LARGE), f, indent=2)
        f.write("\n")
    with open(os.path.join(HERE, "sumo", "city.rou.xml"), "w") as f:
        f.write(routes())
    with open(os.path.join(HERE, "sumo", "city_dense.rou.xml"), "w") as f:
        f.write(routes(scale=2))
    if args.odr:
        subprocess.run([args.odr, "route", os.path.join(HERE, MAP), "--from", "1:-1", "--to", "3:-1",
                        "--ds", "2", "--no-lane-changes", "1", "--out",
                        os.path.join(HERE, "ego_route.csv")], check=True, stdout=subprocess.DEVNULL)


if __name__ == "__main__":
    main()
