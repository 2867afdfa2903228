#!/usr/bin/env python3
"""Write the Truth Cube's mesh, plate trajectory and measured data for scenarios/truth_cube.json.

The Truth Cube (Kerdok, Cotin, Ottensmeyer, Galea, Howe and Dawson, Medical Image Analysis
7(3), 2003): a silicone cube about 80 mm on a side, 343 Teflon beads on a 7 x 7 x 7 grid about
10 mm apart, CT-scanned uncompressed and under uniaxial compression between two plates at 5%,
12.5% and 18.25% nominal strain. `../shared/data/truth-cube/uniaxial_positions.csv` holds the
beads' positions in each scan (mm; SOURCE.md there). The compression is along z, and the
data's -z points up: the top plate is the face of lowest z and moves towards +z.

This script writes, beside itself:

  truth_cube.msh          the cube as linear tetrahedra (Gmsh 2.2, metres): N x N x N hexahedra
                          (N = 8 by default: 10 mm), each split into 6 tetrahedra along its
                          main diagonal (Freudenthal's split, conforming between neighbours).
                          The cube is centred on the beads' rest centroid, 80 mm on a side.
                          `--divisions N` for another resolution (the mesh-convergence check
                          writes truth_cube_16.msh with N = 16).
  truth_cube_trajectory.csv  the top plate (the scenario's SO) over time: a slow compression
                          in three stages, each a 1 s ramp (quintic: no jerk at its ends) and
                          a 1 s hold, to the nominal strains times the cube's 80 mm
                          (4.0, 10.0 and 14.6 mm); the scans are taken at the holds' ends,
                          t = 2, 4 and 6 s, the rest state at t = 0.
  truth_cube_data/observations.csv  the measured data in sigmafem's format (docs/FORMATS.md):
                          one row per step of 0.01 s, the SO's position, the 343 beads (m) at
                          the four scan times and empty (not observed) in every other row.

The beads are the scenario's `observations.points` at their rest (uncompressed) positions:
each is observed as the material point of the tetrahedron that holds it (FORMATS.md).

Python 3 standard library only; the output is the same bytes on every run:

    python3 scenarios/make_truth_cube.py [--data PATH_TO_uniaxial_positions.csv] [--divisions N]
"""

import argparse
import itertools
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_DATA = os.path.join(HERE, "..", "..", "shared", "data", "truth-cube", "uniaxial_positions.csv")

SIDE = 0.080                      # m, the cube's side
STRAINS = [0.05, 0.125, 0.1825]   # nominal, of the side
DT = 0.01                         # s, the scenario's step
RAMP, HOLD = 1.0, 1.0             # s, each stage
SCAN_TIMES = [0.0] + [(k + 1) * (RAMP + HOLD) for k in range(len(STRAINS))]


def read_beads(path):
    """The beads' (i, j, k) and positions (m) in the four scans, in file order."""
    beads = []
    with open(path) as f:
        lines = f.read().splitlines()
    for line in lines[7:]:
        fields = line.split(",")
        if not fields or not fields[0].strip():
            continue
        numbers = [float(x) for x in fields[:15]]
        ijk = tuple(int(x) for x in numbers[:3])
        scans = [[1e-3 * numbers[3 + 3 * s + a] for a in range(3)] for s in range(4)]
        beads.append((ijk, scans))
    if len(beads) != 343:
        raise SystemExit(f"{path}: expected 343 beads, found {len(beads)}")
    return beads


def cube_mesh(centre, divisions):
    """Nodes (x, y, z) and tetrahedra (0-based node indices, positive volume)."""
    n = divisions
    h = SIDE / n
    lower = [c - SIDE / 2 for c in centre]
    index = {}
    nodes = []
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                index[(i, j, k)] = len(nodes)
                nodes.append((lower[0] + i * h, lower[1] + j * h, lower[2] + k * h))
    tets = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                for order in itertools.permutations(range(3)):
                    corner = [0, 0, 0]
                    path = [tuple(corner)]
                    for axis in order:
                        corner[axis] = 1
                        path.append(tuple(corner))
                    tet = [index[(i + a, j + b, k + c)] for (a, b, c) in path]
                    if volume(nodes, tet) < 0:
                        tet[2], tet[3] = tet[3], tet[2]
                    tets.append(tet)
    return nodes, tets


