"""The ego's longitudinal planner as a python_json engine (docs/architecture.md, "Ego planner").

Reads `planner_input` ({"source", "ego": RoadUser dict, "objects": [...]}, built by
planner_input_gt_tf.py or planner_input_det_tf.py) and publishes `target`
({"speed", "mode", "lead", "gap_m", "ttc_s"}): the target speed that motor_tf.py applies to
the report's PID waypoint follower. The parameters come from a JSON file: the environment's
CONVOY_EGO_PLANNER_CONFIG (set it with EngineEnvParams), default ego_planner.json, relative to
this script's folder. With CONVOY_EGO_ROUTE (a route CSV with columns x, y: the one the
follower drives) the planner's path is that route ahead (convoy_traffic.route_path), else the
ego's current curvature; with the route's map too ($CONVOY_EGO_MAP, else the scenario's in
the run folder's scenario_config.json: convoy_traffic.lanes) it passes stopped vehicles by a
lane change, and `target` also carries "steer" (rad) while the ego is off its route's lane.
At shutdown it writes its result (ego_stops_for_pedestrians, distances,
speed trace) to $CONVOY_RUN_DIR/<Output>.
"""
import json
import os

from nrp_core.engines.python_json import EngineScript

from convoy_traffic.ego_planner import Planner, parse_config, SOURCE_LABELS
from convoy_traffic.route_path import RoutePath
from convoy_traffic.lanes import RouteLanes, map_path
from convoy_scenario.roads import RoadMap
from convoy_scenario.xmltree import ScenarioError


class Script(EngineScript):
    def initialize(self):
        name = os.environ.get("CONVOY_EGO_PLANNER_CONFIG", "ego_planner.json")
        path = name if os.path.isabs(name) else os.path.join(os.path.dirname(os.path.abspath(__file__)), name)
        engine = "engine '%s' (ego planner)" % self._name
        try:
            with open(path) as f:
                cfg = json.load(f)
        except OSError as e:
            raise RuntimeError("%s: cannot read its config %s: %s" % (engine, path, e.strerror))
        except ValueError as e:
            raise RuntimeError("%s: %s is not valid JSON: %s" % (engine, path, e))
        self.params = parse_config(cfg, engine="%s, %s" % (engine, path))
        route = None
        route_csv = os.environ.get("CONVOY_EGO_ROUTE")
        if route_csv:
            try:
                route = RoutePath.from_csv(route_csv)
            except (OSError, KeyError, ValueError) as e:
                raise RuntimeError("%s: CONVOY_EGO_ROUTE %s: %s" % (engine, route_csv, e))
        lanes, map_file = None, None
        if route is not None and self.params["LaneChange"]:
            map_file = map_path()
            if map_file:
                try:
                    lanes = RouteLanes.from_map(route, RoadMap.open(map_file), map_file)
                except (OSError, ValueError, ScenarioError) as e:
                    raise RuntimeError("%s: the map %s: %s" % (engine, map_file, e))
        self.planner = Planner(self.params, route, lanes)
        self.engine = engine
        self.run_dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self._registerDataPack("planner_input")
        self._registerDataPack("target")
        self._setDataPack("target", {"speed": 0.0, "mode": "wait", "lead": None, "gap_m": None,
                                     "ttc_s": None, "input": self.params["Input"]})
        print("%s: input %s (%s), path: %s" % (engine, self.params["Input"],
                                                SOURCE_LABELS[self.params["Input"]],
                                                "route " + route_csv if route else "curvature"),
              flush=True)
        print("%s: lane changes %s%s" % (engine, self.planner.lane_change,
                                          " (map %s)" % map_file if map_file else ""), flush=True)

    def runLoop(self, timestep_ns):
        d = self._getDataPack("planner_input")
        if not d or "ego" not in d:
            return
        if d.get("source") != self.params["Input"]:
            raise RuntimeError("%s: key 'Input' is %r but its input TF sends %r objects; list the "
                               "matching planner_input TF" % (self.engine, self.params["Input"],
                                                             d.get("source")))
        out = self.planner.step(self._time_ns * 1e-9, d["ego"], d.get("objects", []))
        out["input"] = self.params["Input"]
        self._setDataPack("target", out)

    def shutdown(self):
        if not hasattr(self, "planner"):
            return  # initialize failed: its error is the message
        res = self.planner.result()
        with open(os.path.join(self.run_dir, self.params["Output"]), "w") as f:
            json.dump(res, f, indent=1, sort_keys=True)
        print("%s: ego_stops_for_pedestrians %d (input: %s)" % (
            self.engine, res["ego_stops_for_pedestrians"], res["input_label"]), flush=True)
