#!/usr/bin/python3
"""What the springs' load model changes in the C-60 (docs/c60.md, "What the loads
change"): the trip and the paper's bench of several scenes side by side, as one
markdown table (scripts/c60_loads_compare.sh runs the scenes and calls this).

  c60_loads_compare.py --trip LABEL=CSV ... --bench LABEL=CSV ... [--json OUT]
                       [--command TEXT] [--commit TEXT] [--date TEXT]

Trip CSVs: nscd_run with the probe at 0.2 m/s from 0.7 ms, every step. Bench CSVs:
scripts/c60_bench.sh's protocol. Definitions (those of c60_trip_figures.py, plus):
- push: the probe's effort (the tripping force), mean over the samples in contact;
  by phase: the nose on the seat F4 (0.1 ms after the touch, past the first-contact
  impact, to the moment the tooth corner takes the load) and the tooth corner (from
  then until the hook starts to turn); and over both (0.1 ms after the touch until the
  hook starts to turn);
- the hook starts to turn: its yaw first exceeds its rest yaw (mean over the last
  0.5 ms before the touch) by 0.25 deg, after the touch (anticlockwise: the way the
  rod turns it once the latch lets go); the bar's angle then: its CAD frame's yaw in
  the world (36 deg at the published ON pose) and its turn since its rest;
- the corner on the hook's tip edge (C4_3_tip, C4_4_tip): from its first to its last
  sample with a force;
- bench: the force held at 2.0 mm (c60_plot.py bench), against the paper's 14.96 N
  simulated and 15.28 N measured.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import c60_plot as P  # noqa: E402
from c60_trip_figures import figures, WINDOW, CLOSED  # noqa: E402

HOOK_TURN_DEG = 0.25


def mean_in(t, F, mask):
    return float(np.mean(F[mask])) if mask.any() else None


def trip_row(d):
    r = figures(d)
    t, F = d['t'], d['probe.effort']
    touch = r['touch_ms'] / 1e3 if r['touch_ms'] is not None else None
    corner = r['corner_ms'] / 1e3 if r['corner_ms'] is not None else None
    hook, bar = np.degrees(P.yaw(d, 'hook')), np.degrees(P.yaw(d, 'trip_bar'))
    out = dict(r)
    if touch is None:
        return out
    rest = (t > touch - 5e-4) & (t < touch)
    hook0, bar0 = float(np.mean(hook[rest])), float(np.mean(bar[rest]))
    turned = np.nonzero((hook - hook0 > HOOK_TURN_DEG) & (t > touch))[0]
    t_turn = float(t[turned[0]]) if len(turned) else None
    in_contact = d['TRIP.gap'] < CLOSED
    start = touch + WINDOW
    out['hook_turn_ms'] = 1e3 * t_turn if t_turn else None
    if t_turn:
        k = turned[0]
        out['hook_turn_travel_mm'] = 1e3 * float(d['probe.cmd'][k])
        out['bar_yaw_at_hook_turn_deg'] = float(bar[k])
        out['bar_turn_at_hook_turn_deg'] = float(bar[k] - bar0)
    out['bar_yaw_rest_deg'] = bar0
    out['hook_yaw_rest_deg'] = hook0
    end = t_turn or (r['release_ms'] or 1e3 * t[-1]) / 1e3
    out['push_seat_N'] = mean_in(t, F, (t >= start) & (t < (corner or end)) & in_contact)
    out['push_corner_N'] = mean_in(t, F, (t >= (corner or end)) & (t < end) & in_contact) if corner else None
    out['push_to_hook_turn_N'] = mean_in(t, F, (t >= start) & (t < end) & in_contact)
    if 'C4_3_tip.fn' in d.dtype.names:
        tip = d['C4_3_tip.fn'] + d['C4_4_tip.fn']
        on = np.nonzero(tip > 0)[0]
        out['tip_from_ms'] = 1e3 * float(t[on[0]]) if len(on) else None
        out['tip_to_ms'] = 1e3 * float(t[on[-1]]) if len(on) else None
    return out


def bench_row(d):
    r = P.bench(d, None)
    return {k: r[k] for k in ('equilibrium_force_N', 'stiffness_fwd_N_per_mm', 'hysteresis_mean_N',
                              'force_start_fwd_N')}


def fmt(v, f):
    return '—' if v is None else f % v


def pair(a, b, fa, fb):
    return '%s (%s)' % (fmt(a, fa), fmt(b, fb))


ROWS = [
    ('rest: C7 force [N]', lambda r: fmt(r['c7_before_N'], '%.2f')),
    ('rest: latch on the seat F4 / on the tooth corner [N]',
     lambda r: '%s / %s' % (fmt(r['latch_seat_before_N'], '%.2f'), fmt(r['latch_corner_before_N'], '%.2f'))),
    ('probe touches the bar [ms] (probe travel [mm])', lambda r: pair(r['touch_ms'], r['touch_travel_mm'], '%.3f', '%.3f')),
    ('push, nose on the seat (touch + 0.1 ms to the corner) [N]', lambda r: fmt(r.get('push_seat_N'), '%.3f')),
    ('tooth corner takes the load [ms]', lambda r: fmt(r['corner_ms'], '%.3f')),
    ('push, tooth corner (to the hook\'s turn) [N]', lambda r: fmt(r.get('push_corner_N'), '%.3f')),
    ('push, touch + 0.1 ms to the hook\'s turn [N]', lambda r: fmt(r.get('push_to_hook_turn_N'), '%.3f')),
    ('hook starts to turn (+0.25° over rest) [ms] (probe travel [mm])',
     lambda r: pair(r.get('hook_turn_ms'), r.get('hook_turn_travel_mm'), '%.3f', '%.3f')),
    ('bar\'s angle then: yaw [°] (turn since rest [°])',
     lambda r: pair(r.get('bar_yaw_at_hook_turn_deg'), r.get('bar_turn_at_hook_turn_deg'), '%.3f', '%.3f')),
    ('corner on the hook\'s tip edge [ms]',
     lambda r: '—' if r.get('tip_from_ms') is None else '%.3f – %.3f' % (r['tip_from_ms'], r['tip_to_ms'])),
    ('latch release, every C4 pair > 20 µm [ms] (probe travel [mm])',
     lambda r: pair(r['release_ms'], r['release_travel_mm'], '%.3f', '%.3f')),
    ('C7 opens [ms]', lambda r: fmt(r['c7_open_ms'], '%.3f')),
]
BENCH_ROWS = [
    ('bench (paper Fig. 7): force held at 2.0 mm [N] (paper: 14.96 simulated, 15.28 measured)',
     lambda b: fmt(b['equilibrium_force_N'], '%.2f')),
    ('bench: force at 0.2 mm → slope [N, N/mm]',
     lambda b: '%s → %s' % (fmt(b['force_start_fwd_N'], '%.2f'), fmt(b['stiffness_fwd_N_per_mm'], '%.3f'))),
    ('bench: hysteresis, forward − backward [N]', lambda b: fmt(b['hysteresis_mean_N'], '%.3f')),
]


def table(trips, benches):
    labels = list(trips) + [l for l in benches if l not in trips]
    lines = ['| | ' + ' | '.join(labels) + ' |', '|---|' + '---|' * len(labels)]
    for name, f in ROWS:
        lines.append('| %s | %s |' % (name, ' | '.join(f(trips[l]) if l in trips else '—' for l in labels)))
    for name, f in BENCH_ROWS:
        lines.append('| %s | %s |' % (name, ' | '.join(f(benches[l]) if l in benches else '—' for l in labels)))
    return '\n'.join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--trip', action='append', default=[], metavar='LABEL=CSV')
    ap.add_argument('--bench', action='append', default=[], metavar='LABEL=CSV')
    ap.add_argument('--json')
    ap.add_argument('--command')
    ap.add_argument('--commit')
    ap.add_argument('--date')
    a = ap.parse_args()
    trips = {s.split('=', 1)[0]: trip_row(P.load(s.split('=', 1)[1])) for s in a.trip}
    benches = {s.split('=', 1)[0]: bench_row(P.load(s.split('=', 1)[1])) for s in a.bench}
    if a.command:
        print('`%s` (%s, commit %s):\n' % (a.command, a.date or '?', a.commit or '?'))
    print(table(trips, benches))
    if a.json:
        with open(a.json, 'w') as f:
            json.dump({'trip': trips, 'bench': benches}, f, indent=1, default=str)


if __name__ == '__main__':
    main()
