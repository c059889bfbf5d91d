#!/usr/bin/python3
"""Top view (along z) of the C-60 scene at ON: joints, contact primitives, spring anchors.
  c60_layout.py [PNG]   (default docs/c60_layout.png)"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import c60_scene as S  # noqa: E402


def main():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    png = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', 'docs', 'c60_layout.png')
    fig, ax = plt.subplots(figsize=(8, 8))
    col = {'handle': 'C1', 'rod': 'C5', 'hook': 'C4', 'plate': 'C2', 'moving_contact': 'C0', 'trip_bar': 'C8',
           'needle': 'k', 'world': '0.4', 'probe': 'C3', 'table': '0.2'}
    # links between joints (kinematic skeleton)
    J = {j[0]: np.array(j[4]) for j in S.JOINTS}
    nose = S.to_world('hook', (-5.675, -0.519, 0))[:2]
    tip = S.to_world('moving_contact', (20.97, 0, 0))[:2]
    for a, b, body in [(J['J1'], J['J5'], 'handle'), (J['J5'], J['J6'], 'rod'), (J['J3'], J['J6'], 'hook'),
                       (J['J6'], nose, 'hook'), (J['J2'], J['J3'], 'plate'), (J['J2'], J['J4'], 'plate'),
                       (J['J3'], J['J4'], 'plate'), (J['J4'], np.array([1.0, -8.9]), 'trip_bar'),
                       (J['J7'], tip, 'moving_contact')]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color=col[body], lw=3, alpha=0.5, solid_capstyle='round')
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in S.JOINTS:
        ax.add_patch(plt.Circle(axy, rj + cr, fill=False, color=col[child]))
        ax.add_patch(plt.Circle(axy, rj, fill=False, color=col[parent], ls=':'))
        ax.annotate(jn, axy, xytext=(4, 4), textcoords='offset points', fontsize=8)
    # contact primitives, parsed back from the generated contact XML
    import re
    for c in S.contacts(True, 1.0, S.geometry_points()['c7_centre'][0] - 5.2):
        name = re.search(r'contact name="(\w+)"', c).group(1)
        first = True
        for m in re.finditer(r'<shape link="(\w+)" type="(\w+)"([^>]*)><origin xyz="([^"]+)" rpy="([^"]+)"', c):
            link, kind, attrs, xyz, rpy = m.groups()
            p = np.array([float(v) for v in xyz.split()]) * 1e3
            r, pch, y = (float(v) for v in rpy.split())
            Rl = S.rotz(math.degrees(y))  # shapes here only turn about z, or are planes
            if link != 'world':
                o, R = S.pose(link)
                pw = R @ p + o
                Rw = R
            else:
                pw, Rw = p, np.eye(3)
            cc = col[link]
            if kind == 'capsule':
                rad = float(re.search(r'radius="([^"]+)"', attrs).group(1)) * 1e3
                ax.add_patch(plt.Circle(pw[:2], rad, fill=False, color=cc, lw=1.2))
            elif kind == 'box':
                size = [float(v) * 1e3 for v in re.search(r'size="([^"]+)"', attrs).group(1).split()]
                Rb = Rw @ Rl
                corners = [Rb @ np.array([sx * size[0] / 2, sy * size[1] / 2, 0]) + pw
                           for sx, sy in [(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)]]
                ax.plot([q[0] for q in corners], [q[1] for q in corners], color=cc, lw=1.2)
            elif kind == 'plane':
                # plane normal = z axis of Rz(y) Ry(p) Rx(r)
                cr_, sr = math.cos(r), math.sin(r)
                cp, sp = math.cos(pch), math.sin(pch)
                cy, sy = math.cos(y), math.sin(y)
                Rf = np.array([[cy * cp, cy * sp * sr - sy * cr_, cy * sp * cr_ + sy * sr],
                               [sy * cp, sy * sp * sr + cy * cr_, sy * sp * cr_ - cy * sr],
                               [-sp, cp * sr, cp * cr_]])
                n = (Rw @ Rf)[:, 2]
                t = np.array([-n[1], n[0]])
                seg = np.array([pw[:2] - 2.5 * t, pw[:2] + 2.5 * t])
                ax.plot(seg[:, 0], seg[:, 1], color=cc, lw=2)
                ax.annotate('', pw[:2] + 1.2 * n[:2], pw[:2], arrowprops=dict(arrowstyle='->', color=cc))
            if first:
                ax.annotate(name, pw[:2], xytext=(-14, -12), textcoords='offset points', fontsize=8, color='r')
                first = False
    a = np.array(S.PLATE_ANCHOR_CASE[:2])
    b = S.to_world('plate', S.PLATE_ANCHOR_PLATE)[:2]
    ax.plot([a[0], b[0]], [a[1], b[1]], 'g--', lw=1)
    ax.annotate('P2', (a + b) / 2, fontsize=8, color='g')
    ax.set_aspect('equal')
    ax.set_xlim(-24, 16)
    ax.set_ylim(-27, 15)
    ax.grid(alpha=0.2)
    ax.set_xlabel('x [mm]')
    ax.set_ylabel('y [mm]')
    ax.set_title('C-60 at ON, top view (z): joints (bore solid, pin dotted),\n'
                 'contact primitives (circles: capsules along z; lines+arrow: planes; box: latch)')
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == '__main__':
    main()
