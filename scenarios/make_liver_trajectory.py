#!/usr/bin/env python3
"""Write liver_trajectory.csv, the solid object (SO) path of scenarios/liver.json.

The seed paper (section 3.2) moves the SO with an Omni haptic device held by hand. This
script makes a deterministic stand-in for such a record: a smooth 3D motion that

  * starts exactly at so(0), the centroid of the control nodes' rest positions in metres
    (docs/FORMATS.md: file trajectories hold absolute SO positions), with zero velocity:
    the motion is multiplied by a quintic ramp e(t) = 10u^3 - 15u^4 + 6u^5, u = t / 2 s,
    whose value and first two derivatives are 0 at t = 0, so the hand eases in;
  * pulls the anterior inferior edge 1.3 cm down and forward, away from the ligaments on
    the upper posterior ridge, so that the ligaments stay loaded for the whole run;
  * wanders around that offset with two sinusoids per axis, of periods 2.7 s to 9.3 s that
    are not multiples of each other, so the direction of motion keeps changing as a hand's
    would (none of the periods is near the model's fast dynamics);
  * reaches about 2.5 cm from so(0) at most, at speeds of a few cm/s.

so(t) = so(0) + e(t) * (lift + sum_k a_k sin(2 pi t / T_k + phi_k)), per axis.

The run length and sampling come from liver.json (time.steps x time.dt: 2000 x 0.01 s =
20 s, one row per step, 2001 rows with t = 0). Times are printed with 2 decimals and
positions with 6 (1 micrometre, far below the 0.5 mm observation noise).

so(0) is computed here, not copied: the script reads liver.json (mesh file, scale,
translate, control node set: `nodes`, or `select` with near + radius or box, the same
inclusive rule as the loader) and the Gmsh mesh (the `$NOD` section of format 1.0, or
`$Nodes` of 2.2: lines `id x y z`, nodes indexed 0-based in file order). Editing the
control nodes or the mesh transform in liver.json therefore only needs a re-run:

    python3 scenarios/make_liver_trajectory.py

Python 3 standard library only; the output is the same bytes on every run.
"""

import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIO = os.path.join(HERE, "liver.json")
OUTPUT = os.path.join(HERE, "liver_trajectory.csv")

SELECTION_SLACK = 1e-9  # m, as kSelectionSlack in host/scenario/scenario.h

RAMP_SECONDS = 2.0
# Down (-y) and forward (+z): away from the ligaments (upper posterior, y+ z-) as seen
# from the SO on the anterior inferior edge.
LIFT = (0.0, -0.008, 0.010)
# (amplitude m, period s, phase rad) per axis.
WAVES = (
    ((0.008, 7.7, 0.0), (0.003, 3.1, 1.3)),  # x
    ((0.006, 9.3, 0.7), (0.003, 4.3, 2.1)),  # y
    ((0.006, 6.1, 1.9), (0.002, 2.7, 0.4)),  # z
)


def read_gmsh_nodes(path):
    """Node positions in file order from a Gmsh 1.0 ($NOD) or 2.2 ($Nodes) ASCII file."""
    with open(path) as f:
        lines = f.read().splitlines()
    for i, line in enumerate(lines):
        if line.strip() in ("$NOD", "$Nodes"):
            count = int(lines[i + 1])
            nodes = []
            for row in lines[i + 2 : i + 2 + count]:
                fields = row.split()
                nodes.append(tuple(float(v) for v in fields[1:4]))
            return nodes
    raise SystemExit(f"{path}: no $NOD or $Nodes section")


def control_nodes(control, nodes):
    """The control node indices, resolved as load_scenario resolves them."""
    if "nodes" in control:
        return sorted(control["nodes"])
    select = control["select"]
    if "box" in select:
        lo, hi = select["box"]["min"], select["box"]["max"]
        return [i for i, p in enumerate(nodes)
                if all(lo[k] - SELECTION_SLACK <= p[k] <= hi[k] + SELECTION_SLACK for k in range(3))]
    near, radius = select["near"], select["radius"]
    return [i for i, p in enumerate(nodes) if math.dist(p, near) <= radius + SELECTION_SLACK]


def ramp(t):
    u = min(max(t / RAMP_SECONDS, 0.0), 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def offset(t):
    e = ramp(t)
    return tuple(
        e * (LIFT[axis] + sum(a * math.sin(2.0 * math.pi * t / period + phase)
                              for a, period, phase in WAVES[axis]))
        for axis in range(3))


def main():
    with open(SCENARIO) as f:
        scenario = json.load(f)
    mesh = scenario["mesh"]
    scale = mesh.get("scale", 1.0)
    translate = mesh.get("translate", [0.0, 0.0, 0.0])
    raw = read_gmsh_nodes(os.path.join(HERE, mesh["file"]))
    nodes = [tuple(scale * p[k] + translate[k] for k in range(3)) for p in raw]
    chosen = control_nodes(scenario["control"], nodes)
    if not chosen:
        raise SystemExit("liver.json: the control node set is empty")
    start = tuple(sum(nodes[i][k] for i in chosen) / len(chosen) for k in range(3))

    dt = scenario["time"]["dt"]
    steps = scenario["time"]["steps"]
    rows = ["time,x,y,z"]
    reach = 0.0
    for step in range(steps + 1):
        t = step * dt
        d = offset(t)
        reach = max(reach, math.sqrt(sum(v * v for v in d)))
        rows.append(f"{t:.2f},{start[0] + d[0]:.6f},{start[1] + d[1]:.6f},{start[2] + d[2]:.6f}")
    with open(OUTPUT, "w", newline="\n") as f:
        f.write("\n".join(rows) + "\n")
    print(f"wrote {OUTPUT}: {steps + 1} rows over {steps * dt:g} s; control nodes {chosen}, "
          f"so(0) = ({start[0]:.6f}, {start[1]:.6f}, {start[2]:.6f}) m, "
          f"largest distance from so(0) {100 * reach:.2f} cm")


if __name__ == "__main__":
    main()
