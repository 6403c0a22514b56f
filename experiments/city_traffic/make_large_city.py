#!/usr/bin/python3
"""Writes large_city.xodr: a grid city for 1,000 pooled road users (issue 26), made with the
city map's generator (tools/opendrive/make_city.py: its roads, junctions, lights, crosswalks
and sidewalks), and, with --odr, the ego's route on it (ego_route_large.csv).

Layout (x east, y north, metres): N x N junctions (N = 4), SPACING m apart, junction (i, j) at
(i * SPACING, j * SPACING), id 100 + j * N + i. Every road has two driving lanes of 3.5 m a
direction and a 2.5 m sidewalk (the city's main-road cross-section), 50 km/h; arms of ARM m
run out of the outer junctions to the map's edges, where vehicles leave and enter. Roads run
west-east (rows) and south-north (columns), one road between two junctions:

    row j, piece i      road id 1 + j * (N + 1) + i      (piece 0: the west arm, N: the east)
    column i, piece j   road id 1 + N * (N + 1) + i * (N + 1) + j   (0: the south arm)
    roads 1000+         connecting roads inside the junctions

Each junction has all movements but U-turns, lights on every arm (rows: group 0, columns:
group 1) and crosswalks. 4 x 4 at 250 m: 30 km of driving lane outside the junctions.

Usage: /usr/bin/python3 make_large_city.py [--odr build/bin/convoy-odr]
Deterministic: the same script always writes the same bytes."""
import argparse
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tools", "opendrive"))
import make_city  # noqa: E402

N = 4            # junctions a side
SPACING = 250.0  # m between junction centres
ARM = 150.0      # m from an outer junction's centre to the map's edge
MAP = "large_city.xodr"
# The ego's route: along row 1 (y = SPACING) west to east, lane -1 (beside the centre line), straight
# through its N junctions; it starts EGO_START_S m along the west arm.
EGO_ROW = 1
EGO_START_S = 40.0
ROUTE_DS = 2.0


def row_road(j, i):
    return str(1 + j * (N + 1) + i)


def column_road(i, j):
    return str(1 + N * (N + 1) + i * (N + 1) + j)


def piece(rid, name, start, length):
    return make_city.Road(rid, name, start, [("line", length)], make_city.main_lanes(),
                          make_city.MAIN_KMH)


def build():
    half = make_city.HALF
    roads = []
    last = (N - 1) * SPACING
    for j in range(N):  # rows, west to east
        y = j * SPACING
        roads.append(piece(row_road(j, 0), "row %d west" % j, (-ARM, y, 0.0), ARM - half))
        for i in range(N - 1):
            roads.append(piece(row_road(j, i + 1), "row %d piece %d" % (j, i + 1),
                               (i * SPACING + half, y, 0.0), SPACING - 2 * half))
        roads.append(piece(row_road(j, N), "row %d east" % j, (last + half, y, 0.0),
                           ARM - half))
    for i in range(N):  # columns, south to north
        x = i * SPACING
        up = math.pi / 2
        roads.append(piece(column_road(i, 0), "column %d south" % i, (x, -ARM, up), ARM - half))
        for j in range(N - 1):
            roads.append(piece(column_road(i, j + 1), "column %d piece %d" % (i, j + 1),
                               (x, j * SPACING + half, up), SPACING - 2 * half))
        roads.append(piece(column_road(i, N), "column %d north" % i, (x, last + half, up),
                           ARM - half))
    junctions = []
    for j in range(N):
        for i in range(N):
            jid = str(100 + j * N + i)
            junctions.append((jid, [(row_road(j, i), True, 0), (row_road(j, i + 1), False, 0),
                                    (column_road(i, j + 1), False, 1),
                                    (column_road(i, j), True, 1)]))
    return make_city.connect(roads, junctions)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--odr", help="convoy-odr binary: also write ego_route_large.csv")
    args = ap.parse_args()
    path = os.path.join(HERE, MAP)
    n_roads, n_junctions = make_city.write(path, build(), "large_city")
    print("%s: %d roads, %d junctions" % (path, n_roads, n_junctions))
    if args.odr:
        subprocess.run([args.odr, "route", path, "--from", "%s:-1" % row_road(EGO_ROW, 0),
                        "--to", "%s:-1" % row_road(EGO_ROW, N), "--ds", str(ROUTE_DS),
                        "--no-lane-changes", "1", "--out",
                        os.path.join(HERE, "ego_route_large.csv")],
                       check=True, stdout=subprocess.DEVNULL)


if __name__ == "__main__":
    main()
