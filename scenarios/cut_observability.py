#!/usr/bin/env python3
"""How observable is a cut ligament's stiffness? (README, "Estimation results".)

Simulates a scenario noise-free with its cut event's stiffness replaced by each of several
values, and prints, against the run with the scenario's own value, the largest displacement
of an observed point and the chi-square of the differences at the scenario's observation
noise, over all steps after the cut and over the last 20% of them.

    python3 scenarios/cut_observability.py build/sigmafem scenarios/box.json 0.5 1.5 5 20
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

from scenario_copy import relocatable_scenario


def observations(path):
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    reader = csv.reader(rows)
    header = next(reader)
    first_point = header.index("so_z") + 1
    return [(float(r[1]), [float(v) for v in r[first_point:]]) for r in reader]


def simulate(sigmafem, scenario, stiffness, folder):
    spec = relocatable_scenario(scenario)
    spec["events"][0]["stiffness"] = stiffness
    path = os.path.join(folder, f"cut_{stiffness}.json")
    with open(path, "w") as f:
        json.dump(spec, f)
    out = os.path.join(folder, f"cut_{stiffness}")
    subprocess.run([sigmafem, "generate", path, "--out", out, "--noise-std", "0",
                    "--vtk-every", "0", "--quiet"], check=True)
    return spec, observations(os.path.join(out, "observations.csv"))


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    sigmafem, scenario, values = sys.argv[1], sys.argv[2], [float(v) for v in sys.argv[3:]]
    with tempfile.TemporaryDirectory() as folder:
        spec, base = simulate(sigmafem, scenario, json.load(open(scenario))["events"][0]["stiffness"], folder)
        cut_time = spec["events"][0]["time"]
        end_time = base[-1][0]
        last_phase = cut_time + 0.8 * (end_time - cut_time)
        sigma = spec["observations"]["noise_std"]
        for value in values:
            _, other = simulate(sigmafem, scenario, value, folder)
            largest = chi_after = chi_last = 0.0
            for (t, a), (_, b) in zip(base, other):
                if t <= cut_time:
                    continue
                d2 = sum((x - y) ** 2 for x, y in zip(a, b))
                largest = max(largest, max(abs(x - y) for x, y in zip(a, b)))
                chi_after += d2 / sigma ** 2
                if t >= last_phase:
                    chi_last += d2 / sigma ** 2
            print(f"cut ligament at {value:g} N/m instead of {spec['events'][0]['stiffness']:g}: "
                  f"largest displacement {largest * 1e6:.0f} um, chi-square {chi_after:.0f} "
                  f"after the cut, {chi_last:.0f} over its last 20%")


if __name__ == "__main__":
    main()
