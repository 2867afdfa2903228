#!/usr/bin/env python3
"""The stiff-inclusion figures (README, "Stiffness fields"; issue 19).

Runs `generate` and `estimate` (CPU back end) on scenarios/liver_inclusion.json and on
variants of it written to OUT, and prints per variant the inclusion's estimate against its
truth, whether it is the stiffest of the 8 regions, the largest error of the other regions'
moduli and of the ligaments' stiffnesses, all at the last step (summary.json, final):

  shipped           the scenario as it is: 73 anterior surface nodes, noise-free
  all_surface       the 140 nodes of the boundary surface (nodes 0-139 of liver.msh)
  moved             the inclusion in right_lower_posterior instead, all surface nodes
  noise_seed1, 2    0.5 mm noise (and the filter told so), seeds 1 and 2
  no_gravity        gravity 0
  truth_refined     the truth on the mesh refined once (4768 tetrahedra)
  no_inclusion_refined   every region at 5 kPa, the truth on the refined mesh
  model_refined     the model on the refined mesh, the truth refined twice (38144
                    tetrahedra), all surface nodes (--fine: about 6 minutes more)

    python3 scenarios/inclusion_table.py build/sigmafem OUT [--fine]
"""
import argparse
import concurrent.futures
import copy
import json
import os
import subprocess

from scenario_copy import relocatable_scenario

INCLUSION = 'left_upper_anterior'


def variants(base, fine):
    def changed(change):
        spec = copy.deepcopy(base)
        change(spec)
        return spec

    def all_surface(spec):
        spec['observations']['nodes'] = list(range(140))

    def move(spec):
        all_surface(spec)
        for region in spec['regions']:
            region.pop('young_modulus', None)
            if region['name'] == 'right_lower_posterior':
                region['young_modulus'] = 25000.0

    def noisy(spec):
        spec['observations']['noise_std'] = 0.0005
        spec['filter']['observation_std'] = 0.0005

    def no_gravity(spec):
        spec['gravity'] = [0.0, 0.0, 0.0]

    def no_inclusion(spec):
        for region in spec['regions']:
            region.pop('young_modulus', None)

    def refined_model(spec):
        all_surface(spec)
        spec['mesh']['refine'] = 1

    runs = [('shipped', base, []), ('all_surface', changed(all_surface), []),
            ('moved', changed(move), []),
            ('noise_seed1', changed(noisy), ['--seed', '1']), ('noise_seed2', changed(noisy), ['--seed', '2']),
            ('no_gravity', changed(no_gravity), []), ('truth_refined', base, ['--truth-refine', '1']),
            ('no_inclusion_refined', changed(no_inclusion), ['--truth-refine', '1'])]
    if fine:
        runs.append(('model_refined', changed(refined_model), ['--truth-refine', '1']))
    return runs


def run(binary, out, name, spec, generate_args):
    folder = os.path.join(out, name)
    os.makedirs(folder, exist_ok=True)
    scenario = os.path.join(folder, 'scenario.json')
    with open(scenario, 'w') as f:
        json.dump(spec, f, indent=1)
    data, estimate = os.path.join(folder, 'data'), os.path.join(folder, 'estimate')
    subprocess.run([binary, 'generate', scenario, '--out', data, '--vtk-every', '0', '--quiet'] + generate_args,
                   check=True)
    subprocess.run([binary, 'estimate', scenario, '--data', data, '--out', estimate, '--backend', 'cpu', '--quiet'],
                   check=True)
    with open(os.path.join(estimate, 'summary.json')) as f:
        final = json.load(f)['final']
    truth = {r['name']: r.get('young_modulus', spec['material']['young_modulus']) for r in spec['regions']}
    inclusion = max(truth, key=truth.get) if len(set(truth.values())) > 1 else None
    moduli = {name[2:]: value['young_modulus_pa'] for name, value in final.items() if name.startswith('E:')}
    errors = {name: moduli[name] / truth[name] - 1 for name in moduli}
    stiffest = max(moduli, key=moduli.get)
    others = [abs(e) for name, e in errors.items() if name != inclusion]
    ligaments = [abs(final[l['name']]['stiffness_n_per_m'] / l['stiffness'] - 1) for l in spec['ligaments']]
    found = '-' if inclusion is None else ('yes' if stiffest == inclusion else 'no (%s)' % stiffest)
    estimate_text = '-' if inclusion is None else '%.0f Pa (%+.1f%%)' % (moduli[inclusion], 100 * errors[inclusion])
    return '| %s | %s | %s | %.1f%% | %.1f%% |' % (name, found, estimate_text, 100 * max(others), 100 * max(ligaments))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('binary')
    parser.add_argument('out')
    parser.add_argument('--fine', action='store_true')
    args = parser.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    base = relocatable_scenario(os.path.join(here, 'liver_inclusion.json'))
    print('| variant | inclusion the stiffest | inclusion estimate (truth 25 kPa) | other regions, largest error | ligaments, largest error |')
    print('| --- | --- | ---: | ---: | ---: |')
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        rows = [pool.submit(run, os.path.abspath(args.binary), args.out, *v) for v in variants(base, args.fine)]
        for row in rows:
            print(row.result(), flush=True)


if __name__ == '__main__':
    main()
