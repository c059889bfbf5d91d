"""nscd_sim.study on a Dask cluster run the way a lab runs one: `dask scheduler` and two
`dask worker` programs (python3-distributed's commands, each its own process group) on
loopback ports, the C-60 clearance study (scripts/analysis/c60_clearance_study.py,
module backend) submitted to tcp://127.0.0.1:PORT by its command line. The workers find
the module and the study's helpers on their PYTHONPATH and the scenes the study writes
on the (here local) shared disk. One worker is killed (SIGKILL to its whole program,
nanny and worker) while it runs a case: Dask reruns that case on the other worker and
the study's result files equal a run on local processes, every figure. The same with
--shard 0/2 and 1/2, a worker killed during shard 0, the two shards' files merged.
Every process started here is stopped at the end, whatever happens."""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

from conftest import NSCD_RUN, REPO

distributed = pytest.importorskip('distributed')

STUDY = os.path.join(REPO, 'scripts', 'analysis', 'c60_clearance_study.py')
DASK = shutil.which('dask') or '/usr/bin/dask'
# Two journal-seed cases next to each other in the study's CASES (indices 6 and 7), so
# --shard 0/2 runs the first and 1/2 the second: four runs (trip, bench) in all.
CASES = ['s01', 's02']
PROCESS_TIMEOUT = 240  # s, any one study or cluster start-up; the ctest entry stops at 300 s


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def python_path():
    """The module's folders (as this process imports it) and the study's helpers."""
    import nscd_sim
    dirs = [os.path.dirname(p) for p in nscd_sim.__path__]
    dirs += [os.path.join(REPO, 'scripts', 'analysis'), os.path.join(REPO, 'scripts', 'c60_model')]
    return os.pathsep.join(dirs)


class Cluster:
    """A scheduler and named workers, each a `dask` command in its own process group."""

    def __init__(self, work):
        self.work = work
        self.port = free_port()
        self.address = 'tcp://127.0.0.1:%d' % self.port
        self.env = dict(os.environ, PYTHONPATH=python_path(), PYTHONDONTWRITEBYTECODE='1',
                        OMP_NUM_THREADS='1')
        self.procs = {}  # name -> Popen
        self.client = None

    def _start(self, name, args):
        log = open(os.path.join(self.work, name + '.log'), 'w')
        self.procs[name] = subprocess.Popen([DASK] + args, stdout=log, stderr=subprocess.STDOUT,
                                            env=self.env, cwd=self.work, start_new_session=True)
        log.close()

    def log(self, name):
        with open(os.path.join(self.work, name + '.log')) as f:
            return f.read()

    def start(self, workers):
        self._start('scheduler', ['scheduler', '--host', '127.0.0.1', '--port', str(self.port),
                                  '--no-dashboard'])
        for name in workers:
            self.add_worker(name)
        deadline = time.monotonic() + PROCESS_TIMEOUT
        while self.client is None:
            try:
                self.client = distributed.Client(self.address, timeout=5)
            except OSError:
                if time.monotonic() > deadline or self.procs['scheduler'].poll() is not None:
                    raise RuntimeError('the scheduler did not start:\n' + self.log('scheduler'))
                time.sleep(0.2)
        self.wait_for(workers)

    def add_worker(self, name):
        os.makedirs(os.path.join(self.work, name), exist_ok=True)
        self._start(name, ['worker', self.address, '--name', name, '--nworkers', '1', '--nthreads', '1',
                           '--host', '127.0.0.1', '--no-dashboard', '--local-directory',
                           os.path.join(self.work, name), '--death-timeout', '60'])

    def workers(self):
        """name -> address of the workers the scheduler has now."""
        return self.client.run_on_scheduler(
            lambda dask_scheduler: {ws.name: a for a, ws in dask_scheduler.workers.items()})

    def wait_for(self, names):
        deadline = time.monotonic() + PROCESS_TIMEOUT
        while set(self.workers()) != set(names):
            if time.monotonic() > deadline:
                raise RuntimeError('workers %s, expected %s' % (sorted(self.workers()), sorted(names)))
            time.sleep(0.1)

    def two_workers(self):
        """Starts workers until the scheduler has two again (after a kill, as a lab's
        job array restarts one); returns their names."""
        names = set(self.workers())
        k = len(self.procs)
        while len(names) < 2:
            names.add('w%d' % k)
            self.add_worker('w%d' % k)
            k += 1
        self.wait_for(names)
        return sorted(names)

    def kill(self, name):
        """SIGKILL to the worker's program: nanny and worker at once, as when a node dies."""
        os.killpg(self.procs[name].pid, signal.SIGKILL)
        self.procs[name].wait(timeout=30)

    def close(self):
        if self.client is not None:
            self.client.close()
        for p in self.procs.values():  # workers first, the scheduler last
            try:
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for p in self.procs.values():
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
            try:  # the group's other processes too (a worker under its nanny)
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()

    def leftovers(self, wait=10.0):
        """The process groups of the cluster that still have a process (after `wait` s
        for the killed ones to be reaped)."""
        deadline = time.monotonic() + wait
        while True:
            alive = []
            for name, p in self.procs.items():
                try:
                    os.killpg(p.pid, 0)
                    alive.append(name)
                except ProcessLookupError:
                    pass
            if not alive or time.monotonic() > deadline:
                return alive
            time.sleep(0.1)


