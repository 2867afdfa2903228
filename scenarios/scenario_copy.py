"""A scenario read for writing a changed copy elsewhere: its file paths made absolute.

Shared by the scripts beside it that simulate variants of a scenario (cut_observability.py,
estimation_table.py).
"""
import json
import os


def relocatable_scenario(scenario):
    """The scenario's JSON with its mesh and trajectory files as absolute paths."""
    with open(scenario) as f:
        spec = json.load(f)
    here = os.path.dirname(os.path.abspath(scenario))
    spec['mesh']['file'] = os.path.join(here, spec['mesh']['file'])
    trajectory = spec['control']['trajectory']
    if 'file' in trajectory:
        trajectory['file'] = os.path.join(here, trajectory['file'])
    return spec
