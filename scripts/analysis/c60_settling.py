#!/usr/bin/python3
"""Why the C-60 trip's touch and push converge slowly with dt: the settling
(docs/c60_convergence.md). Two commands, both on the trip's schedule (probe at
0.2 m/s from 0.7 ms; urdf/c60.urdf):

  c60_settling.py settle [--dts 1e-5,...] [--until 0.0046]
      For each fixed dt, the settling from the published ON pose up to `until`
      (the probe moving, the bar at rest, before the touch): the tripping bar's
      yaw relative to the plate at 0.2, 0.5, 1 and 2 ms and at `until`, the last
      time the bar turns or rocks faster than 1e-3 rad/s, the largest kinetic
      energy, TRIP's gap at `until` and the touch it gives (until + gap / 0.2 m/s).

  c60_settling.py branch [--from-dt 2.5e-8] [--at 0.0046] [--fixed 2e-5,1e-5,...]
                         [--adaptive 1e-2,1e-3] [--atol-ratio 1e-3] [--ref 5e-8]
      One settled state (a run at --from-dt to --at, pickled in
      .build/c60_settled_<dt>_<at>.pickle), then the trip continued from it to
      20.7 ms with each step control: the four figures of
      scripts/analysis/c60_trip_accuracy.py against the continuation at fixed
      --ref (to 10 ms), the steps and the wall time of the continuation (a second
      run that records nothing).

Needs the Python module of the build (.build/ws/devel/lib/python3/dist-packages).
"""
import argparse
import os
import pickle
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(REPO, '.build/ws/devel/lib/python3/dist-packages'))
import c60_csv  # noqa: E402
import c60_trip_accuracy as acc  # noqa: E402
import nscd_sim  # noqa: E402

SCENE = os.path.join(REPO, 'urdf/c60.urdf')
PROBE_SPEED = 0.2  # m/s
END = 0.0207


def simulator(settings):
    return nscd_sim.Simulator(SCENE, settings=settings, commands=acc.PROBE)


def fixed(dt):
    return {'dt': dt}


def adaptive(rtol, atol, dt_max):
    return {'dt': dt_max, 'step_control': 'adaptive', 'rtol': rtol, 'atol': atol}


def settle(a):
    print('| dt | bar yaw − plate yaw at 0.2 / 0.5 / 1 / 2 ms [deg] | at %.1f ms [deg] | bar still from [ms] | '
          'largest kinetic energy [mJ] | TRIP gap at %.1f ms [um] | touch [ms] | wall [s] |' % (1e3 * a.until, 1e3 * a.until))
    print('|---|---|---|---|---|---|---|---|')
    for dt in [float(s) for s in a.dts.split(',')]:
        sim = simulator(fixed(dt))
        w0 = time.perf_counter()
        r = sim.run(a.until, every=max(1, int(round(1e-6 / dt))))
        wall = time.perf_counter() - w0
        t = r['t']
        rel = np.degrees(c60_csv.yaw(r, 'trip_bar') - c60_csv.yaw(r, 'plate'))
        rel -= rel[0]
        w = np.sqrt(r['trip_bar.wx'] ** 2 + r['trip_bar.wy'] ** 2 + r['trip_bar.wz'] ** 2)
        moving = np.nonzero(w > 1e-3)[0]
        at = lambda s: rel[min(np.searchsorted(t, s - 1e-12), len(t) - 1)]  # noqa: E731
        gap = float(r['TRIP.gap'][-1])
        print('| %g | %.3f / %.3f / %.3f / %.3f | %.3f | %.2f | %.2f | %.1f | %.4f | %.1f |' % (
            dt, at(2e-4), at(5e-4), at(1e-3), at(2e-3), rel[-1], 1e3 * t[moving[-1]] if len(moving) else 0,
            1e3 * float(np.max(r['energy_kinetic'])), 1e6 * gap, 1e3 * (a.until + gap / PROBE_SPEED), wall), flush=True)


def trip_columns(records):
    """The columns c60_trip_accuracy.figures reads, from the Python module's records."""
    c4 = [n for n in records[0].dtype.names if n.endswith('.gap') and (n == 'C4.gap' or n.startswith('C4_'))]
    d = {k: np.concatenate([r[k] for r in records]) for k in ('t', 'probe.cmd', 'probe.effort', 'TRIP.gap', 'C7.gap')}
    d['C4.min_gap'] = np.concatenate([np.min(np.vstack([r[n] for n in c4]), axis=0) for r in records])
    if 'h' in records[0].dtype.names:
        d['h'] = np.concatenate([r['h'] for r in records])
    return d


