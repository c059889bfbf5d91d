"""nscd_sim.study: results in case order, the same on 1 or 2 local processes and on a
Dask LocalCluster of 1 or 2 workers; shards partition the study as nscd_sweep's do."""
import time

import numpy as np
import pytest

from nscd_sim.study import Case, CaseResult, merge_results, parse_shard, run_study, shard_indices

from conftest import scene


def bounce_figures(record, sim):
    """Picklable extractor: the highest rebound, the last height, the full z trace."""
    z = record['ball.z']
    return {'z_max_after_first_bounce': float(z[np.argmin(z):].max()), 'z_end': float(z[-1]),
            'z': z.copy(), 'steps': sim.steps}


def cases():
    # Four tiny ball runs whose figures differ (restitution via the dt and theta settings).
    return [Case(scene('urdf/ball.urdf'), 0.4, settings={'theta': th}, label='theta=%g' % th)
            for th in (0.5, 0.6, 0.8, 1.0)]


def same(a, b):
    assert [r.index for r in a] == [r.index for r in b]
    for x, y in zip(a, b):
        assert x.error == y.error
        assert x.value['z'].tobytes() == y.value['z'].tobytes()
        assert x.value['z_end'] == y.value['z_end']


def test_local_processes_give_the_same_results_in_order():
    serial = run_study(cases(), bounce_figures, workers=1)
    assert [r.index for r in serial] == [0, 1, 2, 3]
    assert len({r.value['z_end'] for r in serial}) == 4  # the cases differ
    same(serial, run_study(cases(), bounce_figures, workers=2))


def test_shards_partition_the_study():
    assert shard_indices(7, '1/3') == [1, 4]
    assert parse_shard('2/3') == (2, 3)
    for bad in ('3/3', '1', 'a/b', '-1/2'):
        with pytest.raises(ValueError, match='shard'):
            parse_shard(bad)
    full = run_study(cases(), bounce_figures, workers=1)
    parts = [run_study(cases(), bounce_figures, workers=1, shard='%d/3' % i) for i in range(3)]
    assert [r.index for r in parts[1]] == [1]
    same(full, merge_results(*parts))
    with pytest.raises(ValueError, match='two shards'):
        merge_results(parts[0], parts[0])


def test_failures_name_the_case_or_become_results():
    bad = cases()[:1] + [Case(scene('urdf/ball.urdf'), 0.1, settings={'theta': 0.1})]
    with pytest.raises(RuntimeError, match='case 1 .*SceneError.*theta'):
        run_study(bad, bounce_figures, workers=1)
    res = run_study(bad, bounce_figures, workers=2, keep_going=True)
    assert res[0].error is None and res[1].value is None and res[1].error.startswith('SceneError')
    with pytest.raises(TypeError, match='Case'):
        run_study(['ball.urdf'], bounce_figures)
    with pytest.raises(ValueError, match='workers'):
        run_study(cases(), bounce_figures, workers=0)


def test_dask_local_cluster_1_and_2_workers_agree():
    distributed = pytest.importorskip('distributed')
    serial = run_study(cases(), bounce_figures, workers=1)
    walls = {}
    for n in (1, 2):
        with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster:
            t0 = time.perf_counter()
            res = run_study(cases(), bounce_figures, scheduler=cluster)
            walls[n] = time.perf_counter() - t0
        assert all(isinstance(r, CaseResult) for r in res)
        same(serial, res)
    print('dask LocalCluster wall time: 1 worker %.2f s, 2 workers %.2f s' % (walls[1], walls[2]))


STUDY_FILE = '''
import numpy as np
from nscd_sim.study import Case
CASES = [Case(%r, 0.2, settings={'theta': th}) for th in (0.5, 0.7, 0.9)]
def extract(record, sim):
    return float(record['ball.z'][-1]), int(record['iters'].sum())
'''


def run_study_cli(args, env_path):
    import os
    import subprocess
    import sys
    env = dict(os.environ, PYTHONPATH=env_path)
    p = subprocess.run([sys.executable, '-m', 'nscd_sim.study'] + args, capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr
    return p


def test_command_line_shards_merge_and_dask_scheduler(tmp_path):
    import os
    import pickle
    import nscd_sim
    env_path = os.pathsep.join(nscd_sim.__path__[i].rsplit(os.sep, 1)[0] for i in range(len(nscd_sim.__path__)))
    study = tmp_path / 'ball_study.py'
    study.write_text(STUDY_FILE % scene('urdf/ball.urdf'))
    for i in (0, 1):
        run_study_cli([str(study), '--workers', '2', '--shard', '%d/2' % i, '--out', str(tmp_path / ('s%d.pkl' % i))],
                      env_path)
    run_study_cli(['--merge', str(tmp_path / 's0.pkl'), str(tmp_path / 's1.pkl'), '--out', str(tmp_path / 'all.pkl')],
                  env_path)
    merged = pickle.loads((tmp_path / 'all.pkl').read_bytes())
    assert [r.index for r in merged] == [0, 1, 2]
    values = [r.value for r in merged]
    assert len(set(values)) == 3 and all(r.error is None for r in merged)
    distributed = pytest.importorskip('distributed')
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster:
        run_study_cli([str(study), '--scheduler', cluster.scheduler_address, '--out', str(tmp_path / 'dask.pkl')],
                      env_path)
    assert [r.value for r in pickle.loads((tmp_path / 'dask.pkl').read_bytes())] == values
    p = run_study_cli([str(study), '--workers', '1'], env_path)  # no --out: one line per case
    assert p.stdout.splitlines()[0] == '0 %r' % (values[0],)
