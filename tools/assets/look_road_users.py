#!/usr/bin/python3
"""Renders the road-user actor models with the world engine, to look at them and to measure
how recognisable they are (docs/road_users.md, "Actor models").

  /usr/bin/python3 tools/assets/look_road_users.py docs OUT_DIR
      the frames in docs/: road_users_cars.png (vehicles, 3/4 front and rear),
      road_users_pedestrians.png (people and cyclists), road_users_street.png (a street)
  /usr/bin/python3 tools/assets/look_road_users.py streets OUT_DIR [--count 40] [--table T]
      street scenes seen from a car's camera, random road users (seeds 1..count): street_N.png
      and street_N.json (the camera's ground-truth boxes)
  /usr/bin/python3 tools/assets/look_road_users.py detect OUT_DIR --detector MODEL.onnx
      runs a COCO detector on the street scenes and prints its recall per class

Each frame is a run of `convoy` (--convoy, default build/bin/convoy) with a world of a ground,
a sun and a camera, a python_json engine sending the road users and a TF forwarding them;
--table picks the actor-model table (default: the repository's). The detector is the stock
COCO detector of /work/shared/tools/stock_detector (YOLOv8 output layout, 512 x 512 input);
it is read like engines/detector reads a YOLO model: letterboxed (grey 114), RGB / 255,
confidence > 0.25, per-class NMS 0.45. A ground-truth box at least 40 px tall is found when a
detection of an accepted class overlaps it with IoU >= 0.5: car, truck or bus for the
vehicles, person for pedestrians, person or bicycle for cyclists."""
import argparse
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
TABLE = os.path.join(REPO, "engines", "gazebo_grpc", "actors", "actor_models.json")

TRAFFIC = """from nrp_core.engines.python_json import EngineScript
USERS = %r
class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("road_users")
        self._setDataPack("road_users", {"users": USERS})
    def runLoop(self, timestep_ns):
        self._setDataPack("road_users", {"users": USERS})
"""

FORWARD = """from nrp_core import *
from nrp_core.data.nrp_json import *
@EngineDataPack(keyword='src', id=DataPackIdentifier('road_users', 'traffic'))
@TransceiverFunction("gazebo")
def forward(src):
    if src.isEmpty():
        return []
    dp = JsonDataPack("road_users", "gazebo")
    dp.data["users"] = src.data["users"]
    return [dp]
"""

SAVE = """import json, struct, zlib
import numpy as np
from nrp_core import *
OUT = %r
N = [0]
def write_png(path, image):
    h, w, _ = image.shape
    raw = b"".join(b"\\x00" + image[row].tobytes() for row in range(h))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    with open(path, "wb") as f:
        f.write(b"\\x89PNG\\r\\n\\x1a\\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
@EngineDataPack(keyword='camera', id=DataPackIdentifier('rig::link::cam', 'gazebo'))
@EngineDataPack(keyword='boxes', id=DataPackIdentifier('rig::link::cam::boxes', 'gazebo'))
@TransceiverFunction("gazebo")
def save(camera, boxes):
    N[0] += 1
    if N[0] != 8 or camera.isEmpty():
        return []
    c = camera.data
    img = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    write_png(OUT + ".png", img[:, :, :3].copy())
    with open(OUT + ".json", "w") as f:
        json.dump(boxes.data["boxes"] if not boxes.isEmpty() else [], f)
    return []
"""


