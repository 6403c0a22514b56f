"""Tracks of LiDAR cluster boxes (convoy_sensors.clusters) across scans, in the world frame.

    tracker = ClusterTracker()
    tracks = tracker.update(boxes, t, ego)   # ego: dict x, y, yaw (the ego's pose at the scan)

Each box's centre goes into the world frame by the ego's pose; tracks are predicted to the
scan's time at their velocity and matched to boxes greedily, the closest pair first (ties by
track id, then box order: deterministic), within `gate` m. A matched track takes the box's
centre and size; its velocity is the centre's displacement over the time since its last hit,
filtered (`alpha`, from 0: a first difference may pair two different clusters), at most
MAX_SPEED. A track is confirmed after
`confirm` hits; one not matched coasts at its velocity for `coast` scans, then is dropped.
Once a vehicle (two hits as "car" or "truck"), a track stays one: the box of a car changes
shape as it drives past (its front, then its side), it stays a car. Track ids are "lidar<n>",
n counting up from 0.

The velocity reported (confirmed()) is, per world axis, the filtered one where it agrees in
sign with the robust rate of the track's last `history` centres (Theil-Sen,
convoy_sensors.confirm), the smaller in magnitude, else 0: a standing hedge or house corner
whose cluster grows and shrinks as the ego drives by jumps, it does not move."""

import math

from convoy_sensors.confirm import agreed, theil_sen

MAX_SPEED = 40.0  # m/s
VEHICLES = ("car", "truck")


class ClusterTracker:
    def __init__(self, gate=3.0, alpha=0.4, confirm=2, coast=3, history=10):
        self.gate, self.alpha, self.confirm, self.coast = float(gate), float(alpha), int(confirm), int(coast)
        self.history = int(history)
        self.tracks = []   # dicts: id, x, y, vx, vy, t, hits, misses, class, vehicle_hits, box
        self.next_id = 0

    def _predicted(self, tr, t):
        dt = t - tr["t"]
        return tr["x"] + tr["vx"] * dt, tr["y"] + tr["vy"] * dt

    def update(self, boxes, t, ego):
        """Matches the scan's boxes (ego frame) at time t (s) with the ego at `ego`; returns
        the confirmed tracks seen in the last `coast` scans (see tracks())."""
        c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        cents = []
        for b in boxes:
            bx, by = (b["x0"] + b["x1"]) / 2.0, (b["y0"] + b["y1"]) / 2.0
            cents.append((ego["x"] + c * bx - s * by, ego["y"] + s * bx + c * by))
        pairs = []
        for i, tr in enumerate(self.tracks):
            px, py = self._predicted(tr, t)
            for j, (wx, wy) in enumerate(cents):
                d = math.hypot(wx - px, wy - py)
                if d < self.gate:
                    pairs.append((d, i, j))
        pairs.sort()
        used_t, used_b = set(), set()
        for _, i, j in pairs:
            if i in used_t or j in used_b:
                continue
            used_t.add(i)
            used_b.add(j)
            self._hit(self.tracks[i], boxes[j], cents[j], t)
        kept = []
        for i, tr in enumerate(self.tracks):
            if i not in used_t:
                tr["misses"] += 1
            if tr["misses"] <= self.coast:
                kept.append(tr)
        for j, b in enumerate(boxes):
            if j not in used_b:
                kept.append(self._new(b, cents[j], t))
        self.tracks = kept
        return self.confirmed(t)

    def _new(self, box, cent, t):
        tr = {"id": "lidar%d" % self.next_id, "x": cent[0], "y": cent[1], "vx": 0.0, "vy": 0.0,
              "t": t, "hits": 1, "misses": 0, "class": box["class"], "box": box,
              "vehicle_hits": 1 if box["class"] in VEHICLES else 0, "moved": False,
              "hist": [(t, cent[0], cent[1])]}
        self.next_id += 1
        return tr

    def _hit(self, tr, box, cent, t):
        dt = t - tr["t"]
        if dt > 1e-6:
            vx, vy = (cent[0] - tr["x"]) / dt, (cent[1] - tr["y"]) / dt
            sp = math.hypot(vx, vy)
            if sp > MAX_SPEED:
                vx, vy = vx * MAX_SPEED / sp, vy * MAX_SPEED / sp
            tr["vx"] += self.alpha * (vx - tr["vx"])
            tr["vy"] += self.alpha * (vy - tr["vy"])
            tr["moved"] = True
        tr["x"], tr["y"], tr["t"] = cent[0], cent[1], t
        tr["hist"] = (tr["hist"] + [(t, cent[0], cent[1])])[-self.history:]
        tr["hits"] += 1
        tr["misses"] = 0
        tr["box"] = box
        if box["class"] in VEHICLES:
            tr["vehicle_hits"] += 1
        if tr["vehicle_hits"] >= 2 and box["class"] not in VEHICLES:
            return   # once a vehicle, stays one (module docstring)
        tr["class"] = box["class"]

    def confirmed(self, t):
        """The confirmed tracks (hits >= confirm, velocity known) at time t: dicts id, class, x,
        y (world, predicted to t), vx, vy, length and width (the last box's extent along and
        across the ego's axes then), points, misses, hits."""
        out = []
        for tr in self.tracks:
            if tr["hits"] < self.confirm or not tr["moved"]:
                continue
            ts = [h[0] for h in tr["hist"]]
            vx = agreed(tr["vx"], theil_sen(ts, [h[1] for h in tr["hist"]]))
            vy = agreed(tr["vy"], theil_sen(ts, [h[2] for h in tr["hist"]]))
            dt = t - tr["t"]
            x, y = tr["x"] + vx * dt, tr["y"] + vy * dt
            b = tr["box"]
            out.append({"id": tr["id"], "class": tr["class"], "x": x, "y": y, "vx": vx,
                        "vy": vy, "length": b["x1"] - b["x0"], "width": b["y1"] - b["y0"],
                        "points": b["points"], "misses": tr["misses"], "hits": tr["hits"]})
        return sorted(out, key=lambda o: int(o["id"][5:]))
