"""Every traffic light's stop line on a map, from the lane graph (`convoy-odr query`'s
stop_lines: any geometry the map uses), as experiments/city_traffic/city_map.StopLine objects:
the scenario run's functions (traffic_tf for the ego's planner, the live metrics for red
lights) use them."""

import os
import sys

from .odr import OdrQuery

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def stop_lines(xodr):
    sys.path.insert(0, os.path.join(REPO, "experiments", "city_traffic"))
    import city_map  # noqa: E402

    out = []
    with OdrQuery(xodr) as odr:
        for d in odr.ask(op="stop_lines")["stop_lines"]:
            line = city_map.StopLine(d["id"], d["road"], d["x"], d["y"], d["heading"], d["t_min"], d["t_max"])
            line.entry_x, line.entry_y = d["entry_x"], d["entry_y"]
            out.append(line)
    return out