def render(args, out, users, camera, size=(1280, 720), fov=1.2, ground=(0.36, 0.36, 0.37),
           sun="-0.4 0.3 -0.85", extra=""):
    """One frame: OUT.png, OUT.json. camera: x y z roll pitch yaw."""
    d = tempfile.mkdtemp(prefix="look-")
    g = "%.2f %.2f %.2f 1" % ground
    world = f"""<?xml version="1.0"?>
<sdf version="1.7"><world name="look">
  <light name="sun" type="directional"><pose>0 0 10 0 0 0</pose>
    <diffuse>0.9 0.9 0.85 1</diffuse><specular>0.3 0.3 0.3 1</specular><direction>{sun}</direction></light>
  <scene><ambient>0.45 0.45 0.45 1</ambient><background>0.6 0.75 0.95 1</background></scene>
  <model name="rig"><static>true</static><pose>{' '.join('%.4f' % v for v in camera)}</pose>
    <link name="link"><sensor name="cam" type="camera"><camera><horizontal_fov>{fov}</horizontal_fov>
      <image><width>{size[0]}</width><height>{size[1]}</height></image><clip><near>0.1</near><far>300</far></clip>
    </camera></sensor></link></model>
  <model name="ground"><static>true</static><link name="link">
    <collision name="c"><geometry><plane><normal>0 0 1</normal><size>400 400</size></plane></geometry></collision>
    <visual name="v"><geometry><plane><normal>0 0 1</normal><size>400 400</size></plane></geometry>
      <material><ambient>{g}</ambient><diffuse>{g}</diffuse></material></visual></link></model>
  {extra}
</world></sdf>
"""
    users = [dict(u, id=u.get("id", "u%d_%s" % (k, u["model"]))) for k, u in enumerate(users)]
    files = {"world.sdf": world, "traffic.py": TRAFFIC % users, "forward.py": FORWARD,
             "save.py": SAVE % os.path.abspath(out)}
    for name, text in files.items():
        with open(os.path.join(d, name), "w") as f:
            f.write(text)
    cfg = {"SimulationName": "look", "SimulationTimeout": 0.24,
           "EngineConfigs": [{"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
                              "EngineTimestep": 0.02, "ActorModels": os.path.abspath(args.table), "ActorTimeout": 0},
                             {"EngineType": "python_json", "EngineName": "traffic", "PythonFileName": "traffic.py",
                              "EngineTimestep": 0.02}],
           "DataPackProcessingFunctions": [{"Name": "forward", "FileName": "forward.py"},
                                           {"Name": "save", "FileName": "save.py"}]}
    with open(os.path.join(d, "simulation_config.json"), "w") as f:
        json.dump(cfg, f, indent=1)
    r = subprocess.run([args.convoy, "run", "-q", "-c", "simulation_config.json", "--run-dir", os.path.join(d, "run")],
                       cwd=d, capture_output=True, text=True)
    if r.returncode or not os.path.exists(out + ".png"):
        sys.exit("%s: convoy failed (%s): %s" % (out, d, r.stderr[-2000:]))
    shutil.rmtree(d)


def look_at(target, az_deg, dist, height):
    """A camera pose at `dist` from target (x, y, z) in direction az, `height` up, aimed at it."""
    a = math.radians(az_deg)
    cx, cy = target[0] + dist * math.cos(a), target[1] + dist * math.sin(a)
    return [cx, cy, height, 0, math.atan2(height - target[2], dist), math.atan2(target[1] - cy, target[0] - cx)]


def tiles(args, out, specs, cols, size):
    import cv2
    import numpy as np
    imgs = []
    for k, (model, az, dist, height, tz) in enumerate(specs):
        prefix = os.path.join(args.out, "_tile%d" % k)
        render(args, prefix, [{"model": model, "x": 0, "y": 0}], look_at((0, 0, tz), az, dist, height),
               size=size, fov=0.75, ground=(0.42, 0.42, 0.43))
        imgs.append(cv2.imread(prefix + ".png"))
        os.remove(prefix + ".png")
        os.remove(prefix + ".json")
    rows = [np.hstack(imgs[i:i + cols]) for i in range(0, len(imgs), cols)]
    cv2.imwrite(out, np.vstack(rows))


