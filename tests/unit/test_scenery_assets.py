"""The roadside scenery models (engines/gazebo_grpc/scenery, written by
tools/assets/make_scenery.py): the committed files are what the generator writes; every
catalog entry's meshes, materials and textures exist and agree with its size, triangle count,
budget and class; the SDF models match the catalog; the lights' lamps are meshes of their own;
the sign faces are textured and their PNGs decode.

Run: cd tests/unit && /usr/bin/python3 -m unittest -v test_scenery_assets (ctest: py_scenery_assets)."""

import filecmp
import json
import os
import shutil
import struct
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree as ET
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SCENERY = os.path.join(REPO, "engines", "gazebo_grpc", "scenery")
CATALOG = os.path.join(SCENERY, "scenery_models.json")
GENERATOR = os.path.join(REPO, "tools", "assets", "make_scenery.py")

CLASSES = {"building", "tree", "shrub", "pole", "traffic_light", "sign", "barrier", "other"}
# kind: (class, triangle budget)
KINDS = {"building": ("building", 1500), "tree": ("tree", 1200), "shrub": ("shrub", 300),
         "street_light": ("pole", 400), "bench": ("other", 400), "bin": ("other", 400),
         "bus_stop": ("other", 800), "bollard": ("pole", 400), "guard_rail": ("barrier", 400),
         "barrier": ("barrier", 400), "traffic_light": ("traffic_light", 800),
         "pedestrian_light": ("traffic_light", 800), "sign": ("sign", 400)}
SPEEDS = {5, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120, 130}


def load_catalog():
    with open(CATALOG, encoding="utf-8") as f:
        return json.load(f)


def read_obj(path):
    """(vertices, uvs, faces [(v indices, vt indices or None)], mtllib or None) of an OBJ."""
    vs, vts, faces, mtl = [], [], [], None
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vs.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("vt "):
                vts.append(tuple(float(x) for x in line.split()[1:3]))
            elif line.startswith("f "):
                corners = [c.split("/") for c in line.split()[1:]]
                faces.append(([int(c[0]) for c in corners], [int(c[1]) for c in corners] if corners[0][1] else None))
            elif line.startswith("mtllib "):
                mtl = line.split(None, 1)[1].strip()
    return vs, vts, faces, mtl


def read_mtl(path):
    """{material: {key: value string}} of an MTL."""
    out, cur = {}, None
    with open(path) as f:
        for line in f:
            parts = line.split(None, 1)
            if not parts or parts[0].startswith("#"):
                continue
            if parts[0] == "newmtl":
                cur = out.setdefault(parts[1].strip(), {})
            elif cur is not None and len(parts) == 2:
                cur[parts[0]] = parts[1].strip()
    return out


