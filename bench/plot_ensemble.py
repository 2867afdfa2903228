#!/usr/bin/env python3
"""Plots the ensemble benchmark (bench/ensemble_step_bench.cpp) as PNGs with gnuplot.

    build/bench/sigmafem_bench --benchmark_filter='BM_ensemble_step' \\
        --benchmark_out=ensemble.json --benchmark_out_format=json
    python3 bench/plot_ensemble.py ensemble.json bench/ensemble_speed.png

Left: element-iterations per second against S on the 4768-tetrahedron liver; right: against
the number of tetrahedra at S = 16; one line per back end.
"""
import json
import os
import subprocess
import sys
import tempfile

# The meshes the benchmark runs on, as its capture names end.
MESHES = ["liver_4768", "liver_596", "liver_fine_38144", "box_large_117240"]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    results = json.load(open(sys.argv[1]))["benchmarks"]
    series = {}  # (kind, backend) -> [(x, y)]
    for r in results:
        name = r["name"]
        if not name.startswith("BM_ensemble_step/") or "error_occurred" in r:
            continue
        capture = name.split("/")[1]               # e.g. opencl_per_iteration_liver_4768
        mesh = next(m for m in MESHES if capture.endswith("_" + m))
        backend = capture[: -len(mesh) - 1]          # e.g. opencl_per_iteration
        rate = r["element_iterations_per_s"]
        if capture.endswith("liver_4768"):
            series.setdefault(("sigma", backend), []).append((r["S"], rate))
        if r["S"] == 16:
            series.setdefault(("mesh", backend), []).append((r["tetrahedra"], rate))
    with tempfile.TemporaryDirectory() as folder:
        files = {}
        for key, points in series.items():
            path = os.path.join(folder, "%s_%s.dat" % key)
            with open(path, "w") as f:
                for x, y in sorted(set(points)):
                    f.write("%g %g\n" % (x, y))
            files[key] = path
        def plot(kind):
            return ", ".join("'%s' using 1:2 with linespoints lw 2 title '%s'" % (path, backend)
                             for (k, backend), path in sorted(files.items()) if k == kind)
        out = sys.argv[2]
        script = f"""
set terminal pngcairo size 1200,480 noenhanced
set output '{out}.tmp'
set multiplot layout 1,2
set logscale xy
set grid
set ylabel 'element-iterations per second'
set xlabel 'sigma points S (liver, 4768 tetrahedra)'
set key top left
plot {plot('sigma')}
set xlabel 'tetrahedra (S = 16)'
plot {plot('mesh')}
unset multiplot
"""
        subprocess.run(["gnuplot"], input=script, text=True, check=True)
        os.replace(out + ".tmp", out)


if __name__ == "__main__":
    main()
