#!/usr/bin/python3
"""The C-60's nscd_run CSV read: the joints, bodies and contact groups of the scene and
the quantities derived from their columns. Shared by the figure definitions
(c60_trip_figures.py) and the plots (c60_plot.py), which import it and not each other.

  load(CSV) -> structured array; yaw(d, body); polarisation(d, row);
  group(d, name, suffix), group_gap(d, name), group_fn(d, name); first_time(t, mask)
"""
import math
import sys

import numpy as np

JOINTS = ['J1', 'J2', 'J3', 'J4', 'J5', 'J6', 'J7', 'S3']
BEARING = {'J1': 'handle', 'J2': 'plate', 'J3': 'hook', 'J4': 'trip_bar', 'J5': 'handle', 'J6': 'hook',
           'J7': 'moving_contact', 'S3': None}
BODIES = ['handle', 'rod', 'hook', 'plate', 'moving_contact', 'trip_bar', 'needle']


def load(path):
    d = np.genfromtxt(path, delimiter=',', names=True, deletechars='')
    if d.ndim == 0 or len(d) < 2:
        sys.exit('%s: no data' % path)
    return d


def yaw(d, b):
    qw, qx, qy, qz = (d[b + '.q' + c] for c in 'wxyz')
    return np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


def polarisation(d, i):
    """Per joint: eccentricity / c_r and its direction in the world frame (deg) at row i."""
    out = {}
    for j in JOINTS:
        if j + '.ecc' not in d.dtype.names:
            continue
        ang = d[j + '.ecc_angle'][i] + (yaw(d, BEARING[j])[i] if BEARING[j] else 0.0)
        out[j] = {'ecc': round(float(d[j + '.ecc'][i]), 3),
                  'dir_deg': round(float((math.degrees(ang) + 180) % 360 - 180), 1),
                  'fn': round(float(d[j + '.fn'][i]), 3)}
    return out


def group(d, name, suffix):
    """The columns of a contact group: `name` and `name_*` (C4, C4_2, C4_F2, ...: a CAD
    contact with several point pairs is several <contact>s, docs/c60.md)."""
    return [n for n in d.dtype.names if n.endswith(suffix) and
            (n[:-len(suffix)] == name or n[:-len(suffix)].startswith(name + '_'))]


def group_gap(d, name):
    """Smallest gap of the group's pairs, per row (inf where none has a point)."""
    return np.min(np.vstack([d[n] for n in group(d, name, '.gap')]), axis=0)


def group_fn(d, name):
    return np.sum(np.vstack([d[n] for n in group(d, name, '.fn')]), axis=0)


def first_time(t, mask):
    idx = np.nonzero(mask)[0]
    return float(t[idx[0]]) if len(idx) else None
