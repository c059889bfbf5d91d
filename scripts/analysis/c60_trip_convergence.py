#!/usr/bin/python3
"""Work-precision of the C-60 trip: the trip's figures against the time step.

  c60_trip_convergence.py [--scene urdf/c60.urdf] [--dts 1e-4,...] [--ref 5e-7] [--out DIR]

Runs the trip (probe at 0.2 m/s from 0.7 ms, 20.7 ms) at each dt and at the
reference dt, every step in the CSV, and prints per dt: the probe's touch (not in
the error: it is where the friction-held rest left the bar), the latch release time,
the C7 opening time (both counted from the probe's start at 0.7 ms), the mean
tripping force while the probe is in contact, the peak of its 0.1-ms running mean
(so that steps of any size compare impulse for impulse), each as
scripts/analysis/c60_trip_figures.py defines it, their relative errors against the
reference, the wall time and the real-time factor. The recommended dt is the largest whose four figures are all within 1 %.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import c60_plot  # noqa: E402
import c60_trip_figures  # noqa: E402

T0 = 0.0007
PROBE = 'probe=0:0,0.0007:0,0.0207:0.004'


def figures(csv):
    """The four figures of the work-precision, as scripts/analysis/c60_trip_figures.py defines them."""
    f = c60_trip_figures.figures(c60_plot.load(csv))
    s = lambda key: None if f.get(key) is None else 1e-3 * f[key]  # noqa: E731
    return {'touch_s': s('touch_ms'), 'release_s': s('release_ms'), 'c7_open_s': s('c7_open_ms'),
            'mean_push_N': f.get('force_mean_N') if f.get('force_mean_N') is not None else float('nan'),
            'peak_0.1ms_N': f.get('force_peak_0p1ms_N') if f.get('force_peak_0p1ms_N') is not None else float('nan')}


def run(scene, dt, out):
    csv = os.path.join(out, 'trip_%g.csv' % dt)
    exe = os.environ.get('NSCD_RUN', os.path.join(os.environ.get('NSCD_WS', 'build/ws'), 'devel/lib/nscd_sim/nscd_run'))
    w0 = time.time()
    r = subprocess.run([exe, scene, '--duration', '0.0207', '--dt', repr(dt), '--command', PROBE,
                        '--csv', csv, '--quiet'], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit('nscd_run failed at dt %g: %s' % (dt, r.stderr.strip()))
    info = json.loads(r.stdout.strip().splitlines()[-1])
    f = figures(csv)
    os.remove(csv)
    f.update(dt=dt, wall_s=info['wall_s'], rtf=info['rtf'], unconverged=info['unconverged_steps'])
    return f


def main():
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=os.path.join(repo, 'urdf/c60.urdf'))
    ap.add_argument('--dts', default='1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6')
    ap.add_argument('--ref', type=float, default=5e-7)
    ap.add_argument('--out', default=os.path.join(repo, 'out'))
    ap.add_argument('--json')
    a = ap.parse_args()
    os.environ.setdefault('NSCD_WS', os.path.join(repo, '.build/ws'))
    os.makedirs(a.out, exist_ok=True)
    dts = [float(s) for s in a.dts.split(',')]
    rows = []
    for dt in dts + [a.ref]:
        print('dt %g ...' % dt, file=sys.stderr, flush=True)
        rows.append(run(a.scene, dt, a.out))
    ref = rows[-1]
    keys = [('release_s', True), ('c7_open_s', True), ('mean_push_N', False), ('peak_0.1ms_N', False)]

    def err(r, key, is_time):
        if r[key] is None or ref[key] is None:
            return float('inf')
        if is_time:
            return abs(r[key] - ref[key]) / (ref[key] - T0)
        return abs(r[key] - ref[key]) / abs(ref[key])

    print('| dt | touch ms | release ms | C7 opens ms | mean push N | peak 0.1 ms N | worst rel. error | unconverged | wall s | rtf |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    best = None
    for r in rows:
        e = max(err(r, k, it) for k, it in keys)
        r['worst_rel_error'] = e
        fmt = lambda v: ('%.4f' % (1e3 * v)) if v is not None else '-'
        print('| %g%s | %s | %s | %s | %.3f | %.3f | %s | %d | %.2f | %.4f |' % (
            r['dt'], ' (ref)' if r is ref else '', fmt(r['touch_s']), fmt(r['release_s']), fmt(r['c7_open_s']),
            r['mean_push_N'], r['peak_0.1ms_N'], '-' if r is ref else '%.2g' % e, r['unconverged'],
            r['wall_s'], r['rtf']))
        if r is not ref and e <= 0.01 and (best is None or r['dt'] > best['dt']):
            best = r
    if best:
        print('\nlargest dt with every figure within 1 %% of dt %g: %g (rtf %.4f)' % (a.ref, best['dt'], best['rtf']))
    else:
        print('\nno dt within 1 % of the reference')
    if a.json:
        with open(a.json, 'w') as f:
            json.dump({'rows': rows, 'recommended_dt': best['dt'] if best else None}, f, indent=1)


if __name__ == '__main__':
    main()