def street(args, seed, out):
    """A street (4 lanes, sidewalks, houses) seen from a car in the right lane, random road users."""
    R = random.Random(seed)

    def box(name, x, y, z, sx, sy, sz, rgb):
        c = "%.2f %.2f %.2f 1" % rgb
        return (f"<model name='{name}'><static>true</static><pose>{x} {y} {z + sz / 2} 0 0 0</pose><link name='l'>"
                f"<visual name='v'><geometry><box><size>{sx} {sy} {sz}</size></box></geometry>"
                f"<material><ambient>{c}</ambient><diffuse>{c}</diffuse></material></visual></link></model>")

    extra = [box("walk_l", 60, 9.5, -0.02, 200, 5, 0.15, (0.62, 0.6, 0.57)),
             box("walk_r", 60, -9.5, -0.02, 200, 5, 0.15, (0.62, 0.6, 0.57)),
             box("edge_l", 60, 6.9, 0, 200, 0.15, 0.005, (0.9, 0.9, 0.9)),
             box("edge_r", 60, -6.9, 0, 200, 0.15, 0.005, (0.9, 0.9, 0.9))]
    extra += [box("dash%d" % k, 4 + k * 8, 0, 0, 3, 0.15, 0.005, (0.9, 0.9, 0.9)) for k in range(25)]
    for k in range(14):
        for side in (1, -1):
            h, w, g = R.uniform(6, 18), R.uniform(8, 16), R.uniform(0.45, 0.8)
            extra.append(box("house%d_%d" % (k, side), -5 + k * 15, side * (12 + w / 2), 0, 13, w, h,
                             (g, g * R.uniform(0.85, 1.0), g * R.uniform(0.75, 0.95))))
    models = json.load(open(args.table))["models"]
    kinds = {"car": [], "bus": [], "truck": [], "pedestrian": [], "cyclist": []}
    for key, e in models.items():
        if "_" in key or len(models) < 20:  # the variants (an old table: every entry)
            kinds[e["class"]].append(key)
    users, taken = [], []

    def free(x, y, r):
        return all((x - a) ** 2 + (y - b) ** 2 > (r + c) ** 2 for a, b, c in taken)

    def add(model, x, y, yaw, r, z=0.0):
        off = models[model]["length_offset"]  # (x, y) is the reference point, behind the box's centre
        cx, cy = x + off * math.cos(yaw), y + off * math.sin(yaw)
        if free(cx, cy, r):
            taken.append((cx, cy, r))
            users.append({"model": model, "category": models[model]["class"], "x": x, "y": y, "z": z, "yaw": yaw})
            return True
        return False

    lanes = [(-1.75, 0.0), (-5.25, 0.0), (1.75, math.pi), (5.25, math.pi)]
    for _ in range(R.randint(4, 7)):
        lane_y, yaw = R.choice(lanes)
        u = R.random()
        cls = "bus" if u < 0.18 else "truck" if u < 0.32 else "car"
        model = R.choice(kinds[cls])
        for _ in range(20):
            if add(model, R.uniform(8, 55), lane_y, yaw + R.uniform(-0.05, 0.05), models[model]["size"][0] / 2 + 1):
                break
    if R.random() < 0.5:  # a car turning across
        add(R.choice(kinds["car"]), R.uniform(18, 35), R.uniform(-3, 3), R.choice([1.2, -1.2, 2.0, -2.0]), 3)
    for _ in range(R.randint(3, 6)):
        side = R.choice([1, -1])
        x, y = R.uniform(6, 35), side * R.uniform(7.5, 11)
        if R.random() < 0.25:
            y = R.uniform(-6, 6)  # crossing
        add(R.choice(kinds["pedestrian"]), x, y, R.uniform(-math.pi, math.pi), 0.6, 0.13 if abs(y) > 7 else 0.0)
    if R.random() < 0.6:
        y = R.choice([-6.3, 6.3])
        add(R.choice(kinds["cyclist"]), R.uniform(8, 30), y, 0.0 if y < 0 else math.pi, 1.2)
    render(args, out, users, [0, -1.75, 1.45, 0, 0.04, R.uniform(-0.12, 0.12)], size=(1280, 720), fov=1.3,
           ground=(0.28, 0.28, 0.29), sun=R.choice(["-0.4 0.3 -0.85", "0.5 -0.4 -0.7", "-0.6 -0.5 -0.6"]),
           extra="\n".join(extra))


COCO = {0: "person", 1: "bicycle", 2: "car", 3: "motorcycle", 5: "bus", 7: "truck"}
ACCEPT = {"car": {"car", "truck", "bus"}, "bus": {"car", "truck", "bus"}, "truck": {"car", "truck", "bus"},
          "pedestrian": {"person"}, "cyclist": {"person", "bicycle"}}