def volume(nodes, tet):
    a, b, c, d = (nodes[v] for v in tet)
    u = [b[x] - a[x] for x in range(3)]
    v = [c[x] - a[x] for x in range(3)]
    w = [d[x] - a[x] for x in range(3)]
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
            u[2] * (v[0] * w[1] - v[1] * w[0])) / 6.0


def write_msh(path, nodes, tets):
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write('$PhysicalNames\n1\n3 1 "truth_cube"\n$EndPhysicalNames\n')
        f.write(f"$Nodes\n{len(nodes)}\n")
        for i, (x, y, z) in enumerate(nodes):
            f.write(f"{i + 1} {x:.9g} {y:.9g} {z:.9g}\n")
        f.write(f"$EndNodes\n$Elements\n{len(tets)}\n")
        for e, tet in enumerate(tets):
            f.write(f"{e + 1} 4 2 1 1 {' '.join(str(v + 1) for v in tet)}\n")
        f.write("$EndElements\n")


def quintic(u):
    return 10 * u ** 3 - 15 * u ** 4 + 6 * u ** 5


def plate_displacement(t):
    """The top plate's displacement (m, towards +z) at time t."""
    previous = 0.0
    for k, strain in enumerate(STRAINS):
        start = k * (RAMP + HOLD)
        target = strain * SIDE
        if t < start + RAMP:
            return previous + (target - previous) * quintic(max(0.0, (t - start) / RAMP))
        if t <= start + RAMP + HOLD:
            return target
        previous = target
    return previous


