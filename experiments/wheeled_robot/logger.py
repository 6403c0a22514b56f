"""Logs the robot's trajectory to trajectory.csv in the run folder ($CONVOY_RUN_DIR), prints
progress and what the camera sees once per simulated second, and saves the last camera
frame as camera.png."""
import os
import struct
import zlib

from nrp_core.engines.python_json import EngineScript


def write_png(path, image):
    """Minimal PNG writer (8-bit RGB), so that no imaging library is needed."""
    h, w, _ = image.shape
    raw = b"".join(b"\x00" + image[row].tobytes() for row in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("pose")
        self.dir = os.environ.get("CONVOY_RUN_DIR", ".")
        self.out = open(os.path.join(self.dir, "trajectory.csv"), "w")
        self.out.write("time_s,x,y,speed\n")
        self.frame = None

    def runLoop(self, timestep_ns):
        pose = self._getDataPack("pose")
        if pose is None:
            return
        t = self._time_ns * 1e-9
        self.out.write("%.3f,%.6f,%.6f,%.6f\n" % (t, pose["x"], pose["y"], pose["speed"]))
        if "frame" in pose:
            self.frame = pose["frame"]
        if self._time_ns % 1_000_000_000 == 0:
            print("t=%4.1f s  x=%6.2f  y=%6.2f  speed=%.2f m/s  camera sees: %s" % (
                t, pose["x"], pose["y"], pose["speed"], ", ".join(pose.get("seen", [])) or "-"),
                flush=True)

    def shutdown(self):
        self.out.close()
        if self.frame is not None:
            write_png(os.path.join(self.dir, "camera.png"), self.frame)
