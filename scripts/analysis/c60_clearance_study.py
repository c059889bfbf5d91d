#!/usr/bin/python3
"""The seed paper's question on the C-60: how radial clearance, axial play and the
journals' initial positions change the breaker.

  c60_clearance_study.py [run] [--jobs N] [--shard i/n] [--out DIR] [--cases a,b,c]
                         [--backend module|cli|sweep] [--scheduler ADDR | --local-cluster]
  c60_clearance_study.py report [--out DIR] [--doc docs/c60_clearance_study.md]
  c60_clearance_study.py list

Cases: (a) radial clearance x0 (ideal joints), 0.021 mm in J1-J7 (the authors'
value), the paper's values (nominal), x2; (b) axial play x0.5, x1, x2; (c) 20 runs
with the journals starting at random positions inside their clearances (seeds
1-20, `c60_scene.py --journal-seed`). Each case is a trip (probe at 0.2 m/s from
0.7 ms, 20.7 ms) and a bench (scripts/c60_bench.sh's table, 2 mm and back) of the
scene variant that scripts/c60_model/c60_scene.py writes; figures as c60_trip_figures.py and
c60_plot.py (bench) define them, plus each joint's polarisation (e/c_r, direction)
and out-of-plane tilt (angle between journal and bore axes) at rest before the
probe arrives and at 2 mm on the bench.

`run` runs the cases of its shard (case k with k mod n == i) on --jobs workers
(default: every core), each case's figures into OUT/study_CASE.json; `report`
collects every JSON there into the markdown table and box plots. Without a
command: run, then report. Progress on standard error.

Backends: `module` (default when the Python module is built): the runs go through
`nscd_sim.study.run_study` in worker processes, or to a Dask cluster with
`--scheduler tcp://HOST:8786` (its workers need this repository's scripts/ on
PYTHONPATH, the built module, and OUT on a shared file system) or
`--local-cluster` (a Dask LocalCluster of --jobs workers on this machine); `cli`:
each run is an `nscd_run` process, --jobs at a time; `sweep`: the trips in one
`nscd_sweep --scenes ... --command PROBE --series DIR --every 1` call and the benches
in another, on --jobs threads; every figure is computed from the series CSVs
(nscd_run's --csv format) by the same functions as the cli backend, in --jobs
processes, each run's as soon as nscd_sweep reports it done. `--shard i/n` is passed to nscd_sweep: its run k is the k-th selected
case (CASES order, --cases applied first), so without --cases a shard runs the same
cases as with the other backends; shards of one OUT may run at once (each writes the
scene files atomically, and only its own runs' series and study_CASE.json). The
sweep backend finds nscd_sweep beside nscd_run (or set NSCD_SWEEP). The figures are
the same whatever the backend, up to the CSV's 12 significant digits that the cli
and sweep backends read back (those two agree to the last digit).
"""
import argparse
import concurrent.futures as cf
import csv as csvlib
import json
import math
import os
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'c60_model'))
import c60_plot  # noqa: E402
import c60_scene  # noqa: E402
import c60_trip_figures  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
PROBE = 'probe=0:0,0.0007:0,0.0207:0.004'
TRIP_DURATION = 0.0207
BENCH_DURATION = 0.054
SEEDS = list(range(1, 21))
# name, group, label, c60_scene.build keyword arguments
CASES = ([('r0', 'a', 'radial x0 (ideal joints)', {'cscale': 0.0}),
          ('r021', 'a', 'radial 0.021 mm (J1-J7)', {'radial_mm': 0.021}),
          ('nominal', 'a', 'nominal (paper clearances)', {}),
          ('r2', 'a', 'radial x2', {'radial_scale': 2.0}),
          ('a05', 'b', 'axial x0.5', {'axial_scale': 0.5}),
          ('a2', 'b', 'axial x2', {'axial_scale': 2.0})] +
         [('s%02d' % s, 'c', 'journals at random, seed %d' % s, {'journal_seed': s}) for s in SEEDS])
JOINT_BODIES = {j[0]: (j[1], j[2]) for j in c60_scene.JOINTS}


def table_command():
    """The bench's table schedule, as scripts/c60_env.sh writes it."""
    out = subprocess.run(['bash', '-c', 'source "%s/scripts/c60_env.sh" >/dev/null && echo "$C60_TABLE"' % REPO],
                         capture_output=True, text=True, check=True)
    return out.stdout.strip()