def write_scenario(centre, rest_beads, steps):
    """truth_cube.json: the cube between its plates, the beads observed at their rest positions."""
    bottom = centre[2] + SIDE / 2   # the bottom plate's face (the data's +z is down)
    top = centre[2] - SIDE / 2
    margin = 1e-4                   # m: the face's nodes, not the next layer (10 mm in)
    half = SIDE / 2 + margin
    face = lambda z: {"box": {"min": [round(centre[0] - half, 6), round(centre[1] - half, 6), round(z - margin, 6)],
                              "max": [round(centre[0] + half, 6), round(centre[1] + half, 6), round(z + margin, 6)]}}
    scenario = {
        "format": "sigmafem-scenario/1",
        "name": "truth_cube",
        "description": (
            "The Truth Cube (Kerdok et al. 2003; ../shared/data/truth-cube): an 80 mm silicone cube compressed "
            "between two plates along z (the data's -z is up) to 5, 12.5 and 18.25% nominal strain, 343 beads "
            "located by CT in each scan. The bottom plate holds the face z = max by stiff springs (bonded), the top "
            "plate (the SO) grips the face z = min and moves it down in three 1 s ramps, each held 1 s; the scans "
            "are the holds' ends (t = 2, 4, 6 s). Written by scenarios/make_truth_cube.py; the measured data are "
            "truth_cube_data/observations.csv. Material: E = 15.3 kPa (OpenSurgSim's value for this cube), "
            "nu = 0.45 (the seed paper's soft tissue; diagnose estimates it from the beads: README, \"The Truth "
            "Cube\"), polar element rotations (at 18% strain the QR frame is not at rest near nu = 0.5)."),
        "mesh": {"file": "truth_cube.msh", "scale": 1.0, "translate": [0.0, 0.0, 0.0]},
        "material": {"young_modulus": 15300.0, "poisson_ratio": 0.45, "density": 1000.0, "rotation": "polar"},
        "damping": {"rayleigh_stiffness": 0.05, "rayleigh_mass": 1.0},
        "gravity": [0.0, 0.0, 0.0],
        "time": {"dt": DT, "steps": steps},
        "solver": {"cg_max_iterations": 2000, "cg_tolerance": 1e-10},
        # Plates bonded to the faces and rigid next to the cube: 1e6 N/m over the 81 nodes of a
        # face against the cube's axial stiffness E A / L of about 1.2e3 N/m (with 1e5 the
        # plates' give let the beads feel the modulus a little: README, "The Truth Cube").
        "ligaments": [{"name": "bottom_plate", "select": face(bottom), "stiffness": 1.0e6}],
        "control": {"select": face(top), "stiffness": 1.0e6,
                    "trajectory": {"type": "file", "file": "truth_cube_trajectory.csv"}},
        "observations": {"points": [[round(x, 6) for x in p] for p in rest_beads], "noise_std": 0.0003},
        "filter": {"estimate": ["bottom_plate"], "initial_stiffness": [1.0e6], "initial_log_std": 1.0,
                   "parameter_drift_log_std": 0.0, "observation_std": 0.0003, "sigma_points": "star"},
        "output": {"vtk_every": 50},
    }
    with open(os.path.join(HERE, "truth_cube.json"), "w") as f:
        json.dump(scenario, f, indent=1)
        f.write("\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default=DEFAULT_DATA)
    parser.add_argument("--divisions", type=int, default=8)
    args = parser.parse_args()

    beads = read_beads(args.data)
    centre = [sum(b[1][0][a] for b in beads) / len(beads) for a in range(3)]
    nodes, tets = cube_mesh(centre, args.divisions)
    suffix = "" if args.divisions == 8 else f"_{args.divisions}"
    write_msh(os.path.join(HERE, f"truth_cube{suffix}.msh"), nodes, tets)
    if suffix:
        return

    # The SO starts at the centroid of the control nodes (the top face, z lowest): the
    # centre of that face, as the mesh is regular.
    top = [centre[0], centre[1], centre[2] - SIDE / 2]
    steps = int(round(SCAN_TIMES[-1] / DT))
    with open(os.path.join(HERE, "truth_cube_trajectory.csv"), "w") as f:
        f.write("time,x,y,z\n")
        for s in range(steps + 1):
            t = s * DT
            f.write(f"{t:.2f},{top[0]:.6f},{top[1]:.6f},{top[2] + plate_displacement(t):.6f}\n")

    data_dir = os.path.join(HERE, "truth_cube_data")
    os.makedirs(data_dir, exist_ok=True)
    scan_steps = {int(round(t / DT)): s for s, t in enumerate(SCAN_TIMES)}
    with open(os.path.join(data_dir, "observations.csv"), "w") as f:
        f.write("# The Truth Cube's beads (Kerdok et al. 2003), measured by CT at 0, 5, 12.5 and 18.25% nominal\n")
        f.write("# strain, from ../shared/data/truth-cube/uniaxial_positions.csv (OpenSurgSim, Apache License 2.0),\n")
        f.write("# in metres; written by scenarios/make_truth_cube.py. Rows between scans are not observed.\n")
        header = ["step", "time", "so_x", "so_y", "so_z"]
        for p in range(len(beads)):
            header += [f"p{p}_x", f"p{p}_y", f"p{p}_z"]
        f.write(",".join(header) + "\n")
        for s in range(steps + 1):
            t = s * DT
            row = [str(s), f"{t:.2f}", f"{top[0]:.6f}", f"{top[1]:.6f}", f"{top[2] + plate_displacement(t):.6f}"]
            scan = scan_steps.get(s)
            for _, scans in beads:
                row += [f"{x:.5f}" for x in scans[scan]] if scan is not None else ["", "", ""]
            f.write(",".join(row) + "\n")

    write_scenario(centre, [scans[0] for _, scans in beads], steps)
    print(f"centre {centre}, top face z {top[2]:.5f}, {len(nodes)} nodes, {len(tets)} tetrahedra, {steps} steps")


if __name__ == "__main__":
    main()