def continue_from(state, settings, until, record=True):
    sim = simulator(settings)
    sim.set_state(state)
    if not record:
        w0 = time.perf_counter()
        sim.run(until - state.t, every=10 ** 9, include_start=False)
        return time.perf_counter() - w0, None, None
    records, steps, rejected, unconverged = [], 0, 0, 0
    while sim.time < until - 1e-12:
        r = sim.run(min(2e-4, until - sim.time), every=1, include_start=False)
        records.append(r)
        steps += len(r)
        rejected += int(np.sum(r['rejected'])) if 'rejected' in r.dtype.names else 0
        unconverged += int(np.sum(~r['converged']))
    return (steps, rejected, unconverged), acc.figures(trip_columns(records)), None


def settled_state(a):
    path = os.path.join(REPO, '.build', 'c60_settled_%g_%g.pickle' % (a.from_dt, a.at))
    if os.path.exists(path):
        with open(path, 'rb') as f:
            return pickle.load(f)
    print('settling at dt %g to %g s ...' % (a.from_dt, a.at), file=sys.stderr, flush=True)
    sim = simulator(fixed(a.from_dt))
    sim.run(a.at, every=10 ** 9, include_start=False)
    s = sim.state()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'wb') as f:
        pickle.dump(s, f)
    return s


def branch(a):
    s = settled_state(a)
    print('reference: fixed dt %g from the state at %.2f ms ...' % (a.ref, 1e3 * s.t), file=sys.stderr, flush=True)
    _, ref, _ = continue_from(s, fixed(a.ref), 0.010)
    cases = [('fixed dt %g' % v, fixed(v)) for v in (float(x) for x in a.fixed.split(',') if x)] + \
            [('adaptive rtol %g, atol %g' % (v, v * a.atol_ratio), adaptive(v, v * a.atol_ratio, a.adaptive_dt))
             for v in (float(x) for x in a.adaptive.split(',') if x)]
    print('settled state: fixed dt %g to %.2f ms; reference: fixed dt %g from it: touch %.4f ms, mean push %.4f N, '
          'release %.4f ms, C7 opens %.4f ms' % (a.from_dt, 1e3 * s.t, a.ref, 1e3 * ref['touch_s'], ref['mean_push_N'],
                                                 1e3 * ref['release_s'], 1e3 * ref['c7_open_s']))
    print()
    print('| from the settled state | steps (rejected) | wall to 20.7 ms [s] | touch | mean push | release | C7 opens '
          '| worst | unconverged |')
    print('|---|---|---|---|---|---|---|---|---|')
    for label, settings in cases:
        print('%s ...' % label, file=sys.stderr, flush=True)
        (steps, rejected, unconverged), f, _ = continue_from(s, settings, END)
        wall, _, _ = continue_from(s, settings, END, record=False)
        e = acc.rel_errors(f, ref)
        pct = lambda x: '%.2f %%' % (100 * x)  # noqa: E731
        print('| %s | %d (%d) | %.3f | %s | %s | %s | %s | %s | %d |' % (
            label, steps, rejected, wall, pct(e['touch_s']), pct(e['mean_push_N']), pct(e['release_s']),
            pct(e['c7_open_s']), pct(max(e.values())), unconverged), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest='cmd', required=True)
    p = sub.add_parser('settle')
    p.add_argument('--dts', default='1e-5,5e-6,2e-6,1e-6,5e-7,2e-7,1e-7,5e-8,2.5e-8')
    p.add_argument('--until', type=float, default=0.0046)
    p = sub.add_parser('branch')
    p.add_argument('--from-dt', type=float, default=2.5e-8)
    p.add_argument('--at', type=float, default=0.0046)
    p.add_argument('--fixed', default='4e-5,2e-5,1e-5,5e-6,1e-6')
    p.add_argument('--adaptive', default='')
    p.add_argument('--atol-ratio', type=float, default=1e-3)
    p.add_argument('--adaptive-dt', type=float, default=1e-5)
    p.add_argument('--ref', type=float, default=5e-8)
    a = ap.parse_args()
    settle(a) if a.cmd == 'settle' else branch(a)


if __name__ == '__main__':
    main()