def nscd_run():
    exe = os.environ.get('NSCD_RUN', os.path.join(REPO, '.build/ws/devel/lib/nscd_sim/nscd_run'))
    if not os.path.exists(exe):
        sys.exit('nscd_run not found at %s: run scripts/build.sh first (or set NSCD_RUN)' % exe)
    return exe


def nscd_sweep():
    exe = os.environ.get('NSCD_SWEEP') or os.path.join(os.path.dirname(nscd_run()), 'nscd_sweep')
    if not os.path.exists(exe):
        sys.exit('nscd_sweep not found at %s: run scripts/build.sh first (or set NSCD_SWEEP)' % exe)
    return exe


def axis_z(d, body, i):
    if body == 'world':
        return np.array([0.0, 0.0, 1.0])
    qw, qx, qy, qz = (float(d[body + '.q' + c][i]) for c in 'wxyz')
    return np.array([2 * (qx * qz + qw * qy), 2 * (qy * qz - qw * qx), 1 - 2 * (qx * qx + qy * qy)])


def polarisation(d, i):
    """Per joint at row i: e/c_r, direction (world, deg) and tilt (deg) of journal vs bore."""
    pol = c60_plot.polarisation(d, i)
    for j, p in pol.items():
        a, b = (axis_z(d, body, i) for body in JOINT_BODIES[j])
        p['tilt_deg'] = round(math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))), 5)
    return pol


