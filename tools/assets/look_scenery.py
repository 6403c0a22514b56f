#!/usr/bin/python3
"""Renders the scenery models (engines/gazebo_grpc/scenery, made by make_scenery.py) with the
world engine, to look at them.

  /usr/bin/python3 tools/assets/look_scenery.py OUT_DIR [--only NAME...] [--convoy build/bin/convoy]

writes OUT_DIR/scenery_buildings.png (the buildings' fronts), scenery_nature.png (trees,
shrubs and street furniture), scenery_signals.png (signs and lights at 14 m),
scenery_signs_20m.png and _40m.png (the same 20 and 40 m away), scenery_street.png (a street
lined with them, from a car's camera: docs/scenery_models.png) and scenery_tiles.png (each
model, a colour variant of each building, from 3/4 front; needs cv2); --only docs writes
scenery_models.png (the street over small tiles: docs/scenery_models.png). Each frame is a run of `convoy` with a world of a
ground, a sun, a camera and the models (their SDF links inlined, mesh paths made absolute);
a traffic light's red lamp and a pedestrian light's green one are lit (an emissive material
on the lamp's visual, as a world engine would)."""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
SCENERY = os.path.join(REPO, "engines", "gazebo_grpc", "scenery")
CATALOG = json.load(open(os.path.join(SCENERY, "scenery_models.json")))["models"]
LIT = {"red": "1 0.12 0.05 1", "yellow": "1 0.7 0.05 1", "green": "0.15 1 0.45 1"}

SAVE = """import struct, zlib
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
@TransceiverFunction("gazebo")
def save(camera):
    N[0] += 1
    if N[0] != 4 or camera.isEmpty():
        return []
    c = camera.data
    img = np.frombuffer(c.image_data, np.uint8).reshape(c.image_height, c.image_width, c.image_depth)
    write_png(OUT, img[:, :, :3].copy())
    return []
"""


def place(name, x, y, yaw=0.0, scale=1.0, lit=None, label=None):
    """A catalog model as an inline SDF <model> at (x, y), turned by yaw; lit: a lamp colour."""
    e = CATALOG[name]
    vis = []
    for v in e["visuals"]:
        mat = ""
        if "colour" in v:
            c = "%.3f %.3f %.3f 1" % tuple(v["colour"])
            mat = "<material><ambient>%s</ambient><diffuse>%s</diffuse></material>" % (c, c)
        if lit and e.get("lamps", {}).get(lit) == v["name"]:
            mat = "<material><ambient>%s</ambient><diffuse>%s</diffuse><emissive>%s</emissive></material>" % (
                LIT[lit], LIT[lit], LIT[lit])
        s = "%g %g %g" % (scale, scale, scale)
        vis.append("<visual name='%s'><geometry><mesh><uri>%s</uri><scale>%s</scale></mesh></geometry>%s</visual>"
                   % (v["name"], os.path.join(SCENERY, v["mesh"]), s, mat))
    return ("<model name='%s'><static>true</static><pose>%g %g 0 0 0 %g</pose><link name='link'>%s</link>"
            "<plugin name='convoy_class' filename='convoy_class'><class>%s</class></plugin></model>"
            % (label or name, x, y, yaw, "".join(vis), e["class"]))


def box(name, x, y, z, sx, sy, sz, rgb):
    c = "%.2f %.2f %.2f 1" % rgb
    return (f"<model name='{name}'><static>true</static><pose>{x} {y} {z + sz / 2} 0 0 0</pose><link name='l'>"
            f"<visual name='v'><geometry><box><size>{sx} {sy} {sz}</size></box></geometry>"
            f"<material><ambient>{c}</ambient><diffuse>{c}</diffuse></material></visual></link></model>")


def render(args, out, models, camera, size=(1280, 720), fov=1.1, ground=(0.4, 0.42, 0.38),
           sun="-0.5 0.35 -0.8"):
    """One frame OUT (png). camera: x y z roll pitch yaw."""
    d = tempfile.mkdtemp(prefix="look-scenery-")
    g = "%.2f %.2f %.2f 1" % ground
    world = f"""<?xml version="1.0"?>
<sdf version="1.7"><world name="look">
  <light name="sun" type="directional"><pose>0 0 10 0 0 0</pose>
    <diffuse>0.9 0.9 0.85 1</diffuse><specular>0.3 0.3 0.3 1</specular><direction>{sun}</direction></light>
  <scene><ambient>0.45 0.45 0.45 1</ambient><background>0.6 0.75 0.95 1</background></scene>
  <model name="rig"><static>true</static><pose>{' '.join('%.4f' % v for v in camera)}</pose>
    <link name="link"><sensor name="cam" type="camera"><camera><horizontal_fov>{fov}</horizontal_fov>
      <image><width>{size[0]}</width><height>{size[1]}</height></image><clip><near>0.1</near><far>400</far></clip>
    </camera></sensor></link></model>
  <model name="ground"><static>true</static><link name="link">
    <visual name="v"><geometry><plane><normal>0 0 1</normal><size>600 600</size></plane></geometry>
      <material><ambient>{g}</ambient><diffuse>{g}</diffuse></material></visual></link></model>
  {chr(10).join(models)}
</world></sdf>
"""
    with open(os.path.join(d, "world.sdf"), "w") as f:
        f.write(world)
    with open(os.path.join(d, "save.py"), "w") as f:
        f.write(SAVE % os.path.abspath(out))
    cfg = {"SimulationName": "look_scenery", "SimulationTimeout": 0.1,
           "EngineConfigs": [{"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
                              "EngineTimestep": 0.02}],
           "DataPackProcessingFunctions": [{"Name": "save", "FileName": "save.py"}]}
    with open(os.path.join(d, "simulation_config.json"), "w") as f:
        json.dump(cfg, f, indent=1)
    r = subprocess.run([args.convoy, "run", "-q", "-c", "simulation_config.json", "--run-dir", os.path.join(d, "run")],
                       cwd=d, capture_output=True, text=True)
    if r.returncode or not os.path.exists(out):
        sys.exit("%s: convoy failed (%s): %s" % (out, d, r.stderr[-3000:]))
    shutil.rmtree(d)
    print("wrote", out)


