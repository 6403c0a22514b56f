"""tracks.csv of a scenario run: one row per entity per scenario step,
`t,entity,x,y,z,heading,speed,road,lane,s`, entities named as in the .xosc (the ego included),
in name order; heading in (-pi, pi]. Written by the scenario engine into the run folder ($CONVOY_RUN_DIR), a step's
rows at a time, so a run that ends early keeps the steps it made."""

import math
import os

HEADER = "t,entity,x,y,z,heading,speed,road,lane,s\n"


class TracksWriter:
    def __init__(self, path):
        self.f = open(path, "w")
        self.f.write(HEADER)

    @classmethod
    def in_run_dir(cls):
        run_dir = os.environ.get("CONVOY_RUN_DIR")
        return cls(os.path.join(run_dir, "tracks.csv")) if run_dir else None

    def step(self, t, world):
        """world: entity -> state dict (x, y, z, yaw, speed, and road, lane, s when known)."""
        rows = []
        for name in sorted(world):
            s = world[name]
            on_road = "road" in s
            rows.append("%.3f,%s,%.4f,%.4f,%.4f,%.6f,%.4f,%s,%s,%s\n" % (
                t, name, s["x"], s["y"], s.get("z", 0.0), math.atan2(math.sin(s["yaw"]), math.cos(s["yaw"])),
                s["speed"],
                s["road"] if on_road else "", s["lane"] if on_road else "",
                "%.4f" % s["s"] if on_road else ""))
        self.f.write("".join(rows))
        self.f.flush()

    def close(self):
        if not self.f.closed:
            self.f.close()
