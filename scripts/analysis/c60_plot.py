#!/usr/bin/python3
"""Figures and plots of the C-60 scenarios from nscd_run CSV files.

  c60_plot.py trip   CSV PNG [--json OUT]   tripping force vs probe travel, opening time
  c60_plot.py bench  CSV PNG [--json OUT]   contact force vs table travel, hysteresis, polarisation
  c60_plot.py handle CSV PNG [--json OUT]   handle command/angle and contact gap vs time
  c60_plot.py rest   CSV     [--json OUT]   drift and force balance of the latched ON state

Prints the key figures as text and, with --json, writes them to a file.
"""
import argparse
import json
import math

import numpy as np

# The CSV readers live in c60_csv (c60_trip_figures uses them too); the analyses that
# import c60_plot still find load, yaw, polarisation, group_gap and JOINTS here.
import c60_trip_figures
from c60_csv import BODIES, JOINTS, first_time, group_fn, group_gap, load, polarisation, yaw


def plt_module():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


# --------------------------------------------------------------------------- trip
def trip(d, png):
    """The trip's figures (scripts/analysis/c60_trip_figures.py defines each) and its plot."""
    f = c60_trip_figures.figures(d)
    t = d['t']
    x = d['probe.cmd']               # probe travel from its start, m
    F = d['probe.effort']            # force the driver needs, N (pushing the bar: > 0)
    gap = d['C7.gap']
    c4 = group_gap(d, 'C4')
    s = lambda key: None if f.get(key) is None else 1e-3 * f[key]  # noqa: E731
    touch, t_open = s('touch_ms'), s('c7_open_ms')
    # The first-contact impact: the largest one-sample force in the first 0.02 mm of contact.
    x_touch = 1e-3 * f['touch_travel_mm'] if touch else 0.0
    imp = (x >= x_touch) & (x <= x_touch + 2e-5) & (t >= (touch or t[-1]))
    k_imp = int(np.nonzero(imp)[0][np.argmax(F[imp])]) if imp.any() else int(np.argmax(F))
    res = {'probe_touch_s': touch, 'probe_touch_travel_mm': f['touch_travel_mm'],
           'impact_peak_N': round(float(F[k_imp]), 3),
           'peak_force_N': f.get('force_peak_0p1ms_N'), 'peak_at_travel_mm': f.get('force_peak_travel_mm'),
           'peak_at_s': s('force_peak_at_ms'),
           'mean_push_force_N': f.get('force_mean_N'),
           'corner_takes_load_s': s('corner_ms'),
           'latch_release_s': s('release_ms'), 'c7_open_s': t_open,
           'c7_gap_end_mm': round(float(1e3 * gap[-1]), 3), 'figures': f,
           'after_opening': after_opening(d, f)}
    k = None
    if f.get('force_peak_at_ms') is not None:
        k = int(np.argmin(np.abs(t - 1e-3 * f['force_peak_at_ms'])))
    if png:
        plt = plt_module()
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
        m = t >= (touch if touch else 0) - 2e-4
        ax[0].plot(1e3 * x[m], F[m], 'C0')
        if k is not None:
            # At the peak's value (a 0.1-ms running mean), centred on its window.
            ax[0].plot(1e3 * x[k], f['force_peak_0p1ms_N'], 'o', color='C3', label='0.1-ms peak %.2f N' % f['force_peak_0p1ms_N'])
        ax[0].plot(1e3 * x[k_imp], F[k_imp], 'x', color='k', label='first-contact impact %.2f N' % F[k_imp])
        ax[0].set_xlabel('probe travel [mm]')
        ax[0].set_ylabel('tripping force (probe) [N]')
        ax[0].set_title('C-60 trip: force vs probe travel (0.2 m/s)')
        ax[0].grid(alpha=0.3)
        ax[0].legend()
        ax[1].plot(1e3 * t, 1e3 * gap, 'C1', label='C7 gap (moving-fixed contact)')
        ax[1].plot(1e3 * t, 1e3 * np.minimum(c4, 1e-2), 'C2', label='C4 gap (latch, closest pair; cut at 10 mm)')
        ax[1].plot(1e3 * t, 1e3 * x, 'C0--', label='probe travel')
        if t_open:
            ax[1].axvline(1e3 * t_open, color='C3', lw=0.8)
            ax[1].text(1e3 * t_open, ax[1].get_ylim()[1] * 0.9, ' C7 opens %.2f ms' % (1e3 * t_open), color='C3')
        ax[1].set_xlabel('time [ms]')
        ax[1].set_ylabel('[mm]')
        ax[1].set_title('latch release and contact opening')
        ax[1].grid(alpha=0.3)
        ax[1].legend(loc='upper left', fontsize=8)
        fig.tight_layout()
        fig.savefig(png, dpi=110)
    return res


