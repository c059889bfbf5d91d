#!/usr/bin/python3
"""The C-60 trip's figures from an nscd_run CSV: one definition of each, used by
c60_plot.py (trip), c60_trip_compare.py, c60_trip_convergence.py and
c60_clearance_study.py.

  figures(d) -> dict   (d: c60_csv.load(CSV); probe at 0.2 m/s from 0.7 ms)

- touch: the first sample after the probe starts with TRIP closed (gap < 1 um);
- tripping force: the probe's effort; its mean over the samples in contact (TRIP
  closed) from the touch to the release, and the peak of its 0.1-ms running mean
  over the same span (impact included; also given from 0.1 ms after the touch);
- corner takes the load: the tooth corner (C4_3 + C4_4) carries more than the seat
  F4 (C4 + C4_2) and more than 0.1 N;
- latch release: every C4 pair open by more than 20 um, after the touch;
- C7 opens: the start of the separation that becomes the stroke, i.e. the last
  sample closed (gap < 1 um) before the gap first exceeds 0.1 mm after the release
  (the moving contact chatters by a few um before it);
- stroke: the largest C7 gap, and the moving contact's largest turn from its rest;
- tripped by itself: C7 open by more than 0.1 mm before the probe touches the bar
  (the latch did not hold through the settling). The probe then pushes nothing, so
  the touch, forces, release and opening are not figures of a trip: they are None.
"""
import numpy as np

import c60_csv

T_PROBE = 0.0007      # s: the probe starts [Q-code]
RELEASE_GAP = 20e-6   # m: the latch is released when every C4 pair is open by more
CLOSED = 1e-6         # m: a contact counts as closed below this gap
WINDOW = 1e-4         # s: the running mean of the "0.1-ms peak"


def first(t, mask, after=-np.inf):
    idx = np.nonzero(mask & (t > after))[0]
    return (float(t[idx[0]]), int(idx[0])) if len(idx) else (None, None)


