#!/usr/bin/python3
"""The trip of two C-60 scenes side by side (scripts/c60_trip_compare.sh runs them).

  c60_trip_compare.py OUTDIR LABEL=CSV LABEL=CSV [--json OUT] [--figure PNG]

From each nscd_run CSV (probe at 0.2 m/s from 0.7 ms): the C7 force before the probe
arrives, the first touch (time, probe travel), the tripping force (mean while the probe
is in contact before the release, and the peak of its 0.1-ms running mean), the latch
release (every C4 pair open by more than 20 um), the opening of C7, the moving contact's
stroke and the sequence of events. Prints the table (markdown) and writes one PNG per
figure into OUTDIR (c60_trip_*.png); --figure writes the four panels in one PNG too.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import c60_plot as P  # noqa: E402

from c60_trip_figures import RELEASE_GAP, CLOSED, WINDOW, T_PROBE, first, figures  # noqa: E402,F401


def fmt(v, f='%.2f'):
    return '—' if v is None else f % v


ROWS = [
    ('C7 force before the probe arrives [N] (mean, last 0.5 ms)', 'c7_before_N', '%.2f'),
    ('latch at rest: seat F4 / tooth corner [N]', None, None),
    ('first touch [ms]', 'touch_ms', '%.2f'),
    ('probe travel at the touch [mm]', 'touch_travel_mm', '%.3f'),
    ('tooth corner takes the load [ms]', 'corner_ms', '%.2f'),
    ('tripping force, mean while in contact (touch to release) [N]', 'force_mean_N', '%.2f'),
    ('tripping force, 0.1-ms peak [N]', 'force_peak_0p1ms_N', '%.2f'),
    ('  at probe travel [mm]', 'force_peak_travel_mm', '%.3f'),
    ('tripping force, 0.1-ms peak from 0.1 ms after the touch [N]', 'force_peak_0p1ms_after_impact_N', '%.2f'),
    ('largest one-sample force, touch to release [N]', 'force_max_sample_N', '%.2f'),
    ('latch release, C4 gap > 20 µm [ms]', 'release_ms', '%.2f'),
    ('  probe travel at the release [mm]', 'release_travel_mm', '%.3f'),
    ('C7: first separation by more than 1 µm [ms]', 'c7_first_separation_ms', '%.2f'),
    ('C7 opens (last closed before the gap passes 0.1 mm) [ms]', 'c7_open_ms', '%.2f'),
    ('  after the release [ms]', 'c7_open_after_release_ms', '%.2f'),
    ('moving contact stroke: largest C7 gap [mm]', 'stroke_max_mm', '%.2f'),
    ('  at [ms]', 'stroke_max_at_ms', '%.2f'),
    ('  C7 gap at the end, 20.7 ms [mm]', 'stroke_end_mm', '%.2f'),
]


def table(res):
    labels = list(res)
    lines = ['| | ' + ' | '.join(labels) + ' |', '|---|' + '---|' * len(labels)]
    for name, key, f in ROWS:
        if key is None:
            cells = ['%.2f / %.2f' % (res[l]['latch_seat_before_N'], res[l]['latch_corner_before_N']) for l in labels]
        else:
            cells = [fmt(res[l].get(key), f) for l in labels]
        lines.append('| %s | %s |' % (name, ' | '.join(cells)))
    lines.append('')
    for l in labels:
        lines.append('%s, sequence: ' % l + '; '.join('%s %.2f ms' % (n, t) for n, t in res[l]['events']) +
                     ('' if not res[l]['events_missing'] else '; never: ' + ', '.join(res[l]['events_missing'])))
    return '\n'.join(lines)


def decorate(ax, xlabel, ylabel, title, **legend):
    """A panel's labels, title, grid and legend (legend: matplotlib legend keywords)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(**legend)


