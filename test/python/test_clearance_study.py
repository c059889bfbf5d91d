"""scripts/analysis/c60_clearance_study.py, the C-60 clearance study written against the module:
one case through the module backend (nscd_sim.study, 1 and 2 processes), through
the CLI backend (nscd_run) and through the sweep backend (nscd_sweep, two shards), the
figures the same; a case with random journal starts places them (its initial
eccentricities differ from the centred scene's)."""
import json
import os
import subprocess
import sys

import pytest

from conftest import NSCD_RUN, REPO

STUDY = os.path.join(REPO, 'scripts', 'analysis', 'c60_clearance_study.py')


def run_study(out, *args):
    env = dict(os.environ, NSCD_RUN=NSCD_RUN)
    env.pop('NSCD_SWEEP', None)  # the sweep backend takes the nscd_sweep beside NSCD_RUN
    p = subprocess.run(['/usr/bin/python3', STUDY, 'run', '--out', str(out)] + list(args),
                       capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr
    return p.stderr


def figures(out, case):
    with open(os.path.join(str(out), 'study_%s.json' % case)) as f:
        r = json.load(f)
    return r


def numbers(o, prefix=''):
    """Every number of a result, flattened, wall times left out."""
    if isinstance(o, dict):
        for k, v in o.items():
            if k != 'wall_s':
                yield from numbers(v, prefix + '/' + k)
    elif isinstance(o, list):
        for k, v in enumerate(o):
            yield from numbers(v, '%s/%d' % (prefix, k))
    elif isinstance(o, (int, float)) and not isinstance(o, bool):
        yield prefix, float(o)


def without_wall(o):
    """A result with its wall times left out (every other field kept)."""
    if isinstance(o, dict):
        return {k: without_wall(v) for k, v in o.items() if k != 'wall_s'}
    return o


def test_backends_and_worker_counts_agree(tmp_path):
    one, two, cli = tmp_path / 'one', tmp_path / 'two', tmp_path / 'cli'
    run_study(one, '--cases', 's07,a2', '--jobs', '1', '--backend', 'module')
    run_study(two, '--cases', 's07,a2', '--jobs', '2', '--backend', 'module')
    run_study(cli, '--cases', 's07', '--jobs', '1', '--backend', 'cli')
    for case in ('s07', 'a2'):
        a, b = figures(one, case), figures(two, case)
        assert dict(numbers(a)) == dict(numbers(b)), case  # bit for bit, any worker count
    # The CLI backend reads nscd_run's CSV (12 significant digits) back: the figures agree
    # to that precision (a spread of 5e-8 N reads 5.4e-8 N: 1e-6 absolute).
    m, c = dict(numbers(figures(one, 's07'))), dict(numbers(figures(cli, 's07')))
    assert set(m) == set(c)
    for k in m:
        assert m[k] == pytest.approx(c[k], rel=1e-6, abs=1e-6), k
    # The sweep backend: both shards of s07 and a2 (one case each) in one OUT. Both it and
    # the cli backend read nscd_run's CSV format, so they agree to the last digit; with
    # the module, to the CSV's precision.
    sweep = tmp_path / 'sweep'
    log0 = run_study(sweep, '--cases', 's07,a2', '--jobs', '2', '--backend', 'sweep', '--shard', '0/2')
    log1 = run_study(sweep, '--cases', 's07,a2', '--jobs', '1', '--backend', 'sweep', '--shard', '1/2')
    # Run k of nscd_sweep is the k-th selected case in CASES order (a2, s07): one per shard.
    assert 'study_a2_trip.urdf) ok' in log0 and 'study_s07_trip.urdf' not in log0
    assert 'study_s07_bench.urdf) ok' in log1 and 'study_a2_bench.urdf' not in log1
    assert without_wall(figures(sweep, 's07')) == without_wall(figures(cli, 's07'))  # every field, None too
    s, m = dict(numbers(figures(sweep, 'a2'))), dict(numbers(figures(one, 'a2')))
    assert set(s) == set(m)
    for k in m:
        assert s[k] == pytest.approx(m[k], rel=1e-6, abs=1e-6), k
    assert not os.path.exists(sweep / 'sweep_trip')  # the series are read and removed
    # The study's figures are the physics' (not all zero, and in the published order).
    t = figures(one, 's07')['trip']
    assert 0.7 < t['touch_ms'] < t['corner_ms'] < t['release_ms'] < t['c7_open_ms'] < t['release_ms'] + 2
    assert t['self_trip_ms'] is None and t['joint_apart_ms'] is None  # latched, and every joint held
    assert 15.0 < figures(one, 's07')['bench']['equilibrium_force_N'] < 15.5


def test_random_journal_starts_are_placed(tmp_path):
    run_study(tmp_path, '--cases', 'nominal,s07', '--jobs', '2', '--backend', 'module')
    centred = figures(tmp_path, 'nominal')['polarisation_initial']
    placed = figures(tmp_path, 's07')['polarisation_initial']
    assert max(p['ecc'] for p in centred.values()) < 0.05
    assert min(p['ecc'] for p in placed.values()) > 0.05  # every journal off its bore's axis
    assert max(p['ecc'] for p in placed.values()) < 1.0 + 1e-6  # and inside its bearing


def test_unknown_case_is_refused(tmp_path):
    p = subprocess.run(['/usr/bin/python3', STUDY, 'run', '--out', str(tmp_path), '--cases', 'nope'],
                       capture_output=True, text=True)
    assert p.returncode != 0
    assert 'unknown case(s): nope' in p.stderr
