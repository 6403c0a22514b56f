"""COCO-format ground truth from the world engine's camera datapacks (docs/perception.md).

`CocoWriter` collects frames (the camera image, its `::boxes`, `::instances` and `::depth`
datapacks) into a folder:

  images/<name>.jpg        the camera image
  depth/<name>.png         depth in millimetres, uint16 (0: nothing within range; 65535 cap)
  annotations.json         COCO: images, annotations, categories

Each annotation is one labelled model seen in the frame: `bbox` [x, y, w, h] (pixels, the
visible extent), `category_id`, `segmentation` (its visible pixels as COCO's uncompressed
RLE, column-major), `area` (visible pixels), `iscrowd` 0, and Convoy's own fields:
`instance` (the world's instance id), `model`, `class`, `visible_fraction`, `distance`,
`visibility`, `full_box`.
"""
import json
import os

import cv2
import numpy as np

# The world engine's fixed class set (engines/gazebo_grpc/world_description.cpp).
CLASSES = ["car", "truck", "bus", "pedestrian", "cyclist", "building", "tree", "shrub", "pole",
           "traffic_light", "sign", "barrier", "other"]


def rle_encode(mask):
    """COCO's uncompressed RLE of a boolean H x W mask: run lengths in column-major order,
    starting with a run of zeros."""
    flat = np.asarray(mask, dtype=bool).flatten(order="F")
    if flat.size == 0:
        return {"counts": [], "size": list(mask.shape)}
    change = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    edges = np.concatenate([[0], change, [flat.size]])
    counts = np.diff(edges).tolist()
    if flat[0]:
        counts = [0] + counts
    return {"counts": counts, "size": [int(mask.shape[0]), int(mask.shape[1])]}


def rle_decode(rle):
    """The boolean mask of an uncompressed RLE."""
    h, w = rle["size"]
    flat = np.zeros(h * w, dtype=bool)
    pos, value = 0, False
    for n in rle["counts"]:
        if value:
            flat[pos:pos + n] = True
        pos += n
        value = not value
    return flat.reshape((w, h)).T


class CocoWriter:
    def __init__(self, folder, classes=CLASSES, jpeg_quality=95, min_pixels=1):
        self.folder = folder
        self.classes = list(classes)
        self.jpeg_quality = jpeg_quality
        self.min_pixels = min_pixels
        os.makedirs(os.path.join(folder, "images"), exist_ok=True)
        os.makedirs(os.path.join(folder, "depth"), exist_ok=True)
        self.images, self.annotations = [], []

    def add(self, name, image_rgb, boxes, ids, depth=None, extra=None):
        """One frame: `image_rgb` H x W x 3 uint8; `boxes` the ::boxes datapack's list; `ids`
        the ::instances datapack's H x W id image; `depth` (metres, H x W) optional; `extra`
        fields for the image record (seed, weather...)."""
        h, w = image_rgb.shape[:2]
        image_id = len(self.images) + 1
        file_name = "images/%s.jpg" % name
        cv2.imwrite(os.path.join(self.folder, file_name), np.ascontiguousarray(image_rgb[:, :, ::-1]),
                    [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
        record = {"id": image_id, "file_name": file_name, "width": w, "height": h}
        if depth is not None:
            mm = np.clip(np.nan_to_num(np.asarray(depth, dtype=np.float64) * 1000.0, posinf=0.0),
                         0, 65535).astype(np.uint16)
            cv2.imwrite(os.path.join(self.folder, "depth", name + ".png"), mm)
            record["depth_file"] = "depth/%s.png" % name
        if extra:
            record.update(extra)
        self.images.append(record)
        ids = np.asarray(ids)
        for b in boxes:
            cls = b.get("class")
            if cls not in self.classes:
                continue
            mask = ids == b["instance"]
            area = int(mask.sum())
            if area < self.min_pixels:
                continue
            x0, y0, x1, y1 = b["x_min"], b["y_min"], b["x_max"], b["y_max"]
            self.annotations.append({
                "id": len(self.annotations) + 1, "image_id": image_id,
                "category_id": self.classes.index(cls) + 1,
                "bbox": [x0, y0, x1 - x0 + 1, y1 - y0 + 1], "area": area, "iscrowd": 0,
                "segmentation": rle_encode(mask),
                "instance": b["instance"], "model": b.get("model"), "class": cls,
                "visible_fraction": b.get("visible_fraction", 1.0),
                "distance": b.get("distance"), "visibility": b.get("visibility", 1.0),
                "full_box": b.get("full_box")})
        return image_id

    def write(self, info=None):
        doc = {"info": dict({"description": "Convoy renders with ground truth", "version": "1"},
                            **(info or {})),
               "images": self.images, "annotations": self.annotations,
               "categories": [{"id": i + 1, "name": c, "supercategory": "road"
                               if i < 5 else "scenery"} for i, c in enumerate(self.classes)]}
        with open(os.path.join(self.folder, "annotations.json"), "w") as f:
            json.dump(doc, f)
        return doc
