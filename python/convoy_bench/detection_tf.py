"""Detection against ground truth in a scenario run (docs/scoring.md, "Live scoring"): a
transceiver function at the scenario engine's rate that pairs each new set of the detector's
boxes with the ground truth of the camera frame they were made from, and writes the project's
one detection score (convoy_perception.evaluation) into $CONVOY_RUN_DIR/summary.json:
detector_map50, detector_map50_95, detector_precision, detector_recall,
detector_map50_per_class, detector_frames.

Timing: camera_tf sends the camera's image to the detector at the cycles the detector is due
(multiples of its EngineTimestep); it detects during its next step, so the detections read at
one of its cycles were made from the frame of its previous cycle: they are scored against the
ground-truth boxes read at that cycle. Only new detections (their `frame` count moved) count.

A pure function of the datapacks it reads (the detector's `detections`, the camera's
`::boxes`, the scenario engine's `scenario`) and of the cycle's time, so a replay of the run
gives the same fields. It writes every WRITE_EVERY scored frames and at the end (the scenario
engine's done, or the last cycle before SimulationTimeout)."""

import os
import sys

from nrp_core import *  # noqa: F401,F403

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from convoy_perception.evaluation import evaluate  # noqa: E402
from convoy_bench.run_files import load_config, update_summary  # noqa: E402

SCORED_CLASSES = ("bus", "car", "pedestrian")
WRITE_EVERY = 50  # scored frames (5 s at 10 Hz)
CAMERA_BOXES = "smart_camera::camera::boxes"


CONFIG = load_config()
ENGINES = CONFIG.get("EngineConfigs", [])
SCENARIO = next(e for e in ENGINES if e.get("EngineType") == "scenario")
DETECTOR = next(e for e in ENGINES if e.get("EngineType") == "detector")
WORLD = next(e["EngineName"] for e in ENGINES if e.get("EngineType") == "gazebo_grpc")
TIMEOUT = float(CONFIG.get("SimulationTimeout") or 0.0)
DT = float(SCENARIO.get("EngineTimestep", 0.05))
DETECTOR_DT_NS = int(round(float(DETECTOR.get("EngineTimestep", 0.1)) * 1e9))

_state = {"frames": [], "truth": None, "last": None, "final": False, "ground_truth": None}


def score_fields(frames, ground_truth_detector=False):
    """The summary fields for the scored frames ({"gt", "detections"} each)."""
    if not frames:
        return {"detector_frames": 0, "detector_map50": None}
    s = evaluate(frames, classes=list(SCORED_CLASSES), detections_inclusive=ground_truth_detector)
    return {"detector_frames": len(frames),
            "detector_map50": s.get("map50"),
            "detector_map50_95": s.get("map50_95"),
            "detector_precision": s.get("precision"),
            "detector_recall": s.get("recall"),
            "detector_map50_per_class": {c: v["ap50"] for c, v in s.get("classes", {}).items()}}


def _detection(time_ns, detections, boxes, scenario):
    if _state["final"]:
        return []
    det = None if detections.isEmpty() else detections.data
    new = False
    if det is not None and det.get("frame") != _state["last"] and _state["truth"] is not None:
        _state["last"] = det.get("frame")
        if _state["ground_truth"] is None and "ground_truth" in det:
            _state["ground_truth"] = bool(det["ground_truth"])
        _state["frames"].append({"gt": _state["truth"], "detections": list(det.get("detections", []))})
        new = True
    if time_ns % DETECTOR_DT_NS == 0 and not boxes.isEmpty():
        # the frame camera_tf sends the detector at this cycle
        _state["truth"] = [
            {"class": b["class"], "x_min": b["x_min"], "y_min": b["y_min"], "x_max": b["x_max"],
             "y_max": b["y_max"], "visible_fraction": b.get("visible_fraction", 1.0)}
            for b in boxes.data.get("boxes", []) if b.get("class") in SCORED_CLASSES]
    t = time_ns * 1e-9
    done = not scenario.isEmpty() and bool(scenario.data.get("done"))
    final = done or (TIMEOUT > 0 and t + DT > TIMEOUT + 1e-9)
    n = len(_state["frames"])
    if final or (new and n % WRITE_EVERY == 0):
        update_summary(score_fields(_state["frames"], bool(_state["ground_truth"])))
        _state["final"] = final
    return []


detection = _detection
detection = EngineDataPack(keyword="scenario", id=DataPackIdentifier("scenario", SCENARIO["EngineName"]))(detection)
detection = EngineDataPack(keyword="boxes", id=DataPackIdentifier(CAMERA_BOXES, WORLD))(detection)
detection = EngineDataPack(keyword="detections", id=DataPackIdentifier("detections", DETECTOR["EngineName"]))(detection)
detection = SimulationTime(keyword="time_ns")(detection)
detection = TransceiverFunction(SCENARIO["EngineName"])(detection)