def after_opening(d, f):
    """What the parts do after C7 opens (docs/c60.md, "After the opening"): the plate's
    swing onto its stop C3 and its rebound, each turn from the published ON pose; C3's
    largest one-sample force, when the plate comes to rest on it and its force over the
    last 1 ms; the largest e/c_r of any joint over the run (above 1: a journal left its
    bearing); the tripping bar's spin at the end and the probe's spin about its own
    axis (world x) over the run."""
    t = d['t']
    if f.get('c7_open_ms') is None:
        return None
    plate = np.degrees(yaw(d, 'plate') - yaw(d, 'plate')[0])
    # The first time the plate comes within 0.01 deg of its largest turn: it may touch
    # C3 again later at the same angle, after its rebound.
    k_max = int(np.nonzero(plate >= plate.max() - 0.01)[0][0])
    c3_gap, c3_fn = group_gap(d, 'C3'), group_fn(d, 'C3')
    hit = np.nonzero((c3_gap < c60_trip_figures.CLOSED) & (t > 1e-3 * f['c7_open_ms']))[0]
    r = {'plate_turn_max_deg': round(float(plate[k_max]), 2), 'plate_turn_max_at_ms': round(1e3 * float(t[k_max]), 2),
         'c3_first_closed_ms': round(1e3 * float(t[hit[0]]), 2) if len(hit) else None,
         'c3_force_max_N': round(float(c3_fn.max()), 2)}
    if len(hit):
        after = t >= t[hit[0]]  # the rebound from the first landing on C3
        r['plate_rebound_min_deg'] = round(float(plate[after].min()), 2)
        open_ = np.nonzero(c3_gap >= c60_trip_figures.CLOSED)[0]
        r['c3_closed_from_ms'] = round(1e3 * float(t[open_[-1] + 1]), 2) if len(open_) and open_[-1] + 1 < len(t) else None
    last = t >= t[-1] - 1e-3
    r['c3_force_last_ms_N'] = round(float(np.mean(c3_fn[last])), 2)
    ecc = [np.max(d[j + '.ecc']) for j in JOINTS if j + '.ecc' in d.dtype.names]
    r['ecc_max'] = round(float(max(ecc)), 4) if ecc else None  # None: ideal joints, no bearing to leave
    r['bar_wz_end_rad_s'] = round(float(d['trip_bar.wz'][-1]), 1)
    r['probe_spin_max_rad_s'] = round(float(np.max(np.abs(d['probe.wx']))), 1)
    return r