def decode_png(path):
    """(width, height, rows of (r, g, b)) of an 8-bit RGB or RGBA PNG, with the stdlib only."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, head = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        assert struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0] == zlib.crc32(kind + body), "bad CRC"
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, colour, _, _, interlace = head
    assert depth == 8 and colour in (2, 6) and interlace == 0, head
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        ftype, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[k * bpp:k * bpp + 3]) for k in range(w)])
        prev = line
    return w, h, rows


class Files(unittest.TestCase):
    def test_committed_files_are_what_the_generator_writes(self):
        out = tempfile.mkdtemp(prefix="convoy-scenery-")
        self.addCleanup(shutil.rmtree, out, True)
        subprocess.run(["/usr/bin/python3", GENERATOR, "--out", out], check=True, stdout=subprocess.DEVNULL,
                       env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
        stack = [filecmp.dircmp(out, SCENERY)]
        while stack:
            c = stack.pop()
            self.assertEqual(c.left_only, [], "missing from the repository (run the generator)")
            self.assertEqual(c.right_only, [], "not written by the generator")
            _, mismatch, errors = filecmp.cmpfiles(c.left, c.right, c.common_files, shallow=False)
            self.assertEqual(mismatch + errors, [], "out of date: run /usr/bin/python3 tools/assets/make_scenery.py")
            stack += c.subdirs.values()
        total = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(SCENERY) for f in fs)
        self.assertLess(total, 4_000_000)


class Catalog(unittest.TestCase):
    def test_the_required_models_are_there(self):
        models = load_catalog()["models"]
        kinds = {}
        for name, e in models.items():
            kinds.setdefault(e["kind"], set()).add(name)
        self.assertGreaterEqual(len({n.rsplit("_", 1)[0] for n in kinds["building"]}), 6)
        self.assertGreaterEqual(len(kinds["tree"]), 4)
        self.assertGreaterEqual(len(kinds["shrub"]), 2)
        for kind in ("street_light", "bench", "bin", "bus_stop", "bollard", "guard_rail", "barrier",
                     "traffic_light", "pedestrian_light"):
            self.assertIn(kind, kinds)
        signs = [models[n]["sign"] for n in kinds["sign"]]
        self.assertTrue({"stop", "yield", "no_entry", "speed_limit", "warning"} <= {s["type"] for s in signs})
        self.assertEqual({s["value"] for s in signs if s["type"] == "speed_limit"}, SPEEDS)

    def test_entries_match_their_files(self):
        for name, e in load_catalog()["models"].items():
            with self.subTest(model=name):
                self.assertIn(e["kind"], KINDS)
                cls, budget = KINDS[e["kind"]]
                self.assertIn(e["class"], CLASSES)
                self.assertEqual(e["class"], cls)
                lo, hi, tris, names = [1e9] * 3, [-1e9] * 3, 0, set()
                for v in e["visuals"]:
                    self.assertNotIn(v["name"], names)
                    names.add(v["name"])
                    path = os.path.join(SCENERY, v["mesh"])
                    vs, vts, faces, mtl = read_obj(path)
                    tris += sum(len(f) - 2 for f, _ in faces)
                    for p in vs:
                        lo = [min(a, b) for a, b in zip(lo, p)]
                        hi = [max(a, b) for a, b in zip(hi, p)]
                    self.check_materials(path, mtl, vts, faces)
                    if "colour" in v:
                        self.assertEqual(len(v["colour"]), 3)
                self.assertEqual(tris, e["triangles"])
                self.assertLessEqual(tris, budget)
                size = [b - a for a, b in zip(lo, hi)]
                for k in range(3):
                    self.assertAlmostEqual(size[k], e["size"][k], delta=0.01)
                self.assertAlmostEqual((lo[0] + hi[0]) / 2, 0.0, delta=0.01)  # origin: the base's centre
                self.assertAlmostEqual((lo[1] + hi[1]) / 2, 0.0, delta=0.01)
                self.assertAlmostEqual(lo[2], 0.0, delta=0.01)
                self.assertGreaterEqual(len(e["collisions"]), 1 if e["kind"] != "shrub" else 0)
                for c in e["collisions"]:
                    self.assertEqual(len(c["pose"]), 6)
                    self.assertTrue(all(s > 0 for s in c["box"]))

    def check_materials(self, obj, mtl, vts, faces):
        self.assertIsNotNone(mtl, obj)
        mtl_path = os.path.join(os.path.dirname(obj), mtl)
        materials = read_mtl(mtl_path)
        with open(obj) as f:
            used = {line.split()[1] for line in f if line.startswith("usemtl ")}
        self.assertTrue(used <= set(materials), (obj, used - set(materials)))
        textured = [m for m in used if "map_Kd" in materials[m]]
        for m in textured:
            self.assertTrue(os.path.exists(os.path.join(os.path.dirname(mtl_path), materials[m]["map_Kd"])))
        if textured:
            self.assertTrue(vts, obj)
            self.assertTrue(all(0.0 <= u <= 1.0 and 0.0 <= v <= 1.0 for u, v in vts), obj)
            self.assertTrue(any(t is not None for _, t in faces), obj)

    def test_sdf_models_match_the_catalog(self):
        for name, e in load_catalog()["models"].items():
            with self.subTest(model=name):
                model = ET.parse(os.path.join(SCENERY, name + ".sdf")).getroot().find("model")
                self.assertEqual(model.get("name"), name)
                self.assertEqual(model.find("static").text, "true")
                link = model.find("link")
                visuals = {v.get("name"): v.find("geometry/mesh/uri").text for v in link.findall("visual")}
                self.assertEqual(visuals, {v["name"]: v["mesh"] for v in e["visuals"]})
                self.assertEqual(len(link.findall("collision")), len(e["collisions"]))
                self.assertEqual(model.find("plugin[@name='convoy_class']/class").text, e["class"])
                for v in e["visuals"]:
                    diffuse = link.find("visual[@name='%s']/material/diffuse" % v["name"])
                    if "colour" in v:
                        self.assertEqual([round(float(x), 3) for x in diffuse.text.split()[:3]], v["colour"])
                    else:
                        self.assertIsNone(diffuse)

    def test_lights_have_a_mesh_per_lamp(self):
        models = load_catalog()["models"]
        for name, colours in (("traffic_light", {"red", "yellow", "green"}), ("pedestrian_light", {"red", "green"})):
            e = models[name]
            self.assertEqual(set(e["lamps"]), colours)
            meshes = {v["name"]: v["mesh"] for v in e["visuals"]}
            for colour, visual in e["lamps"].items():
                self.assertEqual(meshes[visual], "meshes/%s_lamp_%s.obj" % (name, colour))
                _, _, faces, _ = read_obj(os.path.join(SCENERY, meshes[visual]))
                self.assertGreater(len(faces), 0)

    def test_textures_decode(self):
        pngs = sorted(f for f in os.listdir(os.path.join(SCENERY, "meshes")) if f.endswith(".png"))
        self.assertGreaterEqual(len(pngs), 18)
        for f in pngs:
            with self.subTest(png=f):
                w, h, rows = decode_png(os.path.join(SCENERY, "meshes", f))
                self.assertTrue(8 <= w <= 256 and 8 <= h <= 256, (w, h))
                self.assertEqual((len(rows), len(rows[0])), (h, w))
                self.assertGreater(len({px for row in rows for px in row}), 2)
        # a speed limit: red ring, white disc, black digits
        w, h, rows = decode_png(os.path.join(SCENERY, "meshes", "sign_speed_50.png"))
        r, g, b = rows[h // 2][1]
        self.assertTrue(r > 150 and g < 60 and b < 60, (r, g, b))  # the ring at the edge
        r, g, b = rows[h // 2 + int(0.68 * h / 2)][w // 2]
        self.assertTrue(min(r, g, b) > 200, (r, g, b))  # white inside the ring
        self.assertTrue(any(max(px) < 60 for px in rows[h // 2]), "no black digit across the middle")


if __name__ == "__main__":
    unittest.main()
