"""Studies: many runs of nscd_sim scenes, spread over local cores or a Dask cluster.

A study is a list of Case (scene, settings, command schedules, duration) and one
picklable function extract(record, sim) -> figures, called after each run with
Simulator.run's record and the Simulator. run_study() returns one CaseResult per
case, in case order, the same whatever the number of workers or the backend:
every run is a fresh Simulator, and the engine is deterministic.

    from nscd_sim.study import Case, run_study
    cases = [Case('urdf/ball.urdf', 0.5, settings={'e': e}) for e in (0.2, 0.5)]
    results = run_study(cases, peak_height, workers=4)          # local processes
    results = run_study(cases, peak_height, scheduler='tcp://head:8786')   # Dask

`--shard i/n` (shard=(i, n)) keeps the runs k with k mod n == i, as nscd_sweep does,
so a Slurm array can split a study; merge_results() joins the shards' results.

Command line (a study file defines CASES and extract):
    python3 -m nscd_sim.study STUDY.py [--workers N | --scheduler ADDRESS] [--shard i/n] [--out R.pkl]
    python3 -m nscd_sim.study --merge R0.pkl R1.pkl ... --out R.pkl
"""

import argparse
import concurrent.futures
import dataclasses
import importlib.util
import os
import pickle
import sys
import time
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union


@dataclasses.dataclass(frozen=True)
class Case:
    """One run: Simulator(scene, settings, config, commands).run(duration, every)."""
    scene: str
    duration: float
    settings: Union[Mapping[str, Any], Sequence[str], None] = None
    commands: Union[Mapping[str, Any], Sequence[str], str, None] = None
    config: Optional[str] = None
    every: int = 1
    label: str = ''


@dataclasses.dataclass
class CaseResult:
    """What extract() returned for case `index` (value), or why the case failed (error:
    'ExceptionType: message'; value None). wall_s is left out of ==."""
    index: int
    value: Any
    error: Optional[str] = None
    wall_s: float = dataclasses.field(default=0.0, compare=False)


def run_case(case: Case, extract: Callable) -> Any:
    """Runs one case in this process and returns extract(record, sim)."""
    import nscd_sim  # here, not at the top: a Dask worker imports it on first use
    sim = nscd_sim.Simulator(case.scene, settings=case.settings, config=case.config,
                             commands=case.commands)
    record = sim.run(case.duration, every=case.every)
    return extract(record, sim)


def _run_indexed(job: Tuple[int, Case, Callable, bool]) -> CaseResult:
    index, case, extract, keep_going = job
    t0 = time.perf_counter()
    try:
        value = run_case(case, extract)
    except Exception as e:  # noqa: BLE001 - a failed case is a result when keep_going
        if not keep_going:
            raise RuntimeError('case %d (%s): %s: %s' % (index, case.label or case.scene,
                                                          type(e).__name__, e)) from e
        return CaseResult(index, None, '%s: %s' % (type(e).__name__, e),
                          time.perf_counter() - t0)
    return CaseResult(index, value, None, time.perf_counter() - t0)


def _run_indexed_pickled_extract(job) -> CaseResult:
    import cloudpickle
    index, case, extract, keep_going = job
    return _run_indexed((index, case, cloudpickle.loads(extract), keep_going))


def parse_shard(text: Union[str, Tuple[int, int], None]) -> Tuple[int, int]:
    """'i/n' or (i, n) -> (i, n), with 0 <= i < n; None -> (0, 1)."""
    if text is None:
        return 0, 1
    if isinstance(text, str):
        parts = text.split('/')
        if len(parts) != 2 or not all(p.strip().isdigit() for p in parts):
            raise ValueError('shard %r: expected i/n with integers 0 <= i < n' % text)
        i, n = int(parts[0]), int(parts[1])
    else:
        i, n = text
    if not (isinstance(i, int) and isinstance(n, int) and 0 <= i < n):
        raise ValueError('shard %r: expected i/n with integers 0 <= i < n' % (text,))
    return i, n


def shard_indices(n_cases: int, shard=None) -> list:
    """The case indices k of a shard: k mod n == i."""
    i, n = parse_shard(shard)
    return list(range(i, n_cases, n))


