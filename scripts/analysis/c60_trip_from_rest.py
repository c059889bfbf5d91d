#!/usr/bin/python3
"""The C-60 trip from a settled rest (docs/c60_convergence.md, section 3): the four
figures of issue 29 and the wall time of each step control, every run started by
`nscd_run --initial-state` from one stored State.

  c60_trip_from_rest.py [--rest-dt 2.5e-8] [--at 0.0046] [--until 0.0092] [--ref 5e-8]
                        [--fixed 2e-5,1e-5,5e-6,2e-6] [--adaptive 1e-2,1e-3] [--atol-ratio 1e-3]
                        [--adaptive-dt 1e-5] [--repeat 3] [--json OUT]

1. The rest: `nscd_run c60.urdf --dt REST_DT --duration AT --command PROBE --save-state
   .build/c60_rest_<REST_DT>_<AT>.state` (made once, kept; the trip's probe schedule, so
   the probe is moving at AT and the bar has not been touched yet).
2. The reference: the continuation from it at fixed dt --ref to --until (its figures
   kept in .build/c60_trip_from_rest_ref_<...>.json).
3. Each step control continued from the same rest to --until: the four figures from
   every step's CSV row (read through a pipe; definitions and errors of
   scripts/analysis/c60_trip_accuracy.py), then the wall: nscd_run's own wall_s
   (the stepping loop) of runs without CSV, the best of --repeat.
The caches are keyed on the scene's checksum, the settings and the engine (nscd_run and
libnscd_engine.so): a rebuilt engine makes the rest and the reference again.
"""
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import c60_trip_accuracy as acc  # noqa: E402

FIGURES = ('touch_s', 'mean_push_N', 'release_s', 'c7_open_s')


def nscd_run(exe, scene, extra, csv=False):
    """One run, its duration in `extra`; returns (its JSON line, the trip's figures or None)."""
    return acc.run(exe, scene, extra, csv=csv, duration=None)


def cached(path, key, make):
    """The JSON at path if made for `key`, else make() stored there."""
    if os.path.exists(path):
        with open(path) as f:
            c = json.load(f)
        if c.get('key') == key:
            return c
        print('%s was made for another scene or settings: making it again' % path, file=sys.stderr)
    c = make()
    c['key'] = key
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        json.dump(c, f, indent=1)
    return c


