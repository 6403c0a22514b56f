"""A LiDAR scan seen from above, coloured by class (issue 27), and the run folder's copy of it.

    from convoy_sensors.birds_eye import RunFolderView
    view = RunFolderView("lidar")        # writes $CONVOY_RUN_DIR/lidar_lidar.png (and .npy)
    view.update(scan)                    # in a TF, with the PointCloud datapack

The picture: the sensor at the centre, x (forward) up, `metres` to each side; unlabelled
returns (the road, the ground) in grey by intensity, labelled ones over them in their class's
colour (the palette of benchmarks/lidar/birds_eye.cpp), weather returns light blue."""

import os

import numpy as np

from convoy_sensors.point_cloud import instances, points

CLASS_COLOURS = {  # RGB
    "car": (245, 90, 50), "truck": (200, 40, 160), "bus": (250, 200, 30),
    "pedestrian": (255, 30, 30), "cyclist": (255, 120, 200), "building": (60, 110, 250),
    "tree": (40, 200, 60), "shrub": (110, 230, 90), "pole": (230, 230, 120),
    "sign": (250, 250, 250), "traffic_light": (250, 150, 0), "barrier": (160, 120, 80),
    "other": (180, 100, 250)}
OTHER = (180, 100, 250)
WEATHER = (150, 200, 255)


def render(pts, classes_by_instance, size=800, metres=40.0):
    """An RGB image (size x size x 3, uint8) of the structured points `pts`."""
    img = np.zeros((size, size, 3), np.uint8)
    scale = size / (2.0 * metres)
    col = (size / 2 - pts["y"] * scale).astype(np.int64)  # left of the sensor: left in the image
    row = (size / 2 - pts["x"] * scale).astype(np.int64)  # ahead: up
    inside = (col >= 0) & (col < size - 2) & (row >= 0) & (row < size - 2)
    labelled = pts["instance"] != 0
    weather = (pts["flags"] & 1) != 0
    grey = np.clip(90 + 165 * pts["intensity"], 0, 255).astype(np.uint8)
    ground = inside & ~labelled & ~weather
    img[row[ground], col[ground]] = grey[ground, None]
    for pass_mask, dot in ((inside & weather, 1), (inside & labelled & ~weather, 2)):
        idx = np.nonzero(pass_mask)[0]
        colours = np.array([WEATHER if weather[i] else
                            CLASS_COLOURS.get(classes_by_instance.get(int(pts["instance"][i]), ""),
                                              OTHER) for i in idx], np.uint8).reshape(-1, 3)
        for dy in range(dot):
            for dx in range(dot):
                img[row[idx] + dy, col[idx] + dx] = colours
    c = size // 2
    img[c - 3:c + 4, c - 1:c + 2] = (255, 255, 0)  # the sensor
    return img


def legend(img, classes, title):
    """Writes `title` and a swatch per class of `classes` in the image's top-left corner."""
    import cv2
    cv2.putText(img, title, (8, 18), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1,
                cv2.LINE_AA)
    for k, cls in enumerate(sorted(classes)):
        y = 36 + 16 * k
        img[y - 9:y + 1, 8:18] = CLASS_COLOURS.get(cls, OTHER)
        cv2.putText(img, cls, (24, y), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1,
                    cv2.LINE_AA)
    return img


def write_png(path, rgb):
    """Writes an RGB image as PNG (OpenCV, which wants BGR)."""
    import cv2
    if not cv2.imwrite(path, np.ascontiguousarray(rgb[:, :, ::-1])):
        raise OSError("cannot write " + path)


class RunFolderView:
    """Keeps a sensor's bird's-eye PNG in the run folder: lidar_<name>.png of the latest scan
    (rewritten at most every `period` s of the scans' time), and lidar_<name>.npy, that scan's
    points as a numpy structured array (np.load)."""

    def __init__(self, name, period=1.0, size=800, metres=40.0, run_dir=None):
        self.name = name.replace("::", "_").replace("/", "_")
        self.period, self.size, self.metres = period, size, metres
        self.dir = run_dir or os.environ.get("CONVOY_RUN_DIR", ".")
        self.last_time = None
        self.scans = 0

    def png_path(self):
        return os.path.join(self.dir, "lidar_%s.png" % self.name)

    def update(self, datapack):
        """Call with each PointCloud datapack; returns True when it wrote the files."""
        if datapack is None or getattr(datapack, "isEmpty", lambda: False)():
            return False
        msg = datapack.data if hasattr(datapack, "data") else datapack
        t = getattr(msg, "time_ns", 0) * 1e-9
        if not msg.count:
            return False
        self.scans += 1
        if self.last_time is not None and t - self.last_time < self.period:
            return False
        self.last_time = t
        pts = points(msg)
        classes = {k: cls for k, (_, cls) in instances(msg).items()}
        img = render(pts, classes, self.size, self.metres)
        seen = {classes.get(int(i), "") for i in np.unique(pts["instance"]) if i} - {""}
        title = "%s  t = %.1f s  %d returns  +-%g m, forward up" % (
            getattr(msg, "frame", self.name), t, len(pts), self.metres)
        write_png(self.png_path(), legend(img, seen, title))
        np.save(os.path.join(self.dir, "lidar_%s.npy" % self.name), pts.copy())
        return True