@pytest.fixture(scope='module')
def cluster(tmp_path_factory):
    c = Cluster(str(tmp_path_factory.mktemp('dask')))
    try:
        c.start(['w0', 'w1'])
        yield c
    finally:
        c.close()
        assert c.leftovers() == [], 'processes of the cluster left running'


def study_command(out, *args):
    return ['/usr/bin/python3', STUDY, 'run', '--out', str(out), '--backend', 'module',
            '--cases', ','.join(CASES)] + list(args)


def study_env(out):
    # scripts/c60_env.sh (the bench's table schedule) wants nscd_run, and makes C60_OUT.
    return dict(os.environ, NSCD_RUN=NSCD_RUN, C60_OUT=str(out), PYTHONDONTWRITEBYTECODE='1')


def run_study(out, *args):
    p = subprocess.run(study_command(out, *args), capture_output=True, text=True, timeout=PROCESS_TIMEOUT,
                       env=study_env(out))
    assert p.returncode == 0, p.stderr
    return p.stderr


def run_study_killing(cluster, out, victim, *args):
    """Runs the study on the cluster and kills worker `victim` once it has been running
    a case for 0.3 s; returns the study's standard error and the keys the victim held."""
    t0 = time.monotonic()
    p = subprocess.Popen(study_command(out, '--scheduler', cluster.address, *args), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=study_env(out))
    try:
        address = cluster.workers()[victim]
        deadline = time.monotonic() + PROCESS_TIMEOUT
        busy_since, held = None, []
        while p.poll() is None and time.monotonic() < deadline:
            held = cluster.client.processing(workers=[address]).get(address, [])
            if not held:
                busy_since = None
            elif busy_since is None:
                busy_since = time.monotonic()
            if held and time.monotonic() - busy_since > 0.3:
                cluster.kill(victim)
                killed_at = time.monotonic() - t0
                break
            time.sleep(0.02)
        else:
            pytest.fail('worker %s never ran a case of the study (study status %s)' % (victim, p.poll()))
        _, err = p.communicate(timeout=PROCESS_TIMEOUT)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 0, err
    print('study %s: worker %s killed at %.1f s holding %d run(s), the study done at %.1f s'
          % (' '.join(args) or 'whole', victim, killed_at, len(held), time.monotonic() - t0))
    return err, held


def without_wall(o):
    """A result with its wall times left out (every other field kept)."""
    if isinstance(o, dict):
        return {k: without_wall(v) for k, v in o.items() if k != 'wall_s'}
    if isinstance(o, list):
        return [without_wall(v) for v in o]
    return o


def results(out):
    found = {}
    for case in CASES:
        with open(os.path.join(str(out), 'study_%s.json' % case)) as f:
            found[case] = without_wall(json.load(f))
    return found


@pytest.fixture(scope='module')
def reference(tmp_path_factory):
    """The study on two local processes, no Dask."""
    out = tmp_path_factory.mktemp('local')
    t0 = time.monotonic()
    run_study(out, '--jobs', '2')
    print('study on 2 local processes: %.1f s' % (time.monotonic() - t0))
    return results(out)


def test_workers_find_the_module_and_the_study_helpers(cluster):
    import nscd_sim
    here = sorted(os.path.realpath(p) for p in nscd_sim.__path__)
    found = cluster.client.run(lambda: (sorted(os.path.realpath(p) for p in __import__('nscd_sim').__path__),
                                        __import__('nscd_sim')._engine.__file__,
                                        __import__('c60_trip_figures').__file__))
    assert sorted(found) == sorted(cluster.workers().values())
    for paths, engine, helper in found.values():
        assert paths == here
        assert os.path.dirname(engine) in here
        assert helper.startswith(os.path.join(REPO, 'scripts', 'analysis'))


def test_study_survives_a_killed_worker(cluster, reference, tmp_path):
    victim, survivor = cluster.two_workers()
    err, held = run_study_killing(cluster, tmp_path, victim)
    assert held, 'the killed worker held no case'
    assert 'through nscd_sim.study on %s' % cluster.address in err
    assert set(cluster.workers()) == {survivor}  # the scheduler saw it go
    assert results(tmp_path) == reference
    # The figures are the physics' (the study's published order), not empty files.
    trip = reference['s01']['trip']
    assert 0.7 < trip['touch_ms'] < trip['release_ms'] < trip['c7_open_ms']


def test_shards_survive_a_killed_worker(cluster, reference, tmp_path):
    victim, _ = cluster.two_workers()
    err0, held = run_study_killing(cluster, tmp_path, victim, '--shard', '0/2')
    assert held, 'the killed worker held no case'
    assert 'study: 1 cases (2 runs)' in err0 and os.path.exists(tmp_path / 'study_s01.json')
    assert not os.path.exists(tmp_path / 'study_s02.json')  # shard 0 ran s01 alone
    err1 = run_study(tmp_path, '--scheduler', cluster.address, '--shard', '1/2')
    assert 'study: 1 cases (2 runs)' in err1
    assert results(tmp_path) == reference  # the two shards' files, merged in one folder
