#!/usr/bin/python3
"""Collects the sensitivity runs of c60_sensitivity.sh into a markdown table.
  c60_sensitivity.py OUT_DIR DOC.md [DATE COMMIT]"""
import json
import os
import sys

CASES = [('c0', 'ideal joints (x0)', '0', '1'), ('c01', 'clearances x0.1', '0.1', '1'),
         ('c02', 'clearances x0.2', '0.2', '1'), ('c05', 'clearances x0.5', '0.5', '1'),
         ('c1', 'nominal', '1', '1'),
         ('c2', 'clearances x2', '2', '1'), ('f05', 'friction x0.5', '1', '0.5'),
         ('f15', 'friction x1.5', '1', '1.5')]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def run_json(path):
    try:
        with open(path) as f:
            return json.loads(f.read().strip().splitlines()[-1])
    except (OSError, ValueError, IndexError):
        return None


def fmt(v, f='%.2f'):
    return '-' if v is None else f % v


def main():
    out, doc = sys.argv[1], sys.argv[2]
    rows = []
    for key, label, cs, fs in CASES:
        b = load(os.path.join(out, 'sens_%s_bench.json' % key))
        t = load(os.path.join(out, 'sens_%s_trip.json' % key))
        rb = run_json(os.path.join(out, 'sens_%s_bench.run.json' % key))
        rt = run_json(os.path.join(out, 'sens_%s_trip.run.json' % key))
        rows.append('| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |' % (
            label, cs, fs,
            fmt(b and b['equilibrium_force_N']),
            fmt(b and b['hysteresis_mean_N'], '%.3f'),
            fmt(t and t['peak_force_N']),
            fmt(t and t['probe_touch_s'] and 1e3 * t['probe_touch_s'], '%.2f'),
            fmt(t and t['corner_takes_load_s'] and 1e3 * t['corner_takes_load_s'], '%.2f'),
            fmt(t and t['latch_release_s'] and 1e3 * t['latch_release_s'], '%.2f'),
            fmt(t and t['c7_open_s'] and 1e3 * t['c7_open_s'], '%.2f'),
            fmt(rb and rb['unconverged_steps'], '%d') + ' / ' + fmt(rt and rt['unconverged_steps'], '%d'),
            fmt(rb and rb['wall_s'], '%.0f') + ' / ' + fmt(rt and rt['wall_s'], '%.0f'),
            fmt(max((r['max_penetration'] for r in (rb, rt) if r), default=None), '%.2g')))
    made = 'Made by `scripts/c60_sensitivity.sh` (%s, commit %s), on a 2-core machine shared with other work.' % (
        sys.argv[3] if len(sys.argv) > 3 else '?', sys.argv[4] if len(sys.argv) > 4 else '?')
    text = '''# C-60 sensitivity to joint clearance and friction

''' + made + ''' Scene variants come from
`scripts/c60_model/c60_scene.py --clearance-scale S --friction-scale F`: every radial and axial
clearance of J1-J7 and S3 is scaled, or every friction coefficient. The calibrated P3 preload
is kept in every case. Each case runs the bench (`scripts/c60_bench.sh`) and the trip
(`scripts/c60_trip.sh`) at the scenes' dt 1e-5; `C60_CASES="name:cscale:fscale ..."` runs a
subset.

Clearance x0 is the model with ideal revolute joints for J1-J7 and S3 (`urdf/c60_ideal.urdf`,
`--clearance-scale 0`): closed loops of bilateral rows, with frictionless joints. x0.1 gives
radial clearances of 4.5-8.5 um (S3 0.6 um).

Definitions:

- equilibrium force: table force held at 2.0 mm (paper: 15.28 N measured, 14.96 N simulated);
- hysteresis: mean forward - backward table force over 0.2-1.8 mm;
- trip figures as `scripts/analysis/c60_trip_figures.py` defines them: peak tripping force = the
  largest 0.1-ms running mean of the probe force from the touch to the latch release (the
  first-contact impact included);
- corner takes the load: the tooth corner (C4_3 + C4_4) carries more than the seat F4;
- latch release: every C4 pair open by more than 20 um;
- C7 opens: the last sample closed (gap < 1 um) before the C7 gap first passes 0.1 mm
  after the release, with the probe starting at 0.7 ms;
- wall times: this shared machine's, two cases at a time: not comparable with each other.

| case | clearance scale | friction scale | equilibrium force [N] | hysteresis [N] | peak tripping force [N] | touch [ms] | corner takes the load [ms] | latch release [ms] | C7 opens [ms] | unconverged steps bench / trip | wall bench / trip [s] | max penetration [m] |
|---|---|---|---|---|---|---|---|---|---|---|---|---|
''' + '\n'.join(rows) + '\n'
    with open(doc, 'w') as f:
        f.write(text)
    print(text)


if __name__ == '__main__':
    main()
