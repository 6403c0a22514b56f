"""A LiDAR scan (convoy.data.PointCloud, proto/convoy/point_cloud.proto) as numpy.

    from convoy_sensors.point_cloud import points, instances

    @EngineDataPack(keyword="scan", id=DataPackIdentifier("car::lidar_link::lidar", "gazebo"))
    @TransceiverFunction("agent")
    def tf(scan):
        p = points(scan)                    # structured array, one row per return
        near = p[np.hypot(p["x"], p["y"]) < 10]
        cars = [i for i, (model, cls) in instances(scan).items() if cls == "car"]

The array is a view of the message's bytes (np.frombuffer: no copy, read-only): copy it
(p.copy()) to change it or to keep it beyond the call. Fields (32 bytes a point): x, y, z
(float32, metres, the sensor's frame), intensity (float32, 0-1), instance (uint32, the
model's ground-truth id, 0: none), label (uint32, its class id), ring, column (uint16),
flags (uint32, 1: a return from rain, snow or fog)."""

import numpy as np

POINT_STEP = 32
# The record of src/lidar/point_cloud.h, as the datapack's `fields` describe it.
DTYPE = np.dtype({
    "names": ["x", "y", "z", "intensity", "instance", "label", "ring", "column", "flags"],
    "formats": ["<f4", "<f4", "<f4", "<f4", "<u4", "<u4", "<u2", "<u2", "<u4"],
    "offsets": [0, 4, 8, 12, 16, 20, 24, 26, 28],
    "itemsize": POINT_STEP,
})


def _message(datapack_or_message):
    """The PointCloud message of a datapack (its .data) or the message itself."""
    m = datapack_or_message
    if not hasattr(m, "points") and hasattr(m, "data"):
        m = m.data
    if not hasattr(m, "points"):
        raise TypeError("not a PointCloud datapack or message: %r" % type(datapack_or_message))
    return m


def dtype_of(message):
    """The record's dtype from the message's fields and point_step (DTYPE when it has none)."""
    fields = list(getattr(message, "fields", []) or [])
    step = getattr(message, "point_step", 0) or POINT_STEP
    if not fields:
        return DTYPE
    return np.dtype({"names": [f.name for f in fields], "formats": [f.dtype for f in fields],
                     "offsets": [f.offset for f in fields], "itemsize": step})


def points(datapack_or_message):
    """The returns as a numpy structured array (a read-only view of the message's bytes)."""
    m = _message(datapack_or_message)
    dt = dtype_of(m)
    raw = m.points
    if len(raw) % dt.itemsize:
        raise ValueError("PointCloud: %d bytes of points is not a whole number of %d-byte records"
                         % (len(raw), dt.itemsize))
    return np.frombuffer(raw, dtype=dt)


def instances(datapack_or_message):
    """Ground truth: {instance id: (model name, class)} for the ids in the points."""
    m = _message(datapack_or_message)
    return {int(k): (v.model, v.class_name) for k, v in m.instances.items()}


def xyz(datapack_or_message):
    """The points' x, y, z as an N x 3 float32 array (a copy)."""
    p = points(datapack_or_message)
    return np.stack([p["x"], p["y"], p["z"]], axis=1)
