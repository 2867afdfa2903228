#!/usr/bin/env python3
"""The model of a filter step over R machines (issue 19; bench/RESULTS.md, "Stop 48: sigma
points over MPI ranks"), from what was measured on one 2-core machine and the message sizes.

One rank per machine of c cores. Per filter step:
  compute   ceil(S / R) sigma points per machine, t_sigma core-seconds each, on c cores
  resample  rank 0 re-samples all S states: measured at R = 1 (recenter_ms), grows as n S p
  transfer  rank 0 receives and sends every other rank's states: 2 (positions, velocities)
            x n x S (1 - 1/R) doubles each way, through its one link of bandwidth B
  latency   five collectives a step (the Bcasts and gathers), each about log2(R) x the
            network's latency
The step is compute + resample + transfer + latency (no overlap: rank 0 waits for the
slowest rank in the gathers, then re-samples while the others wait). Communication
dominates where transfer + latency exceed compute.

    python3 bench/mpi_scaling_model.py
"""
import math

# Measured here (bench/RESULTS.md; sigmafem_mpi_bench on the 2-core machine, CPU back end):
# core-seconds per sigma point and filter step (1 rank, 2 threads: step time x 2 / S), and
# rank 0's re-centring at R = 1 (reading, re-sampling and writing the states). The liver's
# from stop 48; the 38k liver's from stop 49, with the mean sigma point's shared factor and
# the re-sampling on rank 0's two threads (4.85 s a step, 61 ms; stop 48 without them: 6.59 s,
# 97 ms).
CASES = [
    # name, tetrahedra, n (3 x nodes), p, S, t_sigma (core-s), resample (s) at this S and p
    ('liver, p = 16 simplex', 596, 3 * 181, 16, 17, 9.8e-3 * 2 / 17, 0.44e-3),
    ('38k liver, p = 32 simplex', 38144, 3 * 7509, 32, 33, 4.85 * 2 / 33, 0.061),
    ('38k liver, p = 64 star', 38144, 3 * 7509, 64, 129, 4.85 * 2 / 33, 0.061 * (129 * 64) / (33 * 32)),
]
NETWORKS = [('10 Gb/s Ethernet', 1.25e9, 50e-6), ('100 Gb/s InfiniBand', 12.5e9, 2e-6)]
CORES = 2   # per machine, as this kind


def step(case, R, network):
    _, _, n, _, S, t_sigma, resample = case
    _, bandwidth, latency = network
    compute = math.ceil(S / R) * t_sigma / CORES
    transfer = 2 * 2 * n * S * (1 - 1 / R) * 8 / bandwidth   # both ways through rank 0's link
    latencies = 5 * math.ceil(math.log2(R)) * latency if R > 1 else 0.0
    return compute, resample, transfer + latencies


def main():
    for network in NETWORKS:
        print(f'\n{network[0]} ({network[1] / 1e9:g} GB/s, {network[2] * 1e6:g} us), {CORES} cores per machine')
        print('| case | machines | compute | resample (rank 0) | communication | step | communication share |')
        print('| --- | ---: | ---: | ---: | ---: | ---: | ---: |')
        for case in CASES:
            for R in (1, 2, 8, 64):
                if R > case[4]:
                    continue
                compute, resample, communication = step(case, R, network)
                total = compute + resample + communication
                print(f'| {case[0]} | {R} | {compute * 1e3:.1f} ms | {resample * 1e3:.1f} ms | '
                      f'{communication * 1e3:.2f} ms | {total * 1e3:.1f} ms | {100 * communication / total:.0f}% |')
        for case in CASES:
            crossing = next((R for R in range(1, case[4] + 1)
                             if step(case, R, network)[2] > step(case, R, network)[0]), None)
            print(f'{case[0]}: communication exceeds compute from {crossing} machines' if crossing
                  else f'{case[0]}: compute exceeds communication up to S = {case[4]} machines')


if __name__ == '__main__':
    main()