def names(kind_prefix):
    return [n for n, e in CATALOG.items() if e["kind"] in kind_prefix]


def buildings(args):
    """The buildings in a row, fronts towards the camera (+x), in alternating colours."""
    row, y = [], 0.0
    types = ["terraced_house_brick", "terraced_house_plaster", "detached_house_plaster", "apartment_3_brick",
             "corner_shop_plaster", "apartment_4_beige", "apartment_5_grey", "apartment_6_plaster",
             "office_block_grey"]
    for n in types:
        w = CATALOG[n]["size"][1]
        row.append(place(n, 0, y - w / 2, label="b_" + n))
        y -= w + (0.0 if n.startswith("terraced_house") and "plaster" not in n else 3.0)
    mid = y / 2
    render(args, os.path.join(args.out, "scenery_buildings.png"), row,
           [85, mid, 1.7, 0, -0.08, math.pi], size=(1600, 640), fov=1.75)


def nature(args):
    """Trees and shrubs behind a line of street furniture."""
    ms = []
    for k, n in enumerate(["tree_lime", "tree_birch", "tree_plane", "tree_spruce"]):
        ms.append(place(n, -4, 10 - 7 * k))
    for k, n in enumerate(["shrub_round", "shrub_hedge", "shrub_round"]):
        ms.append(place(n, -1.5, 6.5 - 7 * k, yaw=0.7 * k, label="%s_%d" % (n, k)))
    furniture = [("street_light", 8), ("bench", 5.5), ("litter_bin", 4.2), ("bus_stop", 0.5),
                 ("bollard", -3.2), ("guide_post", -4.2), ("guard_rail", -7), ("concrete_barrier", -12)]
    for n, y in furniture:
        ms.append(place(n, 2.5, y))
    render(args, os.path.join(args.out, "scenery_nature.png"), ms, [19, -1.5, 1.8, 0, -0.05, math.pi],
           fov=1.3)


def signals(args, out, dist, fov, size=(1280, 720)):
    """The signs and lights in two rows facing the camera, `dist` m away."""
    signs = [n for n in CATALOG if CATALOG[n]["kind"] == "sign"]
    ms = [place("traffic_light", 0, 6.2, lit="red", label="tl_red"),
          place("traffic_light", 0, 5.4, lit="green", label="tl_green"),
          place("pedestrian_light", 0, 4.6, lit="green", label="pl_green"),
          place("pedestrian_light", 0, 3.9, lit="red", label="pl_red")]
    for k, n in enumerate(signs):
        row, col = divmod(k, 9)
        ms.append(place(n, -2.0 * row, 2.8 - 1.0 * col))
    render(args, out, ms, [dist, -1.2, 1.7, 0, -0.06, math.pi], size=size, fov=fov)