# --------------------------------------------------------------------------- bench
def bench(d, png):
    t = d['t']
    x = d['table.cmd']
    F = d['table.effort']
    xmax = x.max()
    dx = np.gradient(x, t)
    fwd = dx > 1e-6
    bwd = dx < -1e-6
    # Static equilibrium at the end of the forward stroke: the hold at full travel.
    hold = (x > xmax - 1e-9) & ~fwd & ~bwd
    th = t[hold]
    late = hold & (t >= th[0] + 0.5 * (th[-1] - th[0])) if len(th) else hold
    F_eq = float(np.mean(F[late]))
    # Hysteresis: forward minus backward force at equal travel (0.2 .. 1.8 mm).
    grid = np.linspace(0.1 * xmax, 0.9 * xmax, 41)
    ff = np.interp(grid, x[fwd], F[fwd])
    order = np.argsort(x[bwd])
    fb = np.interp(grid, x[bwd][order], F[bwd][order])
    width = ff - fb
    i_eq = np.nonzero(late)[0][-1]
    # Chatter in the hold: steps whose table force drops to 0 between loaded ones (the
    # moving contact opening and closing every other step, a step-size artefact that
    # lowers F_eq; docs/c60.md). Counted over the steps F_eq averages (the hold's
    # first steps carry the stroke's stop, an impulse either way); 0 if unloaded.
    F_late = F[late]
    scale = float(np.median(F_late)) if len(F_late) else 0.0
    hold_zero = int(np.sum(np.abs(F_late) <= 1e-3 * scale)) if scale > 0 else 0
    i0 = np.nonzero(t < (t[fwd][0] if fwd.any() else t[-1]))[0][-1]
    res = {'equilibrium_force_N': round(F_eq, 3), 'paper_measured_N': 15.28, 'paper_simulated_N': 14.96,
           'rel_error_vs_measured_pct': round(100 * (F_eq - 15.28) / 15.28, 2),
           'force_start_fwd_N': round(float(ff[0]), 3), 'force_end_fwd_N': round(float(np.interp(0.9 * xmax, x[fwd], F[fwd])), 3),
           'hysteresis_mean_N': round(float(np.mean(width)), 4), 'hysteresis_max_N': round(float(np.max(np.abs(width))), 4),
           'hysteresis_at_1mm_N': round(float(np.interp(0.5 * xmax, grid, width)), 4),
           'hold_steps_averaged': int(late.sum()), 'hold_zero_force_steps': hold_zero,
           'stiffness_fwd_N_per_mm': round(float(np.polyfit(1e3 * grid, ff, 1)[0]), 4),
           'polarisation_before': polarisation(d, i0), 'polarisation_at_2mm': polarisation(d, i_eq),
           'polarisation_end': polarisation(d, len(t) - 1)}
    if png:
        plt = plt_module()
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={'width_ratios': [1.4, 1]})
        ax[0].plot(1e3 * x[fwd], F[fwd], 'C3', label='forward (opening)')
        ax[0].plot(1e3 * x[bwd], F[bwd], 'C0', label='backward (closing)')
        ax[0].plot([1e3 * xmax], [F_eq], 'ks', label='static equilibrium %.2f N' % F_eq)
        ax[0].plot([2.0], [15.28], 'r*', ms=10, label='paper: measured 15.28 N')
        ax[0].plot([2.0], [14.96], 'b*', ms=10, label='paper: simulated 14.96 N')
        on = x > 2e-5
        lo = min(F[on].min(), 14.96) - 0.5
        ax[0].set_ylim(lo, max(F[on].max(), 15.28) + 0.4)
        ax[0].text(0.02, lo + 0.15, 'force jumps from 0 at 0 mm: the table takes over the C7 load', fontsize=7)
        ax[0].set_xlabel('table travel [mm]')
        ax[0].set_ylabel('contact force (table) [N]')
        ax[0].set_title('C-60 contact-force bench (cf. paper Fig. 7)')
        ax[0].grid(alpha=0.3)
        ax[0].legend(fontsize=8, loc='lower right')
        ax[1].plot(1e3 * grid, 1e3 * width, 'C2')
        ax[1].set_xlabel('table travel [mm]')
        ax[1].set_ylabel('forward - backward force [mN]')
        ax[1].set_title('hysteresis (joint friction)')
        ax[1].grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(png, dpi=110)
        # Polarisation plot: eccentricity vectors of the joints at rest and at 2 mm.
        fig, ax = plt.subplots(figsize=(5.2, 5))
        th = np.linspace(0, 2 * np.pi, 100)
        ax.plot(np.cos(th), np.sin(th), 'k', lw=0.5)
        for i, (lab, mk) in enumerate([('polarisation_before', 'o'), ('polarisation_at_2mm', 'x')]):
            for j, p in res[lab].items():
                a = math.radians(p['dir_deg'])
                ax.plot([0, p['ecc'] * math.cos(a)], [0, p['ecc'] * math.sin(a)], color='C%d' % JOINTS.index(j),
                        marker=mk, lw=0.8, label=j if i == 0 else None)
        ax.set_aspect('equal')
        ax.set_title('joint polarisation: e/c_r, world frame\n(o before the bench, x at 2 mm)')
        ax.legend(fontsize=7, loc='upper right')
        fig.tight_layout()
        fig.savefig(png.replace('.png', '_polarisation.png'), dpi=110)
    return res


