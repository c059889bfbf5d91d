#!/usr/bin/python3
"""What statics expects of the C-60 latch and of the tripping force (docs/c60.md, "Trip:
main model vs the authors' model"), from the ON geometry (model-facts 0, the CAD table)
and the springs of each model; with nscd_run trip CSVs, the same at the settled pose
before the touch, next to what the run gives.

  c60_statics.py [LABEL=CSV ...]

Planar, rigid, quasi-static; mm, N, N mm.
1. The rod J5-J6 is a two-force member. Plate + hook + bar together: the springs' moment
   on the plate about J2 (P2 + P3) is held by the rod's force on the hook at J6 alone
   (J3, J4 and the latch are internal): f = -M_springs / (J6 x u)_z.
2. The hook about J3: the latch normal N (on the hook along (-0.588, 0.809), CAD arm
   -5.4644 mm about J3) balances the rod: N = f (J6 - J3) x u / 5.4644.
3. The bar about J4, turned anticlockwise by the probe (force P along +x at TRIP, 8.81 mm
   below J4 and b_T = 11.6 mm to its -x side, where the bar's arc slides down the probe
   face): the seat's friction mu_s N at h = 7.0 mm from J4 (F4 is bar-local y = 7.0)
   resists; the normal, at bar-local x_n of the nose (CAD -0.208), helps by N |x_n|;
   J4's friction mu_4 N r_4 resists; the probe face's friction mu_T P at b_T resists:
   P = (mu_s N h - N |x_n| + mu_4 N r_4) / (a_T - mu_T b_T).
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'c60_model'))
import c60_scene as S  # noqa: E402

J2 = np.array([0.0, 0.0])
J3 = np.array([7.766977, 7.637695])
J4 = np.array([7.0, -0.25])
J5 = np.array([-11.66, 8.47])
J6 = np.array([4.865, 6.877])
N_HOOK = np.array([-0.5878, 0.809])      # latch normal on the hook, world [CAD row 14]
ARM_C4_J3 = 5.4644                       # mm, its arm about J3 (clockwise on the hook) [CAD]
NOSE_HOOK = np.array([-5.4829, -0.9804])  # the nose's apex, hook-local [model-facts 0]
H_SEAT = 7.0                             # mm, F4 from J4 (bar-local y = 7.0)
A_T, B_T = 8.81, 11.6                    # mm, TRIP below J4 / to its -x side [model-facts 0, CAD]
MU_S, MU_T = 0.2, 0.1                    # seat (C4), probe face (TRIP) [Q-code]
R_4 = 1.1                                # mm, J4's journal


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def p2_moment(along_line=True):
    """P2's moment on the plate about J2 at ON; along the spring line (a spring) or along
    plate-local -x (the plugin)."""
    a = np.array(S.PLATE_ANCHOR_CASE)
    o, R = S.pose('plate')
    b = R @ np.array(S.PLATE_ANCHOR_PLATE) + o
    L = np.linalg.norm(a - b)
    F = S.K_PLATE * (S.L0_PLATE - L)
    d = (b - a) / L if along_line else -R[:, 0]
    return cross(b[:2], F * d[:2]), F


def latch(m_springs):
    u = (J6 - J5) / np.linalg.norm(J6 - J5)
    f = -m_springs / cross(J6, u)
    n = f * cross(J6 - J3, u) / ARM_C4_J3
    return f, n


def push(n, x_n, mu_4):
    return (MU_S * n * H_SEAT - n * abs(x_n) + mu_4 * n * R_4) / (A_T - MU_T * B_T)


def case(label, m_p3, mu_4, x_n=-0.208, p2_line=True, plate_factor=1.0):
    m2, F2 = p2_moment(p2_line)
    ms = m2 + plate_factor * m_p3
    f, n = latch(ms)
    p = push(n, x_n, mu_4)
    print('| %s | %.1f | %.1f | %.1f | %.2f | %.2f | %.3f | %.2f | %.2f |' %
          (label, m2, plate_factor * m_p3, f, n, MU_S * n * H_SEAT, x_n, n * abs(x_n), p))
    return n, p


def settled(path):
    """Mean P3 moment, C7 force, seat force and the nose's bar-local x over the last 0.5 ms
    before the touch."""
    import c60_plot as P
    d = P.load(path)
    t = d['t']
    touch = t[np.nonzero((d['TRIP.gap'] < 1e-6) & (d['probe.cmd'] > 0))[0][0]]
    w = (t > touch - 5e-4) & (t < touch)

    def frame(b, i):
        q = [d[b + '.q' + c][i] for c in 'wxyz']
        w_, x, y, z = q
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w_ * z), 2 * (x * z + w_ * y)],
                      [2 * (x * y + w_ * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w_ * x)],
                      [2 * (x * z - w_ * y), 2 * (y * z + w_ * x), 1 - 2 * (x * x + y * y)]])
        com = np.array([d[b + '.' + c][i] for c in 'xyz']) * 1e3
        return com - R @ np.array(S.BODIES[b]['com']), R
    xs = []
    for i in np.nonzero(w)[0]:
        oh, Rh = frame('hook', i)
        ob, Rb = frame('trip_bar', i)
        p = Rh @ np.array([NOSE_HOOK[0], NOSE_HOOK[1], 1.0]) + oh
        xs.append((Rb.T @ (p - ob))[0])
    return dict(p3=1e3 * abs(np.mean(d['P3_contact.force'][w])), c7=np.mean(d['C7.fn'][w]),
                seat=np.mean(d['C4.fn'][w] + d['C4_2.fn'][w]), x_n=float(np.mean(xs)), touch_ms=1e3 * touch)


def main():
    m_code = S.K_P3 * (S.DELTA_ON + 0.49)
    m_cal = S.K_P3 * -S.P3_REST_CALIBRATED
    print('At the published ON pose (CAD): P2 %.2f N; P3 %.1f N mm (code preload), %.1f (calibrated)\n'
          % (p2_moment()[1], m_code, m_cal))
    print('| case | P2 moment | P3 on the plate | rod force f | latch N | seat friction moment mu N h | '
          'nose x_n | normal\'s moment N abs(x_n) | push P expected [N] |')
    print('|---|---|---|---|---|---|---|---|---|')
    case('main (calibrated P3, spring P2), at ON', m_cal, 0.1)
    case('authors: physical torque pair, spring P2, at ON', m_code, 0.1)
    case('authors as the plugin applies them (1.25 M on the plate, P2 along plate -x), at ON',
         m_code, 0.1, p2_line=False, plate_factor=1.25)
    for spec in sys.argv[1:]:
        label, path = spec.split('=', 1)
        s = settled(path)
        n, p = case('%s, settled before the touch (P3 %.1f N mm, nose x %.3f)' % (label, s['p3'], s['x_n']),
                    s['p3'], 0.1, x_n=s['x_n'])
        print('|   %s run: seat %.2f N (statics %.2f); C7 %.2f N (P3 / 19.85 mm: %.2f) |' %
              (label, s['seat'], n, s['c7'], s['p3'] / 19.85))


if __name__ == '__main__':
    main()