def street(args, out):
    """A street: two lanes, sidewalks, buildings both sides, trees, lights, signs, seen from a
    car's camera in the right lane."""
    ms = [box("road", 60, 0, -0.03, 200, 7.0, 0.03, (0.25, 0.25, 0.26)),
          box("walk_l", 60, 5.5, -0.03, 200, 4.0, 0.15, (0.6, 0.59, 0.56)),
          box("walk_r", 60, -5.5, -0.03, 200, 4.0, 0.15, (0.6, 0.59, 0.56))]
    ms += [box("dash%d" % k, 4 + k * 8, 0, 0, 3, 0.15, 0.005, (0.9, 0.9, 0.9)) for k in range(25)]
    left = ["apartment_5_brick", "corner_shop_plaster", "apartment_4_beige", "apartment_6_grey", "office_block_beige"]
    right = ["terraced_house_brick", "terraced_house_plaster", "terraced_house_beige", "detached_house_plaster",
             "apartment_3_grey", "apartment_5_plaster"]
    for side, row in ((1, left), (-1, right)):
        x = 8.0
        for k, n in enumerate(row):
            L, W, _ = CATALOG[n]["size"]
            yaw = -math.pi / 2 if side > 0 else math.pi / 2  # fronts to the street
            ms.append(place(n, x + W / 2, side * (8.5 + L / 2), yaw, label="%s_%d_%d" % (n, side, k)))
            x += W + (0.0 if n.startswith("terraced") else 4.0)
    trees = ["tree_lime", "tree_plane", "tree_birch", "tree_lime", "tree_spruce", "tree_plane"]
    for k, n in enumerate(trees):
        ms.append(place(n, 14 + 15 * k, 4.6, label="t%d" % k, scale=0.8))
        ms.append(place("street_light", 20 + 15 * k, -4.3, yaw=math.pi / 2, label="sl%d" % k))
    ms.append(place("sign_speed_50", 12, -4.6, yaw=math.pi, label="s50"))
    ms.append(place("sign_stop", 40, -4.6, yaw=math.pi, label="sstop"))
    ms.append(place("traffic_light", 62, -4.2, yaw=math.pi, lit="green", label="tl"))
    ms.append(place("sign_yield", 26, 4.0, yaw=math.pi, label="syield"))
    ms.append(place("bus_stop", 33, -5.9, yaw=math.pi / 2, label="bus"))
    ms.append(place("bench", 50, 5.0, yaw=-math.pi / 2, label="bench"))
    ms.append(place("litter_bin", 49, 4.6, yaw=-math.pi / 2, label="bin"))
    ms.append(place("shrub_hedge", 46, -6.8, yaw=0, label="hedge"))
    render(args, out, ms, [0, -1.75, 1.5, 0, -0.02, 0.06], size=(1280, 720), fov=1.25, sun="-0.55 -0.35 -0.75")


def tile_models():
    """Every model once (a building in its first colour, one speed limit), in catalog order."""
    first = {}
    for n, e in CATALOG.items():
        key = e["visuals"][-1]["mesh"] if e["kind"] == "building" else n
        first.setdefault(key, n)
    return [n for n in first.values() if not n.startswith("sign_speed_") or n == "sign_speed_50"]


def tiles(args, out, models, cols, size=(480, 360)):
    """One frame per model from 3/4 front (35 degrees off +x), stitched cols to a row (cv2)."""
    import cv2
    import numpy as np
    imgs = []
    for k, n in enumerate(models):
        L, W, H = CATALOG[n]["size"]
        dist = 1.2 * max(H / 0.62, 0.9 * W, L) + 1.5
        a = math.radians(35)
        cx, cy = dist * math.cos(a), dist * math.sin(a)
        h = min(1.7, H * 0.6) if H < 3 else 1.7
        cam = [cx, cy, h, 0, math.atan2(h - H * 0.45, dist), math.atan2(-cy, -cx)]
        prefix = os.path.join(args.out, "_tile%d.png" % k)
        render(args, prefix, [place(n, 0, 0, lit="green" if "light" in n and "street" not in n else None)], cam,
               size=size, fov=0.9)
        img = cv2.imread(prefix)
        cv2.putText(img, n, (8, size[1] - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.55, (255, 255, 255), 1, cv2.LINE_AA)
        imgs.append(img)
        os.remove(prefix)
    while len(imgs) % cols:
        imgs.append(np.zeros_like(imgs[0]))
    cv2.imwrite(out, np.vstack([np.hstack(imgs[i:i + cols]) for i in range(0, len(imgs), cols)]))
    print("wrote", out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="output folder")
    ap.add_argument("--convoy", default=os.path.join(REPO, "build", "bin", "convoy"))
    ap.add_argument("--only", nargs="*", help="buildings nature signals far street tiles docs")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    todo = args.only or ["buildings", "nature", "signals", "far", "street"]
    if "buildings" in todo:
        buildings(args)
    if "nature" in todo:
        nature(args)
    if "signals" in todo:
        signals(args, os.path.join(args.out, "scenery_signals.png"), 14, 1.1)
    if "far" in todo:
        for dist in (20, 40):
            signals(args, os.path.join(args.out, "scenery_signs_%dm.png" % dist), dist, 1.1, size=(1280, 720))
    if "street" in todo:
        street(args, os.path.join(args.out, "scenery_street.png"))
    if "tiles" in todo:
        tiles(args, os.path.join(args.out, "scenery_tiles.png"), tile_models(), 5)
    if "docs" in todo:  # docs/scenery_models.png: the street over the models
        import cv2
        import numpy as np
        street(args, os.path.join(args.out, "_street.png"))
        tiles(args, os.path.join(args.out, "_tiles.png"), tile_models(), 5, size=(256, 180))
        a, b = cv2.imread(os.path.join(args.out, "_street.png")), cv2.imread(os.path.join(args.out, "_tiles.png"))
        cv2.imwrite(os.path.join(args.out, "scenery_models.png"), np.vstack([a, b]), [cv2.IMWRITE_PNG_COMPRESSION, 9])
        for f in ("_street.png", "_tiles.png"):
            os.remove(os.path.join(args.out, f))


if __name__ == "__main__":
    main()
