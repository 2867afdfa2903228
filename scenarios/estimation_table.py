#!/usr/bin/env python3
"""The estimation figures over seeds (README, "Estimation results"; issue 16).

For each scenario and seed: `generate` with that seed (the scenario's noise, or --noise-std),
`estimate` on it, then per phase (split where the truth changes) the mean over the ligaments
of |estimate - truth| / truth over the phase's last 20% of steps (in %), the mean absolute
error (N/m), the share of those steps and ligaments with the truth inside estimate +- 2 std,
the steps until the cut was followed (summary.json), and over the whole run the smallest and
largest ratio estimate / truth of a ligament whose truth is above 1 N/m (an uncut one).

    python3 scenarios/estimation_table.py build/sigmafem OUT scenarios/box.json scenarios/liver.json \
        --seeds 1,2,3,4,5 [--noise-std 0] [--observation-std 1e-4] [--backend cpu] \
        [--truth-stiffness 90,420,260] [--truth-refine 1]

--truth-stiffness sets the true ligament stiffnesses (N/m, in the scenario's ligament order) in
a copy of the scenario written to OUT, the filter's prior unchanged: data the scenario was not
tuned on. --truth-refine is passed to `generate` (the truth on a finer mesh).
"""
import argparse
import concurrent.futures
import csv
import json
import os
import subprocess

from scenario_copy import relocatable_scenario


def rows_of(path):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith('#')]
    return rows[0], rows[1:]


def figures(data, estimate):
    header, rows = rows_of(os.path.join(estimate, 'estimates.csv'))
    truth_header, truth_rows = rows_of(os.path.join(data, 'truth.csv'))
    truth = {int(r[0]): r for r in truth_rows}
    names = [n for n in header[2:] if n + '_std' in header]
    def t(step, name): return float(truth[step][truth_header.index(name)])
    steps = [int(r[0]) for r in rows]
    starts = [0] + [i for i in range(1, len(steps)) if any(t(steps[i], n) != t(steps[i - 1], n) for n in names)]
    phases = []
    for p, begin in enumerate(starts):
        end = starts[p + 1] if p + 1 < len(starts) else len(steps)
        tail = rows[end - max(1, -(-(end - begin) // 5)):end]
        relative = absolute = inside = 0.0
        for r in tail:
            for n in names:
                k, truth_k = float(r[header.index(n)]), t(int(r[0]), n)
                std = float(r[header.index(n + '_std')])
                relative += abs(k - truth_k) / truth_k
                absolute += abs(k - truth_k)
                inside += abs(k - truth_k) <= 2 * std
        count = len(tail) * len(names)
        phases.append((100 * relative / count, absolute / count, 100 * inside / count))
    ratios = [float(r[header.index(n)]) / t(int(r[0]), n) for r in rows for n in names if t(int(r[0]), n) > 1]
    return phases, min(ratios), max(ratios)


def with_truth_stiffness(scenario, stiffness, out):
    """A copy of `scenario` in `out` with these true ligament stiffnesses, its files absolute."""
    spec = relocatable_scenario(scenario)
    if len(stiffness) != len(spec['ligaments']):
        raise SystemExit(f'--truth-stiffness: {len(stiffness)} values for the {len(spec["ligaments"])} ligaments of {scenario}')
    for ligament, k in zip(spec['ligaments'], stiffness):
        ligament['stiffness'] = k
    os.makedirs(out, exist_ok=True)
    copy = os.path.join(out, os.path.basename(scenario))
    with open(copy, 'w') as f:
        json.dump(spec, f, indent=1)
    return copy


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('sigmafem')
    parser.add_argument('out')
    parser.add_argument('scenarios', nargs='+')
    parser.add_argument('--seeds', default='1,2,3,4,5')
    parser.add_argument('--noise-std')
    parser.add_argument('--observation-std')
    parser.add_argument('--backend', default='cpu')
    parser.add_argument('--jobs', type=int, default=2)
    parser.add_argument('--truth-stiffness')
    parser.add_argument('--truth-refine')
    args = parser.parse_args()
    if args.truth_stiffness:
        stiffness = [float(k) for k in args.truth_stiffness.split(',')]
        args.scenarios = [with_truth_stiffness(s, stiffness, args.out) for s in args.scenarios]

    def run(job):
        scenario, seed = job
        name = os.path.splitext(os.path.basename(scenario))[0]
        data = os.path.join(args.out, f'{name}-seed{seed}')
        generate = [args.sigmafem, 'generate', scenario, '--out', data, '--seed', str(seed), '--vtk-every', '0', '--quiet']
        if args.noise_std is not None: generate += ['--noise-std', args.noise_std]
        if args.truth_refine is not None: generate += ['--truth-refine', args.truth_refine]
        subprocess.run(generate, check=True)
        estimate = [args.sigmafem, 'estimate', scenario, '--data', data, '--out', os.path.join(data, 'estimate'),
                    '--backend', args.backend, '--quiet']
        if args.observation_std is not None: estimate += ['--observation-std', args.observation_std]
        subprocess.run(estimate, check=True)
        with open(os.path.join(data, 'estimate', 'summary.json')) as f:
            summary = json.load(f)
        follow = [e.get('steps_to_follow') for e in summary['errors'].values()][1:]
        return name, seed, figures(data, os.path.join(data, 'estimate')), follow, [c['ligament'] for c in summary['cuts']]

    jobs = [(s, int(seed)) for s in args.scenarios for seed in args.seeds.split(',')]
    print('| scenario | seed | per phase: error % / N/m / inside +-2 std % | followed in (steps) | cut | uncut estimate / truth |')
    print('|---|---|---|---|---|---|')
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for name, seed, (phases, low, high), follow, cuts in pool.map(run, jobs):
            cells = '; '.join(f'{rel:.2f}% / {ab:.2f} / {cov:.1f}%' for rel, ab, cov in phases)
            print(f'| {name} | {seed} | {cells} | {follow} | {cuts} | {low:.2f}..{high:.2f} |', flush=True)


if __name__ == '__main__':
    main()