def figures(d):
    t, x, F = d['t'], d['probe.cmd'], d['probe.effort']
    c4 = c60_csv.group_gap(d, 'C4')
    seat = d['C4.fn'] + d['C4_2.fn']
    corner = d['C4_3.fn'] + d['C4_4.fn']
    r = {}
    t_touch, k_touch = first(t, (d['TRIP.gap'] < CLOSED) & (x > 0), T_PROBE)
    r['touch_ms'] = 1e3 * t_touch if t_touch else None
    r['touch_travel_mm'] = 1e3 * float(x[k_touch]) if t_touch else None
    # C7 before the probe arrives: the mean over the last 0.5 ms before the touch (the
    # mechanism has settled by then; the spread is printed too).
    pre = (t > (t_touch or t[-1]) - 5e-4) & (t < (t_touch or t[-1]))
    r['c7_before_N'] = float(np.mean(d['C7.fn'][pre]))
    r['c7_before_spread_N'] = float(np.ptp(d['C7.fn'][pre]))
    r['latch_seat_before_N'] = float(np.mean(seat[pre]))
    r['latch_corner_before_N'] = float(np.mean(corner[pre]))
    t_rel, k_rel = first(t, c4 > RELEASE_GAP, t_touch or 0)
    r['release_ms'] = 1e3 * t_rel if t_rel else None
    r['release_travel_mm'] = 1e3 * float(x[k_rel]) if t_rel else None
    t_corner, _ = first(t, (corner > seat) & (corner > 0.1), t_touch or 0)
    r['corner_ms'] = 1e3 * t_corner if t_corner else None
    # The push: from the touch to the release, the samples where the probe is in contact.
    push = (t >= (t_touch or t[-1])) & (t < (t_rel or t[-1])) & (d['TRIP.gap'] < CLOSED)
    r['force_mean_N'] = float(np.mean(F[push])) if push.any() else None
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(WINDOW / dt)))
    win = (t >= (t_touch or t[-1])) & (t < (t_rel or t[-1]))
    idx = np.nonzero(win)[0]
    if len(idx) >= n:
        Fw = F[idx[0]:idx[-1] + 1]
        run = np.convolve(Fw, np.ones(n) / n, mode='valid')
        k = int(np.argmax(run))
        r['force_peak_0p1ms_N'] = float(run[k])
        r['force_peak_at_ms'] = 1e3 * float(t[idx[0] + k + n // 2])
        r['force_peak_travel_mm'] = 1e3 * float(x[idx[0] + k + n // 2])
        # The same after the first 0.1 ms of contact (past the first-contact impact).
        late = run[t[idx[0]:idx[0] + len(run)] >= t_touch + WINDOW]
        r['force_peak_0p1ms_after_impact_N'] = float(late.max()) if len(late) else None
    r['force_max_sample_N'] = float(F[win].max()) if win.any() else None
    # C7 opens: the start of the separation that becomes the stroke, i.e. the last sample
    # closed (gap < 1 um) before the gap first exceeds 0.1 mm after the release. The first
    # separation by more than 1 um comes earlier: the moving contact chatters by a few um
    # on the fixed contact while the released hook and plate start to move.
    gap = d['C7.gap']
    t_sep, _ = first(t, gap > CLOSED, t_rel or t[-1])
    r['c7_first_separation_ms'] = 1e3 * t_sep if t_sep else None
    t_open = None
    t_far, k_far = first(t, gap > 1e-4, t_rel or t[-1])
    if t_far:
        closed = np.nonzero(gap[:k_far] < CLOSED)[0]
        t_open = float(t[closed[-1] + 1]) if len(closed) else float(t[0])
    r['c7_open_ms'] = 1e3 * t_open if t_open else None
    r['c7_open_after_release_ms'] = 1e3 * (t_open - t_rel) if (t_open and t_rel) else None
    # The moving contact's stroke: its largest C7 gap and its turn (from the rest pose).
    k_max = int(np.argmax(gap))
    yaw = c60_csv.yaw(d, 'moving_contact')
    i0 = np.nonzero(pre)[0][-1] if pre.any() else 0
    r['stroke_max_mm'] = 1e3 * float(gap[k_max])
    r['stroke_max_at_ms'] = 1e3 * float(t[k_max])
    r['stroke_end_mm'] = 1e3 * float(gap[-1])
    r['mc_turn_max_deg'] = float(np.degrees(np.max(np.abs(yaw - yaw[i0]))))
    # The sequence: each event's first time after the release.
    ev = [('probe touches the bar (TRIP closes)', t_touch), ('tooth corner takes the load (C4_3/4 > seat)', t_corner),
          ('latch released (C4 > 20 um)', t_rel), ('C7 opens', t_open)]
    for name, grp in [('C6 closes (plate drags the moving contact)', 'C6'), ('C3 closes (plate after-trip stop)', 'C3'),
                      ('FC closes (bar end stop)', 'FC'), ('C5 closes (bar on the hook)', 'C5')]:
        g = c60_csv.group_gap(d, grp)
        ev.append((name, first(t, g < CLOSED, t_rel or t[-1])[0]))
    r['events'] = [(name, 1e3 * tt) for name, tt in sorted(((n_, tt) for n_, tt in ev if tt is not None),
                                                              key=lambda e: e[1])]
    r['events_missing'] = [name for name, tt in ev if tt is None]
    t_self, _ = first(t, (gap > 1e-4) & (t < (t_touch or np.inf)))
    r['self_trip_ms'] = 1e3 * t_self if t_self else None
    if t_self:
        for k in ('touch_ms', 'touch_travel_mm', 'release_ms', 'release_travel_mm', 'corner_ms', 'force_mean_N',
                  'force_peak_0p1ms_N', 'force_peak_at_ms', 'force_peak_travel_mm',
                  'force_peak_0p1ms_after_impact_N', 'force_max_sample_N', 'c7_open_ms', 'c7_open_after_release_ms'):
            r[k] = None
        r['events'] = [('tripped by itself (C7 > 0.1 mm before any touch)', 1e3 * t_self)]
    return r