def rest_state(exe, scene, a, key):
    """The settled rest's state file (made once)."""
    path = os.path.join(REPO, '.build', 'c60_rest_%g_%g.state' % (a.rest_dt, a.at))
    meta = path + '.json'

    def make():
        print('settling: fixed dt %g to %g s (once) ...' % (a.rest_dt, a.at), file=sys.stderr, flush=True)
        s, _ = nscd_run(exe, scene, ['--dt', repr(a.rest_dt), '--duration', repr(a.at), '--save-state', path])
        return {'binary': acc.checksum([exe]), 'steps': s['steps'], 'wall_s': s['wall_s'],
                'unconverged': s['unconverged_steps']}
    if not os.path.exists(path) and os.path.exists(meta):
        os.remove(meta)  # the state itself is gone: made again
    info = cached(meta, key, make)
    return path, info


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=os.path.join(REPO, 'urdf/c60.urdf'))
    ap.add_argument('--rest-dt', type=float, default=2.5e-8, help='the settling run\'s fixed dt')
    ap.add_argument('--at', type=float, default=0.0046, help='where the rest is stored, s')
    ap.add_argument('--until', type=float, default=0.0092, help='where the continuations end, s')
    ap.add_argument('--ref', type=float, default=5e-8, help='the reference continuation\'s fixed dt')
    ap.add_argument('--fixed', default='2e-5,1e-5,5e-6,2e-6', help='fixed dts (empty: none)')
    ap.add_argument('--adaptive', default='1e-2,1e-3', help='adaptive rtol values (empty: none)')
    ap.add_argument('--atol-ratio', type=float, default=1e-3, help='atol = rtol x this')
    ap.add_argument('--adaptive-dt', type=float, default=1e-5, help='the largest adaptive step')
    ap.add_argument('--repeat', type=int, default=3, help='timing runs per case (the best is kept)')
    ap.add_argument('--json', help='write the rows here')
    a = ap.parse_args()
    exe = acc.nscd_run_path(REPO)
    scene_sum = acc.checksum([a.scene])

    engine = acc.engine_checksum(exe)
    rest, rest_info = rest_state(exe, a.scene, a, {'scene': scene_sum, 'dt': a.rest_dt, 'at': a.at, 'engine': engine})
    from_rest = ['--initial-state', rest, '--duration', repr(a.until - a.at)]
    ref_path = os.path.join(REPO, '.build', 'c60_trip_from_rest_ref_%g_%g_%g_%g.json' % (a.rest_dt, a.at, a.ref,
                                                                                        a.until))

    def make_ref():
        print('reference: fixed dt %g from the rest (once) ...' % a.ref, file=sys.stderr, flush=True)
        s, f = nscd_run(exe, a.scene, from_rest + ['--dt', repr(a.ref)], csv=True)
        return {'binary': acc.checksum([exe]), 'figures': f, 'steps': s['steps'], 'wall_s': s['wall_s'],
                'unconverged': s['unconverged_steps']}
    ref = cached(ref_path, {'scene': scene_sum, 'rest': rest_info['key'], 'rest_at': a.at, 'rest_binary': rest_info['binary'],
                            'ref': a.ref, 'until': a.until}, make_ref)
    rf = ref['figures']
    missing = [k for k in FIGURES if rf.get(k) is None]
    if missing:
        sys.exit('the reference does not reach every figure by %g s (missing: %s): raise --until' % (
            a.until, ', '.join(missing)))

    cases = [('fixed dt %g' % v, ['--dt', repr(v)]) for v in (float(x) for x in a.fixed.split(',') if x)] + \
            [('adaptive rtol %g, atol %g' % (v, v * a.atol_ratio),
              ['--dt', repr(a.adaptive_dt), '--set', 'step_control=adaptive', '--set', 'rtol=%r' % v,
               '--set', 'atol=%r' % (v * a.atol_ratio)])
             for v in (float(x) for x in a.adaptive.split(',') if x)]
    rows = []
    for label, extra in cases:
        print('%s ...' % label, file=sys.stderr, flush=True)
        s, f = nscd_run(exe, a.scene, from_rest + extra, csv=True)
        walls = [nscd_run(exe, a.scene, from_rest + extra)[0]['wall_s'] for _ in range(a.repeat)]
        complete = all(f.get(k) is not None for k in FIGURES)
        e = acc.rel_errors(f, rf) if complete else {k: float('inf') for k in FIGURES}
        rows.append({'label': label, 'summary': s, 'figures': f, 'errors': e, 'walls': walls, 'wall_s': min(walls),
                     'complete': complete})

    print('rest: fixed dt %g from the ON pose to %.2f ms (%d steps, %d unconverged); reference: fixed dt %g from '
          'it to %.2f ms (%d steps, %d unconverged): touch %.4f ms, mean push %.4f N, release %.4f ms, '
          'C7 opens %.4f ms' % (a.rest_dt, 1e3 * a.at, rest_info['steps'], rest_info['unconverged'], a.ref,
                                1e3 * a.until, ref['steps'], ref['unconverged'], 1e3 * rf['touch_s'],
                                rf['mean_push_N'], 1e3 * rf['release_s'], 1e3 * rf['c7_open_s']))
    print()
    print('| from the rest to %.1f ms | steps (rejected) | wall s (best of %d) | touch | mean push | release | '
          'C7 opens | worst | unconverged |' % (1e3 * a.until, a.repeat))
    print('|---|---|---|---|---|---|---|---|---|')
    pct = lambda x: '%.2f %%' % (100 * x) if x != float('inf') else 'missing'  # noqa: E731
    for r in rows:
        s, e = r['summary'], r['errors']
        print('| %s | %d (%d) | %.3f | %s | %s | %s | %s | %s | %d |' % (
            r['label'], s['steps'], s.get('rejected_steps', 0), r['wall_s'], pct(e['touch_s']),
            pct(e['mean_push_N']), pct(e['release_s']), pct(e['c7_open_s']), pct(max(e.values())),
            s['unconverged_steps']))
    good = [r for r in rows if r['complete'] and max(r['errors'].values()) <= 0.01 and
            r['summary']['unconverged_steps'] == 0]
    print()
    if good:
        best = min(good, key=lambda r: r['wall_s'])
        print('cheapest with every figure within 1 %% and 0 unconverged steps: %s, %.3f s wall (worst error %.2f %%)'
              % (best['label'], best['wall_s'], 100 * max(best['errors'].values())))
    else:
        print('no run has every figure within 1 % and 0 unconverged steps')
    if a.json:
        with open(a.json, 'w') as f:
            json.dump({'rest': rest_info, 'reference': ref, 'rows': rows}, f, indent=1)


if __name__ == '__main__':
    main()
