#!/usr/bin/python3
"""Accuracy per second of the C-60 trip: the four figures of issue 29 against a
converged reference, for fixed steps and adaptive tolerances.

  c60_trip_accuracy.py [--scene urdf/c60.urdf] [--fixed 1e-5,1e-6,2e-7,1e-7]
                       [--adaptive 1e-3,1e-4] [--atol-ratio 1] [--adaptive-dt 1e-5]
                       [--ref 2.5e-8] [--ref-cache FILE] [--set KEY=VALUE ...] [--json OUT]

The trip: `nscd_run SCENE --duration 0.0207 --command probe=0:0,0.0007:0,0.0207:0.004`.
The four figures, from every step's row (the CSV is read through a pipe, never
stored):
- touch: the end of the first step after 0.7 ms with TRIP closed (gap < 1 um) and
  the probe moving (scripts/analysis/c60_trip_figures.py's definition);
- mean push: the probe's effort averaged over time (each row weighted by its step)
  from 0.1 ms after the touch to the release: the impulse over the span, so that
  runs with any steps compare alike;
- release: the first step end after the touch with every C4 pair open by > 20 um;
- C7 opens: the first step end after the last closed one (gap < 1 um) before the gap
  first exceeds 0.1 mm after the release.
Event errors are relative to the time from the probe's start (0.7 ms), the push's
to its value. The wall time is that of a second run without CSV output (nscd_run's
own wall_s; the CSV writer costs ~70 us a row, more than a fine step); the
reference's wall is that of its figures run. The reference (fixed dt --ref) is
run once under `nice` and its figures kept in --ref-cache (default
.build/c60_trip_reference_<dt>.json), keyed on the scene's
checksum and the settings (`--ref-cache` elsewhere, or delete it, to run it again).
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import threading

import numpy as np

T_PROBE = 0.0007
PROBE = 'probe=0:0,0.0007:0,0.0207:0.004'
DURATION = 0.0207
CLOSED = 1e-6
RELEASE_GAP = 20e-6
PUSH_SKIP = 1e-4


def nscd_run_path(repo):
    return os.environ.get('NSCD_RUN', os.path.join(repo, '.build/ws/devel/lib/nscd_sim/nscd_run'))


def columns_of(header):
    names = header.strip().split(',')
    idx = {n: i for i, n in enumerate(names)}
    c4 = [i for n, i in idx.items() if n.endswith('.gap') and (n[:-4] == 'C4' or n[:-4].startswith('C4_'))]
    want = {k: idx[k] for k in ('t', 'probe.cmd', 'probe.effort', 'TRIP.gap', 'C7.gap')}
    if 'h' in idx:
        want['h'] = idx['h']
    return want, c4


def read_rows(stream):
    """The trip's columns from an nscd_run CSV stream: dict of numpy arrays."""
    header = stream.readline()
    want, c4 = columns_of(header)
    keys = list(want)
    cols = {k: [] for k in keys}
    c4min = []
    for line in stream:
        f = line.split(',')
        for k in keys:
            cols[k].append(float(f[want[k]]))
        c4min.append(min(float(f[i]) for i in c4))
    d = {k: np.array(v) for k, v in cols.items()}
    d['C4.min_gap'] = np.array(c4min)
    return d


def first(t, mask, after):
    idx = np.nonzero(mask & (t > after))[0]
    return (float(t[idx[0]]), int(idx[0])) if len(idx) else (None, None)