def run_study(cases: Sequence[Case], extract: Callable, workers: Optional[int] = None,
              scheduler=None, shard=None, keep_going: bool = False) -> list:
    """Runs the cases (those of `shard`) and returns their CaseResults in case order.

    workers: local processes (default: all cores; 1 runs in this process). scheduler:
    a Dask scheduler address ('tcp://host:8786'), a distributed.Client or a
    LocalCluster; then the runs go to its workers and `workers` is ignored.
    keep_going: a case that raises becomes a CaseResult with `error` set; otherwise
    the first failure raises RuntimeError naming the case.
    """
    cases = list(cases)
    for k, c in enumerate(cases):
        if not isinstance(c, Case):
            raise TypeError('cases[%d]: expected nscd_sim.study.Case, got %s' % (k, type(c).__name__))
    if not callable(extract):
        raise TypeError('extract must be callable: extract(record, sim) -> figures')
    jobs = [(k, cases[k], extract, keep_going) for k in shard_indices(len(cases), shard)]
    if scheduler is not None:
        return _run_dask(jobs, scheduler)
    if workers is None:  # the cores this process may use
        workers = len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else os.cpu_count() or 1
    if not isinstance(workers, int) or workers < 1:
        raise ValueError('workers must be an integer >= 1 (got %r)' % (workers,))
    if workers == 1 or len(jobs) <= 1:
        return [_run_indexed(j) for j in jobs]
    with concurrent.futures.ProcessPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
        return list(pool.map(_run_indexed, jobs))  # map keeps the order of jobs


def _run_dask(jobs, scheduler) -> list:
    import distributed
    if isinstance(scheduler, distributed.Client):
        client, own = scheduler, False
    else:
        client, own = distributed.Client(scheduler), True  # address or cluster object
    # Dask pickles with the standard pickle first, which sends functions by name: an
    # extract() defined in a study file a worker cannot import must travel by value.
    import cloudpickle
    jobs = [(k, case, cloudpickle.dumps(extract), keep_going) for k, case, extract, keep_going in jobs]
    try:
        futures = client.map(_run_indexed_pickled_extract, jobs, pure=False)
        return client.gather(futures)  # in the order of `futures`
    finally:
        if own:
            client.close()


def merge_results(*shards: Sequence[CaseResult]) -> list:
    """Joins the results of several shards into one list sorted by case index."""
    merged = sorted((r for s in shards for r in s), key=lambda r: r.index)
    for a, b in zip(merged, merged[1:]):
        if a.index == b.index:
            raise ValueError('case %d appears in two shards' % a.index)
    return merged


def _load_study(path: str):
    spec = importlib.util.spec_from_file_location('nscd_study_' + os.path.basename(path).split('.')[0], path)
    if spec is None or spec.loader is None:
        raise SystemExit('nscd_sim.study: %s: not a Python file' % path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    for name in ('CASES', 'extract'):
        if not hasattr(module, name):
            raise SystemExit('nscd_sim.study: %s defines no %s' % (path, name))
    try:  # Dask workers cannot import the study file: its functions travel by value
        import cloudpickle
        cloudpickle.register_pickle_by_value(module)
    except (ImportError, AttributeError):
        pass
    return module


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog='python3 -m nscd_sim.study', description=__doc__.split('\n')[0])
    ap.add_argument('study', nargs='?', help='a Python file defining CASES and extract(record, sim)')
    ap.add_argument('--workers', type=int, default=None, help='local processes (default: all cores)')
    ap.add_argument('--scheduler', default=None, help='Dask scheduler address, e.g. tcp://host:8786')
    ap.add_argument('--shard', default='0/1', help='run only the cases k with k mod n == i (i/n)')
    ap.add_argument('--keep-going', action='store_true', help='a failed case is a result, not an exit')
    ap.add_argument('--out', default=None, help='write the CaseResults to this pickle file')
    ap.add_argument('--merge', nargs='+', metavar='PKL', help='merge shard pickles (into --out)')
    a = ap.parse_args(argv)
    if a.merge:
        shards = []
        for p in a.merge:
            with open(p, 'rb') as f:
                shards.append(pickle.load(f))
        results = merge_results(*shards)
    else:
        if not a.study:
            ap.error('a study file is required (or --merge)')
        try:
            shard = parse_shard(a.shard)
        except ValueError as e:
            ap.error(str(e))
        study = _load_study(a.study)
        t0 = time.perf_counter()
        results = run_study(study.CASES, study.extract, workers=a.workers, scheduler=a.scheduler,
                            shard=shard, keep_going=a.keep_going)
        print('nscd_sim.study: %d cases in %.2f s' % (len(results), time.perf_counter() - t0),
              file=sys.stderr)
    if a.out:
        with open(a.out, 'wb') as f:
            pickle.dump(results, f)
    else:
        for r in results:
            print(r.index, r.error if r.error else r.value)
    return 0


if __name__ == '__main__':
    # Through the package, so what travels to workers is nscd_sim.study's, not __main__'s.
    from nscd_sim.study import main as _main
    sys.exit(_main())