def run_one(exe, scene, duration, command, csv, every):
    r = subprocess.run([exe, scene, '--duration', repr(duration), '--command', command, '--csv', csv,
                        '--every', str(every), '--quiet'], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError('%s: %s' % (os.path.basename(scene), r.stderr.strip()))
    return json.loads(r.stdout.strip().splitlines()[-1])


RUN_KEYS = ('steps', 'wall_s', 'iters_mean', 'iters_max', 'unconverged_steps', 'frictionless_fallbacks',
            'max_penetration', 'energy_initial', 'energy_final')


def trip_figures(d):
    """The trip's figures and the polarisation at t = 0 and at rest before the touch."""
    fig = c60_trip_figures.figures(d)
    t = d['t']
    touch = 1e-3 * fig['touch_ms'] if fig.get('touch_ms') else c60_trip_figures.T_PROBE
    # Integrity: the first time a journal stands outside its bearing (e/c_r > 1.1:
    # the joint came apart; the projection then snaps it back, adding energy).
    ecc = np.max(np.vstack([d[j + '.ecc'] for j in c60_plot.JOINTS if j + '.ecc' in d.dtype.names] +
                           [np.zeros(len(t))]), axis=0)
    broken = np.nonzero(ecc > 1.1)[0]
    fig['joint_apart_ms'] = 1e3 * float(t[broken[0]]) if len(broken) else None
    # How far the latch starts open (the nose above the seat F4, or the corner): the
    # journal offsets close the loop with the links turned.
    fig['latch_gap_initial_um'] = 1e6 * float(c60_plot.group_gap(d, 'C4')[0])
    fig['hook_yaw_initial_rad'] = float(c60_plot.yaw(d, 'hook')[0])
    return {'trip': fig, 'polarisation_initial': polarisation(d, 0),
            # The last row before the touch, with half a sample of slack: the touch time
            # comes back from ms, and a CSV's t and the module's differ in the last digit.
            'polarisation_rest': polarisation(d, int(np.nonzero(t < touch - 0.5 * float(np.median(np.diff(t))))[0][-1]))}


def bench_figures(d):
    b = c60_plot.bench(d, None)
    i_eq = int(np.argmin(np.abs(d['t'] - (0.030 - 1e-3))))  # end of the hold at 2 mm
    fig = {k: b[k] for k in ('equilibrium_force_N', 'hysteresis_mean_N', 'hysteresis_max_N', 'hold_steps_averaged',
                             'hold_zero_force_steps')}
    # The bench measures a latched breaker: if the latch is open at 2 mm (every C4 pair
    # > 20 um: it did not hold through the settling), its forces are not bench figures.
    fig['latch_open_at_2mm'] = bool(c60_plot.group_gap(d, 'C4')[i_eq] > c60_trip_figures.RELEASE_GAP)
    if fig['latch_open_at_2mm']:
        fig.update({k: None for k in ('equilibrium_force_N', 'hysteresis_mean_N', 'hysteresis_max_N')})
    return {'bench': fig, 'polarisation_2mm': polarisation(d, i_eq)}


def write_scenes(case, out):
    name, _, _, kw = case
    paths = {}
    for kind in ('trip', 'bench'):
        paths[kind] = os.path.join(out, 'study_%s_%s.urdf' % (name, kind))
        # Atomically: sweep shards of one OUT write the same files and read them at once.
        tmp = '%s.%d.tmp' % (paths[kind], os.getpid())
        with open(tmp, 'w') as f:
            f.write(c60_scene.build(bench=kind == 'bench', **kw))
        os.replace(tmp, paths[kind])
    return paths


def case_header(case):
    name, group, label, kw = case
    return {'case': name, 'group': group, 'label': label, 'scene_args': kw}


def run_case(case, out, exe, table):
    """The cli backend: one case, its trip and bench as nscd_run processes."""
    t0 = time.time()
    res = case_header(case)
    scenes = write_scenes(case, out)
    for kind in ('trip', 'bench'):
        csv = os.path.join(out, 'study_%s_%s.csv' % (case[0], kind))
        if kind == 'trip':
            run = run_one(exe, scenes[kind], TRIP_DURATION, PROBE, csv, 1)
            res.update(trip_figures(c60_plot.load(csv)))
        else:
            run = run_one(exe, scenes[kind], BENCH_DURATION, table, csv, 1)
            res.update(bench_figures(c60_plot.load(csv)))
        res[kind + '_run'] = {k: run[k] for k in RUN_KEYS}
        os.remove(csv)
    res['wall_s'] = time.time() - t0
    with open(os.path.join(out, 'study_%s.json' % case[0]), 'w') as f:
        json.dump(res, f, indent=1)
    return res


def module_extract(record, sim):
    """The module backend's extract(): a run's figures and statistics, in a worker."""
    stats = record['converged']
    run = {'steps': int(sim.steps), 'iters_mean': float(np.mean(record['iters'][1:])),
           'iters_max': int(np.max(record['iters'])), 'unconverged_steps': int(np.sum(~stats[1:].astype(bool))),
           'frictionless_fallbacks': int(np.sum(record['frictionless_fallback'])),
           'max_penetration': float(np.max(record['max_penetration']))}
    energy = record['energy_kinetic'] + record['energy_gravity'] + record['energy_springs']
    run.update(energy_initial=float(energy[0]), energy_final=float(energy[-1]))
    figs = bench_figures(record) if 'table.cmd' in record.dtype.names else trip_figures(record)
    return figs, run


def run_module(cases, a):
    """The module backend: every trip and bench as nscd_sim.study Cases."""
    from nscd_sim import study
    jobs = []
    for c in cases:
        scenes = write_scenes(c, a.out)
        jobs.append(study.Case(scenes['trip'], TRIP_DURATION, commands=PROBE, every=1, label=c[0] + ' trip'))
        jobs.append(study.Case(scenes['bench'], BENCH_DURATION, commands=table_command(), every=1,
                               label=c[0] + ' bench'))
    scheduler = a.scheduler
    cluster = None
    if a.local_cluster:
        import distributed
        os.environ['PYTHONPATH'] = os.pathsep.join([HERE, os.path.join(REPO, 'scripts', 'c60_model'),
                                              os.environ.get('PYTHONPATH', '')])  # for the workers
        cluster = distributed.LocalCluster(n_workers=a.jobs, threads_per_worker=1, dashboard_address=None)
        scheduler = cluster
    try:
        results = study.run_study(jobs, module_extract, workers=a.jobs, scheduler=scheduler, keep_going=True)
    finally:
        if cluster is not None:
            cluster.close()
    failed = []
    for k, c in enumerate(cases):
        res = case_header(c)
        for kind, r in (('trip', results[2 * k]), ('bench', results[2 * k + 1])):
            if r.error:
                failed.append('%s %s: %s' % (c[0], kind, r.error))
                break
            figs, run = r.value
            run['wall_s'] = r.wall_s
            res.update(figs)
            res[kind + '_run'] = run
        else:
            res['wall_s'] = results[2 * k].wall_s + results[2 * k + 1].wall_s
            with open(os.path.join(a.out, 'study_%s.json' % c[0]), 'w') as f:
                json.dump(res, f, indent=1)
    return failed


def sweep_run_results(kind, k, out):
    """The sweep backend: run k's figures and statistics from its series and JSON line,
    as run_case() gets them from nscd_run; removes both files. Runs in a worker process."""
    stem = os.path.join(out, 'sweep_' + kind, 'run_%d' % k)
    with open(stem + '.json') as f:
        run = json.loads(f.read().strip())
    d = c60_plot.load(stem + '.csv')
    figs = trip_figures(d) if kind == 'trip' else bench_figures(d)
    os.remove(stem + '.csv')
    os.remove(stem + '.json')
    return figs, {q: run[q] for q in RUN_KEYS}


def run_sweep(selected, a):
    """The sweep backend: the trips of every selected case in one nscd_sweep call (this
    shard of them), the benches in another; each run's figures computed in a worker as
    soon as nscd_sweep reports the run done (its --progress line), so the figures of
    the first runs overlap the later runs; then each case's study_CASE.json. Returns
    the failed runs."""
    exe, table = nscd_sweep(), table_command()
    scenes = [write_scenes(c, a.out) for c in selected]
    i, n = (int(v) for v in a.shard.split('/'))
    mine = [k for k in range(len(selected)) if k % n == i]
    t0 = time.time()
    errors, results, futs = {}, {}, {}  # (kind, k) -> message / (figures, run statistics) / future
    done_line = re.compile(r': run (\d+) \(.*\) ok in ')

    def report(fut, kind, k):  # progress as each run's figures are done
        e = fut.exception()
        print('study: %s %s: %s (%.0f s elapsed)' % (selected[k][0], kind, 'figures' if e is None else 'FAILED: %s' % e,
                                                     time.time() - t0), file=sys.stderr, flush=True)

    def submit(pool, kind, k):
        if (kind, k) in futs:
            return
        fut = futs[kind, k] = pool.submit(sweep_run_results, kind, k, a.out)
        fut.add_done_callback(lambda fut: report(fut, kind, k))

    def run(pool, kind, duration, command):
        print('study: %d %s runs through nscd_sweep (shard %s, %d threads)' % (len(mine), kind, a.shard, a.jobs),
              file=sys.stderr, flush=True)
        stats = os.path.join(a.out, 'sweep_%s_shard%dof%d.csv' % (kind, i, n))
        proc = subprocess.Popen([exe, '--scenes'] + [p[kind] for p in scenes] +
                                ['--command', command, '--duration', repr(duration), '--series',
                                 os.path.join(a.out, 'sweep_' + kind), '--every', '1', '--jobs', str(a.jobs),
                                 '--shard', a.shard, '--csv', stats, '--progress'],
                                stderr=subprocess.PIPE, text=True)
        for line in proc.stderr:  # nscd_sweep's progress, passed on; a finished run's series is complete
            sys.stderr.write(line)
            sys.stderr.flush()
            m = done_line.search(line)
            if m:
                submit(pool, kind, int(m.group(1)))
        if proc.wait() != 0:
            sys.exit('nscd_sweep failed (status %d) for the %s runs' % (proc.returncode, kind))
        with open(stats) as f:  # the statuses (and any run whose line was missed)
            for row in csvlib.DictReader(f):
                if row['status'] != 'ok':
                    errors[kind, int(row['run'])] = row['status']
                else:
                    submit(pool, kind, int(row['run']))

    with cf.ProcessPoolExecutor(max_workers=a.jobs) as pool:
        run(pool, 'trip', TRIP_DURATION, PROBE)
        run(pool, 'bench', BENCH_DURATION, table)
        for key, fut in futs.items():
            try:
                results[key] = fut.result()
            except Exception as e:  # noqa: BLE001  (a failed case is reported, the others go on)
                errors[key] = str(e)
    failed = []
    for k in mine:
        c = selected[k]
        bad = ['%s %s: %s' % (c[0], kind, errors[kind, k]) for kind in ('trip', 'bench') if (kind, k) in errors]
        if bad:
            failed += bad
            continue
        res = case_header(c)
        for kind in ('trip', 'bench'):
            figs, stats = results[kind, k]
            res.update(figs)
            res[kind + '_run'] = stats
        res['wall_s'] = res['trip_run']['wall_s'] + res['bench_run']['wall_s']
        with open(os.path.join(a.out, 'study_%s.json' % c[0]), 'w') as f:
            json.dump(res, f, indent=1)
    for kind in ('trip', 'bench'):
        try:
            os.rmdir(os.path.join(a.out, 'sweep_' + kind))  # empty unless a run failed or a shard still runs
        except OSError:
            pass
    return failed


def do_run(a):
    i, n = (int(v) for v in a.shard.split('/'))
    if not (n >= 1 and 0 <= i < n):
        sys.exit('--shard must be i/n with 0 <= i < n, got %s' % a.shard)
    cases = [c for k, c in enumerate(CASES) if k % n == i]
    selected = CASES
    if a.cases:
        want = set(a.cases.split(','))
        unknown = want - {c[0] for c in CASES}
        if unknown:
            sys.exit('unknown case(s): %s (see: c60_clearance_study.py list)' % ', '.join(sorted(unknown)))
        cases = [c for c in cases if c[0] in want]
        selected = [c for c in CASES if c[0] in want]
    if a.backend == 'sweep':  # nscd_sweep shards the selected cases (see the help)
        cases = [c for k, c in enumerate(selected) if k % n == i]
    os.makedirs(a.out, exist_ok=True)
    t0 = time.time()
    failed = []
    if a.backend == 'sweep':
        failed = run_sweep(selected, a)
    elif a.backend == 'module':
        print('study: %d cases (%d runs) through nscd_sim.study on %s' % (
            len(cases), 2 * len(cases), a.scheduler or ('a LocalCluster of %d workers' % a.jobs if a.local_cluster
                                                        else '%d processes' % a.jobs)), file=sys.stderr, flush=True)
        failed = run_module(cases, a)
    else:
        exe, table = nscd_run(), table_command()
        with cf.ThreadPoolExecutor(max_workers=a.jobs) as pool:  # each worker waits on an nscd_run process
            futs = {pool.submit(run_case, c, a.out, exe, table): c[0] for c in cases}
            for k, fut in enumerate(cf.as_completed(futs), 1):
                try:
                    r = fut.result()
                    print('[%d/%d] %s: %.0f s (%.0f s elapsed)' % (k, len(cases), futs[fut], r['wall_s'],
                                                                 time.time() - t0), file=sys.stderr, flush=True)
                except Exception as e:  # noqa: BLE001  (a failed case is reported, the others go on)
                    failed.append(futs[fut])
                    print('[%d/%d] %s FAILED: %s' % (k, len(cases), futs[fut], e), file=sys.stderr, flush=True)
    wall = time.time() - t0
    with open(os.path.join(a.out, 'study_wall_shard%d_of_%d.json' % (i, n)), 'w') as f:
        json.dump({'wall_s': wall, 'jobs': a.jobs, 'cases': len(cases), 'failed': failed, 'backend': a.backend,
                   'where': a.scheduler or ('LocalCluster' if a.local_cluster else 'local')}, f)
    print('study shard %d/%d: %d cases on %d workers in %.0f s%s' % (
        i, n, len(cases), a.jobs, wall, '' if not failed else '; FAILED: ' + ', '.join(failed)), file=sys.stderr)
    return 1 if failed else 0


# --------------------------------------------------------------------------- report
def fmt(v, f='%.2f'):
    return '—' if v is None else f % v


def load_results(out):
    res = {}
    for c in CASES:
        p = os.path.join(out, 'study_%s.json' % c[0])
        if os.path.exists(p):
            with open(p) as f:
                res[c[0]] = json.load(f)
    return res


FIGS = [('bench force at 2 mm [N]', lambda r: r['bench']['equilibrium_force_N'], '%.2f'),
        ('hysteresis [N]', lambda r: r['bench']['hysteresis_mean_N'], '%.3f'),
        ('trip force mean [N]', lambda r: r['trip'].get('force_mean_N'), '%.2f'),
        ('trip force 0.1-ms peak [N]', lambda r: r['trip'].get('force_peak_0p1ms_N'), '%.2f'),
        ('touch [ms]', lambda r: r['trip'].get('touch_ms'), '%.2f'),
        ('latch release [ms]', lambda r: r['trip'].get('release_ms'), '%.2f'),
        ('C7 opens [ms]', lambda r: r['trip'].get('c7_open_ms'), '%.2f'),
        ('a joint comes apart [ms]', lambda r: r['trip'].get('joint_apart_ms'), '%.2f')]


def git_commit():
    """The repository's commit, +changes when the tree differs from it."""
    try:
        c = subprocess.run(['git', '-C', REPO, 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True,
                           check=True).stdout.strip()
        dirty = subprocess.run(['git', '-C', REPO, 'diff', '--quiet', 'HEAD', '--']).returncode != 0
        return c + ('+changes' if dirty else '')
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'


def pol_cell(p):
    return '%.2f@%.0f°' % (p['ecc'], p['dir_deg'])


def report(a):
    res = load_results(a.out)
    if not res:
        sys.exit('no study results in %s: run the study first' % a.out)
    walls = []
    for fn in sorted(os.listdir(a.out)):
        if fn.startswith('study_wall_shard'):
            with open(os.path.join(a.out, fn)) as f:
                walls.append(json.load(f))
    L = ['# The C-60 and its clearances: the seed paper\'s question, answered with data', '',
         'Generated by `scripts/analysis/c60_clearance_study.py` (run, then report) from the scene variants',
         '`scripts/c60_model/c60_scene.py` writes; every figure as `scripts/analysis/c60_trip_figures.py` (trip) and',
         '`scripts/analysis/c60_plot.py` (bench) define it. Trip: probe at 0.2 m/s from 0.7 ms, 20.7 ms,',
         'dt 1e-5. Bench: the table pushes the moving contact 2 mm off the fixed contact and back',
         '(`scripts/c60_bench.sh`). Nothing is tuned per case; the calibrated P3 preload is kept.', '',
         'Made by `scripts/analysis/c60_clearance_study.py --backend %s` (%s, commit %s).' % (
             a.backend, time.strftime('%Y-%m-%d', time.gmtime()), git_commit()), '']
    if walls:
        L.append('**Wall time of the whole study**: %s (%d cases, each a trip and a bench: %d nscd_run runs).' % (
            ' + '.join('%.0f s (shard of %d cases on %d workers)' % (w['wall_s'], w['cases'], w['jobs']) for w in walls),
            len(res), 2 * len(res)))
        L.append('')
    L += ['## (a) radial clearance and (b) axial play', '',
          '| case | ' + ' | '.join(f[0] for f in FIGS) + ' | unconverged steps trip / bench | max penetration [m] |',
          '|---|' + '---|' * (len(FIGS) + 2)]
    for c in CASES:
        if c[1] == 'c' or c[0] not in res:
            continue
        r = res[c[0]]
        L.append('| %s | %s | %d / %d | %.2g |' % (
            c[2], ' | '.join(fmt(f[1](r), f[2]) for f in FIGS), r['trip_run']['unconverged_steps'],
            r['bench_run']['unconverged_steps'], max(r['trip_run']['max_penetration'], r['bench_run']['max_penetration'])))
    L += ['', 'Axial play x1 is the nominal row.']
    for key, title in (('polarisation_rest', 'Polarisation at rest before the probe arrives'),
                       ('polarisation_2mm', 'Polarisation at 2 mm on the bench')):
        L += ['', '### %s (e/c_r @ direction, world; tilt of the journal)' % title, '',
              '| case | ' + ' | '.join(c60_plot.JOINTS) + ' |', '|---|' + '---|' * len(c60_plot.JOINTS)]
        for c in CASES:
            if c[1] == 'c' or c[0] not in res:
                continue
            p = res[c[0]][key]
            L.append('| %s | %s |' % (c[2], ' | '.join(
                (pol_cell(p[j]) + ', %.3f°' % p[j]['tilt_deg']) if j in p else 'ideal' for j in c60_plot.JOINTS)))
    seeds = [res[c[0]] for c in CASES if c[1] == 'c' and c[0] in res]
    seed_names = [c[0] for c in CASES if c[1] == 'c' and c[0] in res]
    if seeds:
        L += ['', '## (c) journals starting at random inside their clearances (%d runs)' % len(seeds), '',
              'Each journal\'s centre drawn uniformly in its bore\'s disc and its axial play',
              '(`c60_scene.py --journal-seed S`, `<clearance initial_offset>`; axial offsets conditioned',
              'on the loop closing). The nominal row is the same scene with every journal centred.', '',
              '| figure | nominal (centred) | min | median | max | spread (max - min) |', '|---|---|---|---|---|---|']
        nominal = res.get('nominal')
        for name, fn, f in FIGS:
            v = [fn(r) for r in seeds if fn(r) is not None]
            missing = len(seeds) - len(v)
            if not v:
                continue
            L.append('| %s%s | %s | %s | %s | %s | %s |' % (
                name, (' (%d runs without)' % missing) if missing else '', fmt(nominal and fn(nominal), f),
                f % min(v), f % float(np.median(v)), f % max(v), f % (max(v) - min(v))))
        self_trip = ['%s (%.2f ms)' % (n, r['trip']['self_trip_ms']) for n, r in zip(seed_names, seeds)
                     if r['trip'].get('self_trip_ms')]
        bench_open = [n for n, r in zip(seed_names, seeds) if r['bench'].get('latch_open_at_2mm')]
        gaps = [(n, r['trip']['latch_gap_initial_um']) for n, r in zip(seed_names, seeds)]
        opened = [g for g in gaps if g[1] > 1]
        turns = [abs(r['trip']['hook_yaw_initial_rad'] - nominal['trip']['hook_yaw_initial_rad']) for r in seeds] \
            if nominal and 'hook_yaw_initial_rad' in nominal['trip'] else []
        L += ['', 'At t = 0 the latch is open in %d of %d runs, by %.0f-%.0f um (%s): the journal offsets' % (
                  len(opened), len(seeds), min(g[1] for g in opened) if opened else 0,
                  max(g[1] for g in opened) if opened else 0, ', '.join('%s %.0f' % g for g in opened)),
              'close the loop with the links turned, the hook most (its pivot J3 and the rod pin J6 are 3.0 mm apart%s),' % (
                  ': up to %.0f mrad' % (1e3 * max(turns)) if turns else ''),
              'and the nose then falls onto the latch under P3.']
        L += ['', 'The breaker tripped by itself, before the probe touched the bar (C7 open by more than',
              '0.1 mm), in %d of %d trip runs%s; the latch was open at 2 mm on the bench in %d of %d%s. Those runs have' % (
                  len(self_trip), len(seeds), (': ' + ', '.join(self_trip)) if self_trip else '',
                  len(bench_open), len(seeds), (': ' + ', '.join(bench_open)) if bench_open else ''),
              'no trip (resp. bench) figures above, and their polarisation at rest (resp. at 2 mm) is',
              'left out below: they are not latched.']
        L += ['', '### Polarisation: initial (after the assembly), at rest before the probe, at 2 mm', '',
              'e/c_r median [min, max] over the runs; direction spread = the widest gap-free arc',
              'holding every run\'s direction (360° minus the largest empty arc).', '',
              '| joint | initial e/c_r | at rest e/c_r | at rest direction spread | at rest tilt max [°] | at 2 mm e/c_r | at 2 mm direction spread |',
              '|---|---|---|---|---|---|---|']
        for j in c60_plot.JOINTS:
            def col(key, field):
                # At rest / at 2 mm: latched runs only.
                held = {'polarisation_initial': lambda r: True,
                        'polarisation_rest': lambda r: not r['trip'].get('self_trip_ms'),
                        'polarisation_2mm': lambda r: not r['bench'].get('latch_open_at_2mm')}[key]
                return [r[key][j][field] for r in seeds if j in r[key] and held(r)]

            def spread(dirs):
                s = sorted(d % 360 for d in dirs)
                gaps = [b - a for a, b in zip(s, s[1:])] + [s[0] + 360 - s[-1]]
                return 360 - max(gaps)
            e0, er, e2 = col('polarisation_initial', 'ecc'), col('polarisation_rest', 'ecc'), col('polarisation_2mm', 'ecc')
            if not er:
                continue
            L.append('| %s | %.2f [%.2f, %.2f] | %.2f [%.2f, %.2f] | %.0f° | %.4f | %.2f [%.2f, %.2f] | %.0f° |' % (
                j, np.median(e0), min(e0), max(e0), np.median(er), min(er), max(er),
                spread(col('polarisation_rest', 'dir_deg')), max(col('polarisation_rest', 'tilt_deg')),
                np.median(e2), min(e2), max(e2), spread(col('polarisation_2mm', 'dir_deg'))))
        png = os.path.join(os.path.dirname(a.doc), 'images', 'c60_clearance_study.png')
        box_plots(seeds, nominal, png)
        L += ['', '![box plots of the 20 random-start runs](images/c60_clearance_study.png)', '']
    chatter = [(c[0], res[c[0]]['bench']) for c in CASES
               if c[0] in res and (res[c[0]]['bench'].get('hold_zero_force_steps') or 0) > 0]
    L += ['## Chatter on the bench', '',
          'Runs whose table force falls to 0 in some of the steps the bench force averages (the second',
          'half of the hold at 2 mm), between loaded ones: the moving contact opens and closes every',
          'other step, a step-size artefact that lowers the bench force (docs/c60.md): %s.' % (
              '; '.join('%s, %d of %d steps' % (n, b['hold_zero_force_steps'], b['hold_steps_averaged'])
                        for n, b in chatter) if chatter else 'none'), '']
    L += ['## Runs', '',
          'Per run: steps, solver iterations mean / max, unconverged steps, frictionless fallbacks,',
          'largest penetration, energy (kinetic + springs) at the start and the end. The trip\'s',
          'end energy is below its start (the probe and the handle servo do little work; the',
          'impacts after the release dissipate).', '',
          '| case | trip | bench | wall trip + bench [s] |', '|---|---|---|---|']
    for c in CASES:
        if c[0] not in res:
            continue
        r = res[c[0]]
        cell = lambda q: '%d, %.1f / %d, %d, %d, %.1e m, %.3f -> %.3f J' % (  # noqa: E731
            q['steps'], q['iters_mean'], q['iters_max'], q['unconverged_steps'], q['frictionless_fallbacks'],
            q['max_penetration'], q.get('energy_initial', float('nan')), q.get('energy_final', float('nan')))
        L.append('| %s | %s | %s | %.0f |' % (c[0], cell(r['trip_run']), cell(r['bench_run']), r['wall_s']))
    text = '\n'.join(L) + '\n'
    with open(a.doc, 'w') as f:
        f.write(text)
    print(text)


def box_plots(seeds, nominal, png):
    plt = c60_plot.plt_module()
    figs = [f for f in FIGS if not f[0].startswith('a joint')]
    fig, ax = plt.subplots(1, len(figs), figsize=(2.0 * len(figs), 3.6))
    for k, (name, fn, _) in enumerate(figs):
        v = [fn(r) for r in seeds if fn(r) is not None]
        ax[k].boxplot(v, widths=0.5)
        ax[k].plot(np.random.default_rng(k).normal(1, 0.04, len(v)), v, '.', color='C0', alpha=0.6)
        if nominal and fn(nominal) is not None:
            ax[k].axhline(fn(nominal), color='C3', lw=0.8, label='journals centred')
        ax[k].set_title(name, fontsize=8)
        ax[k].set_xticks([])
        ax[k].tick_params(labelsize=7)
    ax[0].legend(fontsize=7)
    fig.suptitle('C-60: %d runs with the journals starting at random inside their clearances' % len(seeds), fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.dirname(png), exist_ok=True)
    fig.savefig(png, dpi=100)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('command', nargs='?', choices=['run', 'report', 'list', 'all'], default='all')
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    ap.add_argument('--shard', default='0/1')
    ap.add_argument('--cases', help='comma-separated case names (default: all of the shard)')
    ap.add_argument('--out', default=os.path.join(REPO, 'out', 'clearance_study'))
    ap.add_argument('--doc', default=os.path.join(REPO, 'docs', 'c60_clearance_study.md'))
    ap.add_argument('--backend', choices=['module', 'cli', 'sweep'], default=None,
                    help='module (nscd_sim.study; default when the module imports), cli (nscd_run '
                         'processes) or sweep (two nscd_sweep calls, --shard passed through)')
    ap.add_argument('--scheduler', help='module backend: a Dask scheduler address (tcp://HOST:8786)')
    ap.add_argument('--local-cluster', action='store_true', help='module backend: a Dask LocalCluster of --jobs workers')
    a = ap.parse_args()
    if a.jobs < 1:
        sys.exit('--jobs must be >= 1')
    if a.backend is None:
        try:
            import nscd_sim  # noqa: F401
            a.backend = 'module'
        except ImportError:
            a.backend = 'cli'
    if a.backend in ('cli', 'sweep') and (a.scheduler or a.local_cluster):
        sys.exit('--scheduler and --local-cluster need the module backend')
    if a.command == 'list':
        for k, c in enumerate(CASES):
            print('%2d %-8s (%s) %s  %s' % (k, c[0], c[1], c[2], c[3]))
        return 0
    rc = 0
    if a.command in ('run', 'all'):
        rc = do_run(a)
    if a.command in ('report', 'all'):
        report(a)
    return rc


if __name__ == '__main__':
    sys.exit(main())