def figures(d):
    t = d['t']
    # Each row ends a step; the step lengths (the first row is the initial state).
    h = d['h'] if 'h' in d else np.concatenate([[0.0], np.diff(t)])
    touch, _ = first(t, (d['TRIP.gap'] < CLOSED) & (d['probe.cmd'] > 0), T_PROBE)
    r = {'touch_s': touch, 'release_s': None, 'c7_open_s': None, 'mean_push_N': None}
    if touch is None:
        return r
    release, _ = first(t, d['C4.min_gap'] > RELEASE_GAP, touch)
    r['release_s'] = release
    if release is not None:
        # The steps inside [touch + 0.1 ms, release], each weighted by its length.
        inside = (t - h >= touch + PUSH_SKIP - 1e-12) & (t <= release)
        if inside.any():
            r['mean_push_N'] = float(np.sum(d['probe.effort'][inside] * h[inside]) / np.sum(h[inside]))
        gap = d['C7.gap']
        _, k_far = first(t, gap > 1e-4, release)
        if k_far is not None:
            closed = np.nonzero(gap[:k_far] < CLOSED)[0]
            r['c7_open_s'] = float(t[closed[-1] + 1]) if len(closed) else float(t[0])
    return r


def run(exe, scene, extra, csv=True, nice=False, arrays=None, duration=DURATION):
    """One trip; returns (summary JSON, figures or None); `arrays`: an .npz to keep the columns in;
    duration None: `extra` gives it (or the run's own default)."""
    cmd = ((['nice', '-n', '10'] if nice else []) + [exe, scene] +
           ([] if duration is None else ['--duration', repr(duration)]) + ['--command', PROBE, '--quiet'] + extra)
    if not csv:
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit('nscd_run failed: %s\n%s' % (' '.join(cmd), r.stderr.strip()))
        return json.loads(r.stdout.strip().splitlines()[-1]), None
    with tempfile.TemporaryDirectory() as tmp:
        fifo = os.path.join(tmp, 'trip.csv')
        os.mkfifo(fifo)
        p = subprocess.Popen(cmd + ['--csv', fifo], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        out = {}

        def drain():
            out['stdout'], out['stderr'] = p.communicate()
        th = threading.Thread(target=drain)
        th.start()
        with open(fifo) as stream:
            d = read_rows(stream)
        th.join()
        if p.returncode != 0:
            sys.exit('nscd_run failed: %s\n%s' % (' '.join(cmd), out['stderr'].strip()))
        if arrays:
            np.savez_compressed(arrays, **d)
        return json.loads(out['stdout'].strip().splitlines()[-1]), figures(d)


def checksum(paths):
    h = hashlib.sha256()
    for p in paths:
        with open(p, 'rb') as f:
            h.update(f.read())
    return h.hexdigest()[:16]


def engine_checksum(exe):
    """The checksum of nscd_run and of the engine library it loads (where the physics is):
    a cached run of another engine is not reused."""
    paths = [exe]
    try:
        out = subprocess.run(['ldd', exe], capture_output=True, text=True, check=True).stdout
        paths += [line.split('=>')[1].split('(')[0].strip() for line in out.splitlines()
                  if 'libnscd_engine' in line and '=>' in line]
    except (OSError, subprocess.CalledProcessError):
        pass
    return checksum(paths)


def rel_errors(f, ref):
    e = {}
    for k in ('touch_s', 'release_s', 'c7_open_s'):
        e[k] = abs(f[k] - ref[k]) / (ref[k] - T_PROBE) if f[k] is not None else float('inf')
    e['mean_push_N'] = (abs(f['mean_push_N'] - ref['mean_push_N']) / abs(ref['mean_push_N'])
                        if f['mean_push_N'] is not None else float('inf'))
    return e


def main():
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=os.path.join(repo, 'urdf/c60.urdf'))
    ap.add_argument('--fixed', default='1e-5,1e-6,2e-7,1e-7', help='fixed dts (empty: none)')
    ap.add_argument('--adaptive', default='', help='adaptive rtol values (empty: none)')
    ap.add_argument('--atol-ratio', type=float, default=1.0, help='atol = rtol x this')
    ap.add_argument('--adaptive-dt', type=float, default=1e-5, help='the largest adaptive step')
    ap.add_argument('--ref', type=float, default=2.5e-8, help='the reference run\'s fixed dt')
    ap.add_argument('--ref-cache', help='where the reference figures are kept')
    ap.add_argument('--ref-arrays', help='keep the reference run\'s trip columns in this .npz')
    ap.add_argument('--set', action='append', default=[], help='extra --set KEY=VALUE for every run')
    ap.add_argument('--no-timing', action='store_true', help='wall from the figures run (with CSV)')
    ap.add_argument('--json', help='write the rows here')
    a = ap.parse_args()
    exe = nscd_run_path(repo)
    sets = sum((['--set', s] for s in a.set), [])

    # Keyed on the engine too: a change of the physics must not reuse an old reference.
    key = {'scene': checksum([a.scene]), 'dt': a.ref, 'set': a.set, 'engine': engine_checksum(exe)}
    cache = a.ref_cache or os.path.join(repo, '.build', 'c60_trip_reference_%g.json' % a.ref)
    ref = None
    if os.path.exists(cache):
        with open(cache) as f:
            c = json.load(f)
        if c.get('key') == key:
            ref = c
        else:
            print('reference cache %s is for another scene, binary or settings: running it again' % cache,
                  file=sys.stderr)
    if ref is None:
        print('reference: fixed dt %g (nice; minutes) ...' % a.ref, file=sys.stderr, flush=True)
        summary, fig = run(exe, a.scene, ['--dt', repr(a.ref)] + sets, nice=True, arrays=a.ref_arrays)
        ref = {'key': key, 'figures': fig, 'steps': summary['steps'], 'wall_s': summary['wall_s'],
               'unconverged': summary['unconverged_steps']}
        os.makedirs(os.path.dirname(cache), exist_ok=True)
        with open(cache, 'w') as f:
            json.dump(ref, f, indent=1)
    rf = ref['figures']

    cases = [('fixed', float(s)) for s in a.fixed.split(',') if s] + \
            [('adaptive', float(s)) for s in a.adaptive.split(',') if s]
    rows = []
    for mode, v in cases:
        print('%s %g ...' % (mode, v), file=sys.stderr, flush=True)
        if mode == 'fixed':
            extra = ['--dt', repr(v)] + sets
        else:
            extra = ['--dt', repr(a.adaptive_dt), '--set', 'step_control=adaptive', '--set', 'rtol=%r' % v,
                     '--set', 'atol=%r' % (v * a.atol_ratio)] + sets
        summary, fig = run(exe, a.scene, extra)
        if not a.no_timing:
            summary_t, _ = run(exe, a.scene, extra, csv=False)
            summary['wall_s'] = summary_t['wall_s']
        rows.append({'mode': mode, 'value': v, 'summary': summary, 'figures': fig, 'errors': rel_errors(fig, rf)})

    print('reference: fixed dt %g, %d steps, %d unconverged, %.1f s wall (with its CSV): touch %.4f ms, '
          'mean push %.4f N, release %.4f ms, C7 opens %.4f ms' % (
              a.ref, ref['steps'], ref['unconverged'], ref['wall_s'], 1e3 * rf['touch_s'], rf['mean_push_N'],
              1e3 * rf['release_s'], 1e3 * rf['c7_open_s']))
    print()
    print('| run | steps (rejected) | wall s | touch | mean push | release | C7 opens | worst | unconverged |')
    print('|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        s, e = r['summary'], r['errors']
        label = 'fixed dt %g' % r['value'] if r['mode'] == 'fixed' else 'adaptive rtol %g, atol %g' % (
            r['value'], r['value'] * a.atol_ratio)
        pct = lambda x: '%.2f %%' % (100 * x)  # noqa: E731
        worst = max(e.values())
        print('| %s | %d (%d) | %.3f | %s | %s | %s | %s | %s | %d |' % (
            label, s['steps'], s.get('rejected_steps', 0), s['wall_s'], pct(e['touch_s']), pct(e['mean_push_N']),
            pct(e['release_s']), pct(e['c7_open_s']), pct(worst), s['unconverged_steps']))
    if a.json:
        with open(a.json, 'w') as f:
            json.dump({'reference': ref, 'rows': rows}, f, indent=1)


if __name__ == '__main__':
    main()
