#!/usr/bin/python3
"""Top view (along z) of the C-60 scene at ON: joints, contact primitives, spring anchors.
  c60_layout.py [PNG]   (default docs/c60_layout.png)"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import c60_scene as S  # noqa: E402


def rpy_matrix(r, p, y):
    """URDF rpy -> rotation matrix (Rz(y) Ry(p) Rx(r))."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def main():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    png = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..', 'docs', 'c60_layout.png')
    fig, ax = plt.subplots(figsize=(8, 8))
    col = {'handle': 'C1', 'rod': 'C5', 'hook': 'C4', 'plate': 'C2', 'moving_contact': 'C0', 'trip_bar': 'C8',
           'needle': 'k', 'world': '0.4', 'probe': 'C3', 'table': '0.2'}
    # links between joints (kinematic skeleton)
    J = {j[0]: np.array(j[4]) for j in S.JOINTS}
    nose = S.to_world('hook', (-5.675, -0.519, 0))[:2]
    tip = S.geometry_points()['c7_centre'][:2]
    for a, b, body in [(J['J1'], J['J5'], 'handle'), (J['J5'], J['J6'], 'rod'), (J['J3'], J['J6'], 'hook'),
                       (J['J6'], nose, 'hook'), (J['J2'], J['J3'], 'plate'), (J['J2'], J['J4'], 'plate'),
                       (J['J3'], J['J4'], 'plate'), (J['J4'], S.to_world('trip_bar', (-9.7174, -3.8291, 0))[:2], 'trip_bar'),
                       (J['J7'], tip, 'moving_contact')]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color=col[body], lw=3, alpha=0.5, solid_capstyle='round')
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in S.JOINTS:
        ax.add_patch(plt.Circle(axy, rj + cr, fill=False, color=col[child]))
        ax.add_patch(plt.Circle(axy, rj, fill=False, color=col[parent], ls=':'))
        ax.annotate(jn, axy, xytext=(4, 4), textcoords='offset points', fontsize=8)
    # contact primitives, parsed back from the generated contact XML
    import re
    for c in S.contacts(True, 1.0):
        name = re.search(r'contact name="(\w+)"', c).group(1)
        if name.endswith(('_F1', '_F2', '_F3')) or name == 'TRIP_upper':
            label = None   # drawn, not labelled (they overlap C4 / TRIP at this scale)
        else:
            label = name
        for m in re.finditer(r'<shape link="(\w+)" type="(\w+)"([^>]*)><origin xyz="([^"]+)" rpy="([^"]+)"', c):
            link, kind, attrs, xyz, rpy = m.groups()
            p = np.array([float(v) for v in xyz.split()]) * 1e3
            Rf = rpy_matrix(*(float(v) for v in rpy.split()))
            o, R = (S.pose(link) if link != 'world' else (np.zeros(3), np.eye(3)))
            pw, Rs = R @ p + o, R @ Rf          # shape frame in the world, mm
            cc = col[link]

            def attr(k, default=None):
                m2 = re.search(k + r'="([^"]+)"', attrs)
                return float(m2.group(1)) if m2 else default
            if kind in ('ring', 'cylinder'):
                rad = attr('radius') * 1e3
                a0, sp = attr('start', 0.0), attr('span', 2 * math.pi)
                th = np.linspace(a0, a0 + sp, 60)
                pts = np.array([pw + rad * (math.cos(q) * Rs[:, 0] + math.sin(q) * Rs[:, 1]) for q in th])
                ax.plot(pts[:, 0], pts[:, 1], color=cc, lw=1.2 if kind == 'ring' else 2.0)
                anchor = pts[len(pts) // 2, :2]
            elif kind == 'face':
                sx, sy = (float(v) * 1e3 for v in re.search(r'size="([^"]+)"', attrs).group(1).split())
                corners = np.array([pw + u * sx / 2 * Rs[:, 0] + v * sy / 2 * Rs[:, 1]
                                    for u, v in [(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)]])
                ax.plot(corners[:, 0], corners[:, 1], color=cc, lw=2)
                n = Rs[:, 2]
                ax.annotate('', pw[:2] + 0.8 * n[:2], pw[:2], arrowprops=dict(arrowstyle='->', color=cc))
                anchor = pw[:2]
            elif kind == 'plane':
                n = Rs[:, 2]
                t = np.array([-n[1], n[0]])
                seg = np.array([pw[:2] - 2.5 * t, pw[:2] + 2.5 * t])
                ax.plot(seg[:, 0], seg[:, 1], color=cc, lw=2, ls='--')
                ax.annotate('', pw[:2] + 1.2 * n[:2], pw[:2], arrowprops=dict(arrowstyle='->', color=cc))
                anchor = pw[:2]
            if label:
                ax.annotate(label, anchor, xytext=(-14, -12), textcoords='offset points', fontsize=7, color='r')
                label = None
    a = np.array(S.PLATE_ANCHOR_CASE[:2])
    b = S.to_world('plate', S.PLATE_ANCHOR_PLATE)[:2]
    ax.plot([a[0], b[0]], [a[1], b[1]], 'g--', lw=1)
    ax.annotate('P2', (a + b) / 2, fontsize=8, color='g')
    ax.set_aspect('equal')
    ax.set_xlim(-24, 16)
    ax.set_ylim(-27, 16)
    ax.grid(alpha=0.2)
    ax.set_xlabel('x [mm]')
    ax.set_ylabel('y [mm]')
    ax.set_title('C-60 at ON, top view (z): joints (bore solid, pin dotted),\n'
                 'contact shapes from the CAD (arcs: rings, thick arcs: cylinder arcs; '
                 'segments+arrow: faces; dashed: planes)', fontsize=9)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == '__main__':
    main()