def plots(data, res, outdir, figure=None):
    plt = P.plt_module()
    cols = ['C0', 'C3', 'C2', 'C1']

    def force_travel(ax):
        for c, (l, d) in zip(cols, data.items()):
            r = res[l]
            m = d['t'] >= (r['touch_ms'] or 0) * 1e-3 - 2e-4
            ax.plot(1e3 * d['probe.cmd'][m], d['probe.effort'][m], c, lw=0.9, label=l)
            if r.get('force_peak_travel_mm') is not None:
                ax.plot(r['force_peak_travel_mm'], r['force_peak_0p1ms_N'], 'o', color=c, ms=4)
            if r['release_travel_mm'] is not None:
                ax.axvline(r['release_travel_mm'], color=c, lw=0.6, ls=':')
        ax.set_xlim(min(r['touch_travel_mm'] or 0 for r in res.values()) - 0.1,
                    max(r['release_travel_mm'] or 0 for r in res.values()) + 0.4)
        decorate(ax, 'probe travel [mm]', 'tripping force (probe) [N]',
                 'tripping force vs probe travel\n(o 0.1-ms peak; dotted: latch release)',
                 fontsize=8)

    def latch(ax):
        for c, (l, d) in zip(cols, data.items()):
            t = 1e3 * d['t']
            ax.plot(t, d['C4.fn'] + d['C4_2.fn'], c, lw=0.9, label='%s: seat F4 (C4, C4_2)' % l)
            ax.plot(t, d['C4_3.fn'] + d['C4_4.fn'], c, lw=0.9, ls='--', label='%s: tooth corner (C4_3, C4_4)' % l)
            if res[l]['release_ms']:
                ax.axvline(res[l]['release_ms'], color=c, lw=0.6, ls=':')
        ax.set_xlim(0, max(r['release_ms'] or 0 for r in res.values()) + 1.5)
        ax.set_ylim(0, 15)
        decorate(ax, 'time [ms]', 'latch force [N] (cut at 15 N)',
                 'latch: the seat, then the corner, then the release (dotted)',
                 fontsize=7)

    def c7(ax):
        for c, (l, d) in zip(cols, data.items()):
            t = 1e3 * d['t']
            ax.plot(t, d['C7.fn'], c, lw=0.9, label='%s: C7 force [N]' % l)
            if res[l]['touch_ms']:
                ax.axvline(res[l]['touch_ms'], color=c, lw=0.6, ls=':')
        ax.set_xlim(0, max(r['c7_open_ms'] or 0 for r in res.values()) + 0.5)
        ax.set_ylim(0, 30)
        decorate(ax, 'time [ms] (dotted: the touch)', 'C7 force [N]',
                 'main contact C7: force before the touch and at the opening',
                 fontsize=8, loc='lower left')

    def stroke(ax):
        for c, (l, d) in zip(cols, data.items()):
            t = 1e3 * d['t']
            ax.plot(t, 1e3 * d['C7.gap'], c, lw=0.9, label='%s: C7 gap' % l)
            for n, te in res[l]['events']:
                ax.plot([te], [0], '|', color=c, ms=10)
        decorate(ax, 'time [ms]', 'C7 gap (stroke of the moving contact) [mm]',
                 'stroke; ticks: the events (touch, corner, release, opening, ...)',
                 fontsize=8)

    panels = [('force', force_travel), ('latch', latch), ('c7_force', c7), ('stroke', stroke)]
    for name, fn in panels:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        fn(ax)
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, 'c60_trip_%s.png' % name), dpi=100)
        plt.close(fig)
    if figure:
        fig, axs = plt.subplots(2, 2, figsize=(12, 8))
        for ax, (name, fn) in zip(axs.flat, panels):
            fn(ax)
        fig.suptitle('C-60 trip, probe 0.2 m/s from 0.7 ms: ' + ' vs '.join(data), fontsize=11)
        fig.tight_layout()
        fig.savefig(figure, dpi=64)
        plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('outdir')
    ap.add_argument('runs', nargs='+', help='LABEL=CSV')
    ap.add_argument('--json')
    ap.add_argument('--figure')
    a = ap.parse_args()
    data = {}
    for spec in a.runs:
        label, path = spec.split('=', 1)
        data[label] = P.load(path)
    res = {l: figures(d) for l, d in data.items()}
    print(table(res))
    os.makedirs(a.outdir, exist_ok=True)
    plots(data, res, a.outdir, a.figure)
    if a.json:
        with open(a.json, 'w') as f:
            json.dump(res, f, indent=1)


if __name__ == '__main__':
    main()
