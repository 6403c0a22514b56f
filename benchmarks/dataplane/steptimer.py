"""Times an engine's runLoop calls and writes timing_<engine>.json (next to this file, or
in `outdir`)."""
import json
import os
import time


class StepTimer:
    def __init__(self, name, outdir=None):
        self.name = name
        self.outdir = outdir or os.path.dirname(os.path.abspath(__file__))
        self.stamps = []

    def tick(self):
        self.stamps.append(time.perf_counter())

    def dump(self, **extra):
        st = self.stamps
        res = {"engine": self.name, "n_calls": len(st)}
        if len(st) >= 3:
            res["steps_per_s"] = (len(st) - 2) / (st[-1] - st[1])  # first interval is warm-up
        res.update(extra)
        with open(os.path.join(self.outdir, "timing_%s.json" % self.name), "w") as f:
            json.dump(res, f, indent=1)
