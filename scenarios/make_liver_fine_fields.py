#!/usr/bin/env python3
"""Writes scenarios/liver_fine_fields.json (issue 19: p = 32 on the 38k liver, over MPI ranks).

liver_inclusion.json's set-up (the 140 boundary-surface nodes of liver.msh observed), with
liver.json's 0.5 mm noise and no gravity, on liver_fine.json's mesh (liver.msh refined twice: 38144 tetrahedra) with
29 regions instead of 8: the boxes of a 5 x 5 x 2 grid over the liver's rest bounding box that
hold the most of liver.msh's tetrahedra centroids (29 of the 35 that hold any), each with its own
Young's modulus estimated (p = 3 ligaments + 29 moduli = 32, 33 simplex sigma points); the
truth has 5x the tissue's modulus in one of them. 10 steps: a run to time, not to converge.

    python3 scenarios/make_liver_fine_fields.py
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
GRID = (5, 5, 2)
REGIONS = 29


def coarse_centroids(mesh, scale, translate):
    lines = open(mesh).read().split('\n')
    start = next(i for i, l in enumerate(lines) if l.strip() in ('$NOD', '$Nodes'))
    nodes = {}
    for line in lines[start + 2:start + 2 + int(lines[start + 1])]:
        f = line.split()
        nodes[int(f[0])] = [float(f[1 + j]) * scale + translate[j] for j in range(3)]
    start = next(i for i, l in enumerate(lines) if l.strip() in ('$ELM', '$Elements'))
    centroids = []
    for line in lines[start + 2:start + 2 + int(lines[start + 1])]:
        f = [int(x) for x in line.split()]
        if f[1] != 4:   # Gmsh 1.0: number, type (4: tetrahedron), reg-phys, reg-elem, count, nodes
            continue
        corners = [nodes[n] for n in f[-4:]]
        centroids.append([sum(c[j] for c in corners) / 4 for j in range(3)])
    return nodes, centroids


def main():
    base = json.load(open(os.path.join(HERE, 'liver_inclusion.json')))
    fine = json.load(open(os.path.join(HERE, 'liver_fine.json')))
    mesh = base['mesh']
    nodes, centroids = coarse_centroids(os.path.join(HERE, mesh['file']), mesh['scale'], mesh['translate'])
    low = [min(p[j] for p in nodes.values()) - 1e-4 for j in range(3)]
    high = [max(p[j] for p in nodes.values()) + 1e-4 for j in range(3)]
    size = [(high[j] - low[j]) / GRID[j] for j in range(3)]
    boxes = []
    for i in range(GRID[0]):
        for k in range(GRID[1]):
            for m in range(GRID[2]):
                index = (i, k, m)
                lo = [low[j] + index[j] * size[j] for j in range(3)]
                hi = [lo[j] + size[j] for j in range(3)]
                count = sum(all(lo[j] <= c[j] < hi[j] for j in range(3)) for c in centroids)
                boxes.append((count, f'x{i}y{k}z{m}', lo, hi))
    chosen = sorted(sorted(boxes, reverse=True)[:REGIONS], key=lambda b: b[1])
    # The inclusion: the anterior box (z1, under the observed face) with the most tetrahedra.
    inclusion = max((b for b in chosen if b[1].endswith('z1')), key=lambda b: b[0])[1]
    regions = []
    for count, name, lo, hi in chosen:
        region = {'name': name, 'select': {'box': {'min': [round(v, 6) for v in lo], 'max': [round(v, 6) for v in hi]}}}
        if name == inclusion:
            region['young_modulus'] = 5 * base['material']['young_modulus']
        regions.append(region)
    assert any(r['name'] == inclusion for r in regions)
    spec = dict(base)
    spec['name'] = 'liver_fine_fields'
    spec['description'] = (
        "Issue 19: p = 32 on the 38k liver, to run over MPI ranks (README, \"Over MPI ranks\"). "
        "liver_inclusion.json's set-up (the 140 boundary-surface nodes observed) with liver.json's 0.5 mm noise and no gravity, on "
        "liver_fine.json's mesh (liver.msh refined twice, 38144 tetrahedra; the SO on its three nodes) with 29 "
        "regions: the boxes of a 5 x 5 x 2 grid over the rest bounding box that hold the most of liver.msh's "
        "tetrahedra (made by make_liver_fine_fields.py); the 6 smallest boxes' tetrahedra keep the tissue's modulus. The truth has 25 kPa in " + inclusion + ", 5 kPa elsewhere; "
        "the filter estimates the 29 moduli from 5 kPa each and the 3 ligaments (33 simplex sigma points). "
        "10 steps (0.1 s): a run to time, not to converge.")
    spec['mesh'] = fine['mesh']
    spec['control'] = fine['control']
    spec['solver'] = fine['solver']
    spec['time'] = {'dt': base['time']['dt'], 'steps': 10}
    # liver.json's noise (0.5 mm) and no gravity, as sigmafem_mpi_bench's 38k case.
    spec['gravity'] = [0.0, 0.0, 0.0]
    spec['observations'] = dict(base['observations'], nodes=list(range(140)), noise_std=0.0005)
    spec['regions'] = regions
    spec['filter'] = dict(base['filter'], observation_std=0.0005,
                          estimate_young_modulus=[r['name'] for r in regions],
                          initial_young_modulus=[base['material']['young_modulus']] * len(regions))
    spec['output'] = {'vtk_every': 0}
    with open(os.path.join(HERE, 'liver_fine_fields.json'), 'w') as out:
        json.dump(spec, out, indent=2)
        out.write('\n')
    print(f'{len(regions)} regions, {sum(b[0] for b in chosen)} of {len(centroids)} coarse tetrahedra in them')


if __name__ == '__main__':
    main()