# --------------------------------------------------------------------------- handle
def handle(d, png):
    t = d['t']
    ang = yaw(d, 'handle')
    ang = np.degrees(ang - ang[0])
    gap = d['C7.gap']
    t_open = first_time(t, (t > 0.002) & (gap > 1e-5))   # after the settling closed it
    plate = yaw(d, 'plate')
    plate = np.degrees(plate - plate[0])
    effort = np.abs(d['handle.effort'])
    back = t > d['t'][np.argmax(d['handle.cmd'])]           # the command on its way back
    sat = back & (effort >= 0.999 * effort.max())
    res = {'handle_max_deg': round(float(ang.max()), 2), 'handle_end_deg': round(float(ang[-1]), 2),
           'c7_open_s': t_open,
           'c7_gap_end_mm': round(float(1e3 * gap[-1]), 3),
           'c7_gap_max_mm': round(float(1e3 * gap.max()), 3),
           'c7_reclosed_s': first_time(t, (t > (t_open or t[-1])) & (gap < 1e-6)),
           'c4_gap_end_mm': round(float(1e3 * min(group_gap(d, 'C4')[-1], 1.0)), 3),
           'plate_max_deg': round(float(plate.max()), 2), 'plate_end_deg': round(float(plate[-1]), 2),
           'effort_max_Nm': round(float(effort.max()), 4),
           'saturated_on_the_way_back_s': first_time(t, sat),
           'handle_deg_when_saturated': round(float(ang[np.nonzero(sat)[0][0]]), 2) if sat.any() else None}
    if png:
        plt = plt_module()
        fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        ax[0].plot(1e3 * t, np.degrees(d['handle.cmd']), 'k--', label='command')
        ax[0].plot(1e3 * t, ang, 'C1', label='handle angle (from ON)')
        for b, c in [('plate', 'C2'), ('moving_contact', 'C0'), ('hook', 'C4')]:
            a = yaw(d, b)
            ax[0].plot(1e3 * t, np.degrees(a - a[0]), c, lw=0.8, label=b)
        ax[0].set_ylabel('[deg]')
        ax[0].legend(fontsize=8)
        ax[0].grid(alpha=0.3)
        ax[0].set_title('C-60 handle ON -> OFF -> ON command')
        ax[1].plot(1e3 * t, 1e3 * gap, 'C1', label='C7 gap')
        ax[1].plot(1e3 * t, 1e3 * np.minimum(group_gap(d, 'C4'), 1e-3), 'C2', label='C4 gap (latch, closest pair; cut at 1 mm)')
        ax[1].plot(1e3 * t, 1e3 * d['handle.effort'], 'C3', lw=0.8, label='handle torque [N mm]')
        ax[1].set_xlabel('time [ms]')
        ax[1].set_ylabel('[mm], [N mm]')
        ax[1].legend(fontsize=8)
        ax[1].grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(png, dpi=110)
    return res


# --------------------------------------------------------------------------- rest
def rest(d, png):
    t = d['t']
    half = t >= 0.5 * t[-1]
    i0 = np.nonzero(half)[0][0]
    drift = {}
    for b in BODIES:
        a = yaw(d, b)
        drift[b] = {'dyaw_urad': round(float(1e6 * (a[-1] - a[i0])), 3),
                    'dxy_nm': round(float(1e9 * math.hypot(d[b + '.x'][-1] - d[b + '.x'][i0], d[b + '.y'][-1] - d[b + '.y'][i0])), 3),
                    'vmax_mm_s': round(float(1e3 * np.max(np.hypot(d[b + '.vx'][half], d[b + '.vy'][half]))), 5)}
    names = [n[:-3] for n in d.dtype.names if n.endswith('.fn')]
    forces = {n: {'mean': round(float(np.mean(d[n + '.fn'][half])), 4),
                  'spread': round(float(np.ptp(d[n + '.fn'][half])), 5)} for n in names}
    gaps = {n[:-4]: round(float(1e6 * d[n][-1]), 4) for n in d.dtype.names
            if n.endswith('.gap') and np.isfinite(d[n][-1])}
    # The settling: each part's turn and centre-of-mass displacement from the published ON
    # pose (the first row) to 4 ms, when the joints have taken up their clearances.
    k4 = int(np.argmin(np.abs(t - 0.004)))
    settling = {b: {'yaw_deg': round(float(np.degrees(yaw(d, b)[k4] - yaw(d, b)[0])), 3),
                    'com_moved_um': round(float(1e6 * math.sqrt(sum((d[b + '.' + c][k4] - d[b + '.' + c][0]) ** 2
                                                                     for c in 'xyz'))), 1)} for b in BODIES}
    # The springs and the handle servo at the end (the scene's signs: P2 a tension, P3 the
    # moment on its second body, the moving contact).
    loads = {'P1_handle_Nmm': round(1e3 * float(d['P1_handle.force'][-1]), 3),
             'P2_plate_N': round(float(d['P2_plate.force'][-1]), 3),
             'P3_contact_Nm': round(float(d['P3_contact.force'][-1]), 4),
             'handle_servo_Nmm': round(1e3 * float(d['handle.effort'][-1]), 3)}
    return {'window_s': [float(t[i0]), float(t[-1])], 'settling_to_4ms': settling, 'drift': drift,
            'forces_N': forces, 'gaps_um': gaps, 'loads_end': loads,
            'latched': bool(group_gap(d, 'C4')[-1] < 1e-6 and d['C7.gap'][-1] < 1e-6),
            'polarisation': polarisation(d, len(t) - 1)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('kind', choices=['trip', 'bench', 'handle', 'rest'])
    ap.add_argument('csv')
    ap.add_argument('png', nargs='?')
    ap.add_argument('--json')
    a = ap.parse_args()
    d = load(a.csv)
    res = {'trip': trip, 'bench': bench, 'handle': handle, 'rest': rest}[a.kind](d, a.png)
    print(json.dumps(res, indent=1))
    if a.json:
        with open(a.json, 'w') as f:
            json.dump(res, f, indent=1)


if __name__ == '__main__':
    main()