def detect(net, img, size=512, conf_min=0.25, nms=0.45):
    import cv2
    import numpy as np
    h, w = img.shape[:2]
    s = min(size / w, size / h)
    nw, nh = round(w * s), round(h * s)
    px, py = (size - nw) // 2, (size - nh) // 2
    lb = cv2.copyMakeBorder(cv2.resize(img, (nw, nh)), py, size - nh - py, px, size - nw - px,
                            cv2.BORDER_CONSTANT, value=(114, 114, 114))
    net.setInput(cv2.dnn.blobFromImage(lb, 1 / 255.0, (size, size), swapRB=True))
    out = net.forward()[0].T  # candidates x (cx cy w h, 80 scores)
    cls = out[:, 4:].argmax(1)
    conf = out[np.arange(len(cls)), 4 + cls]
    dets = []
    for c in np.unique(cls[conf > conf_min]):
        idx = np.where((conf > conf_min) & (cls == c))[0]
        boxes = [[float(out[i, 0] - out[i, 2] / 2), float(out[i, 1] - out[i, 3] / 2), float(out[i, 2]),
                  float(out[i, 3])] for i in idx]
        for j in np.array(cv2.dnn.NMSBoxes(boxes, [float(conf[i]) for i in idx], conf_min, nms)).flatten():
            x, y, bw, bh = boxes[j]
            x0, y0 = (x - px) / s, (y - py) / s
            dets.append((COCO.get(int(c), str(int(c))), x0, y0, x0 + bw / s, y0 + bh / s))
    return dets


def iou(a, b):
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    i = ix * iy
    return i / ((a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - i + 1e-9)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=["docs", "streets", "detect"])
    ap.add_argument("out", help="output folder")
    ap.add_argument("--count", type=int, default=40, help="street scenes (seeds 1..count)")
    ap.add_argument("--table", default=TABLE, help="actor-model table")
    ap.add_argument("--convoy", default=os.path.join(REPO, "build", "bin", "convoy"))
    ap.add_argument("--detector", help="the stock COCO detector (ONNX), for detect")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.what == "docs":
        tiles(args, os.path.join(args.out, "road_users_cars.png"), [
            ("hatchback_red", 35, 9.5, 2.2, 0.6), ("sedan_silver", 35, 10, 2.2, 0.6), ("suv_blue", 35, 10, 2.3, 0.7),
            ("van_white", 35, 11.5, 2.6, 0.9), ("bus_red", 35, 23, 4, 1.4), ("truck_blue", 35, 19, 4, 1.5),
            ("sedan_black", 215, 8.5, 2.2, 0.6), ("bus_yellow", 215, 18, 4, 1.3), ("truck_white", 215, 15, 4, 1.4)],
            3, (426, 240))
        people = [("pedestrian_man_1", -2.6), ("walker_woman_1", 2.0), ("pedestrian_tall_man_1", -2.5),
                  ("walker_woman_coat_2", -1.2), ("walker_man_2", 1.57), ("pedestrian_woman_2", 2.7),
                  ("walker_tall_man_3", -1.9), ("pedestrian_woman_coat_3", 2.6), ("walker_woman_3", 1.2)]
        users = [{"model": m, "x": 0.35 * (k % 2), "y": 4.4 - 1.1 * k, "yaw": yaw} for k, (m, yaw) in enumerate(people)]
        users += [{"model": "cyclist_1", "x": -2.3, "y": 3.6, "yaw": -1.9},
                  {"model": "cyclist_3", "x": -2.6, "y": -3.4, "yaw": -1.2}]
        render(args, os.path.join(args.out, "road_users_pedestrians"), users, [9.6, 0, 1.6, 0, 0.07, math.pi],
               size=(1280, 560), fov=1.0, ground=(0.42, 0.42, 0.43))
        street(args, 13, os.path.join(args.out, "road_users_street"))
        for f in ("road_users_pedestrians.json", "road_users_street.json"):
            os.remove(os.path.join(args.out, f))
    elif args.what == "streets":
        for seed in range(1, args.count + 1):
            street(args, seed, os.path.join(args.out, "street_%d" % seed))
    else:
        import cv2
        net = cv2.dnn.readNetFromONNX(args.detector)
        total, found = {}, {}
        for seed in range(1, args.count + 1):
            prefix = os.path.join(args.out, "street_%d" % seed)
            if not os.path.exists(prefix + ".json"):
                continue
            dets = detect(net, cv2.imread(prefix + ".png"))
            for g in json.load(open(prefix + ".json")):
                box = (g["x_min"], g["y_min"], g["x_max"], g["y_max"])
                if g["class"] not in ACCEPT or box[3] - box[1] < 40:
                    continue
                hit = any(d[0] in ACCEPT[g["class"]] and iou(box, d[1:]) >= 0.5 for d in dets)
                total[g["class"]] = total.get(g["class"], 0) + 1
                found[g["class"]] = found.get(g["class"], 0) + hit
        for c in sorted(total):
            print("%-10s %3d of %3d found (%.0f%%)" % (c, found[c], total[c], 100.0 * found[c] / total[c]))


if __name__ == "__main__":
    main()
