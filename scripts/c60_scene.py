#!/usr/bin/python3
"""Generates the C-60 breaker scene (URDF + <nscd>) from the published data.

All input numbers are in the authors' units (mm, g, g mm^2, N, N mm) with their
source tags from model-facts.md ([Q-code], [D-code], [Q-paper], [INF], [OWN] =
our own choice); the writer converts to SI. docs/c60.md explains every choice.

  scripts/c60_scene.py                       writes urdf/c60.urdf and urdf/c60_bench.urdf
  scripts/c60_scene.py --out F [--bench] [--clearance-scale S] [--friction-scale S]
                       [--p3-rest R]          writes one variant (sensitivity runs)
"""
import argparse
import math
import os

import numpy as np

MM = 1e-3            # mm -> m
G = 1e-3             # g -> kg
GMM2 = 1e-9          # g mm^2 -> kg m^2
NMM = 1e-3           # N mm (/rad) -> N m (/rad)
NPMM = 1e3           # N/mm -> N/m
DEG = math.pi / 180

# --------------------------------------------------------------------------- bodies
# CAD frame poses at ON: origin (mm) and rotation about global z (deg) [Q-code initPos].
# mass g, CoM in the CAD frame mm, inertia about the CoM in CAD axes g mm^2 [Q-code].
BODIES = {
    'handle': dict(o=(-16.1, 10.0, 0.5), yaw=-19.0, m=1.30, com=(1.123281, 2.939292, 4.001829),
                   I=[[38.91182, -6.015089, -0.28917964], [-6.0150893, 27.959058, -1.9219978],
                      [-0.28917964, -1.9219978, 41.931367]]),
    'rod': dict(o=(-11.659106, 8.461021, 10.3), yaw=-5.47692, m=0.50, com=(7.56245, -1.224523, -0.1585747),
                I=[[2.455011, 0.31330348, -1.465067], [0.31330348, 21.62942, 0.68441857],
                   [-1.465067, 0.68441857, 20.9176]]),
    'hook': dict(o=(7.766977, 7.637695, 7.1), yaw=14.6953, m=0.09, com=(-1.966777, 0.7198357, 1.282473),
                 I=[[0.30507502, 0.08178143, -0.054128496], [0.08178143, 0.4419299, 0.019009435],
                    [-0.054128496, 0.019009435, 0.620631]]),
    'plate': dict(o=(0.0, 0.0, 9.7), yaw=-2.0, m=1.35, com=(3.319088, 4.365461, -4.706395),
                  I=[[29.772412, 3.5465101, 0.47496642], [3.5465101, 25.09582, 0.60505649],
                     [0.47496642, 0.60505649, 37.698441]]),
    'moving_contact': dict(o=(0.0, 0.0, 0.0), yaw=-71.25, m=2.50, com=(7.7911593, -1.7807128, 4.0343125),
                           I=[[23.767882, 0.85414908, -11.814918], [0.85414908, 177.0225, -0.14361701],
                              [-11.814918, -0.14361701, 182.55743]]),
    'trip_bar': dict(o=(7.0, -0.25, 7.1), yaw=36.0, m=0.77, com=(-1.9723481, -2.3250491, -4.9871647),
                     I=[[18.429238, -1.9231011, 5.9362999], [-1.9231011, 31.822293, -0.53010733],
                        [5.9362999, -0.53010733, 27.636361]]),
    # [OWN] our needle frame: on the main axis, mid-length (z -2.7 .. 12.9 [D-code]); the
    # published inertia is a placeholder (identity): solid pin r 1 mm, L 15.6 mm of the
    # published mass 0.1 g.
    'needle': dict(o=(0.0, 0.0, 5.1), yaw=0.0, m=0.10, com=(0, 0, 0),
                   I=[[0.1 * (3 * 1 + 15.6 ** 2) / 12, 0, 0], [0, 0.1 * (3 * 1 + 15.6 ** 2) / 12, 0],
                      [0, 0, 0.1 * 1 / 2]]),
    # [Q-code] probe: -180 deg about y (handled in pose()), CoM (2.844, 0, 0).
    'probe': dict(o=(-5.9, -8.9, 4.65), yaw=None, m=0.8, com=(2.844, 0, 0),
                  I=[[17.8, 0, 0], [0, 161, 0], [0, 0, 161]]),
}


def rotz(deg):
    c, s = math.cos(deg * DEG), math.sin(deg * DEG)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def pose(name):
    if name == 'table':  # bench table frame: on the fixed-contact plane, identity rotation
        c7 = to_world('moving_contact', (20.97, 0.0, 4.5))
        return np.array([c7[0] - 5.2 - TABLE_GAP, c7[1], 4.5]), np.eye(3)
    b = BODIES[name]
    if name == 'probe':
        R = np.array([[-1.0, 0, 0], [0, 1, 0], [0, 0, -1]])  # -180 deg about y
    else:
        R = rotz(b['yaw'])
    return np.array(b['o'], float), R


def to_local(name, p_world):
    """World point (mm) -> body CAD frame (mm), at ON."""
    o, R = pose(name)
    return R.T @ (np.asarray(p_world, float) - o)


def to_world(name, p_local):
    o, R = pose(name)
    return R @ np.asarray(p_local, float) + o


def rpy_of(R):
    """URDF rpy of a rotation matrix (R = Rz(y) Ry(p) Rx(r))."""
    p = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    r = math.atan2(R[2, 1], R[2, 2])
    y = math.atan2(R[1, 0], R[0, 0])
    return r, p, y


def snap(x):
    """x, with round-off around zero (|x| < 1e-15, and -0) written as 0: the last bits
    of a sum that should cancel differ between machines (numpy, libm), and the
    generated URDFs must not."""
    return 0.0 if abs(x) < 1e-15 else x


def fmt(v, scale=MM):
    return ' '.join('%.9g' % snap(x * scale) for x in v)


def fmt_rpy(R):
    R = np.vectorize(snap)(np.asarray(R, dtype=float))  # no sign flip of atan2 at +-pi
    return ' '.join('%.12g' % snap(a) for a in rpy_of(R))


# --------------------------------------------------------------------------- joints
# Joint axes at ON (global x, y) and bearing rings (global z) [D-code, model-facts 2.2];
# journal radius [D-code]; radial clearance of the paper [Q-paper]; friction [OWN from
# Q-paper: plastic-plastic 0.3, steel-plastic 0.1; steel-steel not given: 0.1].
# parent, child, which one carries the journal.
JOINTS = [
    # name  parent            child             journal   axis xy            rings z        r_j   c_r    mu
    ('J1', 'world',          'handle',         'parent', (-16.1, 10.0),     (1.0, 10.1),   2.3,  0.085, 0.3),
    ('J2', 'needle',         'plate',          'parent', (0.0, 0.0),        (4.2, 9.7),    1.0,  0.050, 0.1),
    ('J3', 'plate',          'hook',           'parent', (7.766977, 7.637695), (7.6, 10.5), 1.25, 0.060, 0.1),
    ('J4', 'plate',          'trip_bar',       'parent', (7.0, -0.25),      (7.3, 11.2),   1.1,  0.060, 0.1),
    ('J5', 'handle',         'rod',            'child',  (-11.66, 8.47),    (4.9, 8.86),   0.9,  0.045, 0.1),
    ('J6', 'hook',           'rod',            'child',  (4.865, 6.877),    (7.6, 8.65),   0.9,  0.045, 0.1),
    ('J7', 'needle',         'moving_contact', 'parent', (0.0, 0.0),        (0.5, 3.8),    1.0,  0.055, 0.1),
    # S3: the needle held in the case/cover bores [Q-code offsets: 0.006 mm].
    ('S3', 'world',          'needle',         'child',  (0.0, 0.0),        (-0.5, 10.7),  1.0,  0.006, 0.1),
]
def joints():
    return JOINTS


AXIAL = 0.1          # mm, total axial play of every joint [OWN; D-code: ~0.1 mm handle-case]
BUMPS = 3            # per bearing face [Q-paper: three semi-circular rings]
BUMP_R = 0.2         # mm, section radius of a bump [D-code: S1 rings r 0.2]

# --------------------------------------------------------------------------- springs
K_HANDLE = 3.82      # N mm/rad [Q-code 0.382*10]
A0_HANDLE = 1.99     # rad preload [Q-code]
K_PLATE = 1.16       # N/mm [Q-code]
L0_PLATE = 18.44     # mm [Q-code]
PLATE_ANCHOR_CASE = (11.8, 9.0, 1.95)        # world mm [Q-code]
PLATE_ANCHOR_PLATE = (0.19, 9.0, -7.6)       # plate CAD frame mm [Q-code]
K_P3 = 244.46        # N mm/rad [Q-code]
# P3 relative angle at ON: Delta = th_mc - th_plate - (-54.54 - 22.0) deg; M = K2 (Delta + 0.49).
DELTA_ON = (-71.25 - (-2.0) - (-54.54 - 22.0)) * DEG   # [D-code] 7.29 deg
P3_REST_CODE = -(DELTA_ON + 0.49)                      # rad: torque on MC = K2 * rest at ON


def geometry_points():
    """Derived ON-state points (mm, world) used by the contacts; printed by --info."""
    P = {}
    # C7: contact arc r 5.2 centred 20.97 mm from the MC pivot along its CAD x [D-code].
    P['c7_centre'] = to_world('moving_contact', (20.97, 0.0, 4.5))
    # Hook nose half-rings [Q-code hook-local (-5.675, -0.519), z 0 and 2].
    P['nose'] = to_world('hook', (-5.675, -0.519, 1.0))
    return P


def build(bench=False, cscale=1.0, fscale=1.0, p3_rest=None, dt=1e-5):
    p3_rest = P3_REST_CALIBRATED if p3_rest is None else p3_rest
    out = []
    w = out.append
    w('<?xml version="1.0"?>')
    w('<!-- C-60 miniature circuit breaker mechanism in the ON (closed, latched) state.')
    w('     GENERATED by scripts/c60_scene.py (edit that, not this file); docs/c60.md explains')
    w('     every number and its source. SI units; joint axes along world z; no gravity.')
    w('     clearance scale %g, friction scale %g%s -->' % (cscale, fscale, ', with bench table' if bench else ''))
    w('<robot name="c60%s">' % ('_bench' if bench else ''))

    # ---- ground: case + cover. Visuals only (contacts are declared in <nscd>).
    w('  <link name="world">')
    c7 = geometry_points()['c7_centre']
    x_fixed = c7[0] - 5.2
    vis = [
        # base plate of the case (thin, below everything)
        ('box', (0.0, 0.0, -1.2), (0, 0, 0), (44.0, 40.0, 0.4), 'case'),
        # fixed contact block
        ('box', (x_fixed - 1.5, c7[1], 4.5), (0, 0, 0), (3.0, 4.0, 4.5), 'copper'),
        # case wall around the probe bore
        ('box', (-6.0, -8.9, 4.65), (0, 0, 0), (2.0, 8.0, 8.0), 'case'),
        # handle pin (J1) and needle bosses
        ('cyl', (-16.1, 10.0, 0.0), (0, 0, 0), (2.3, 1.0), 'case'),
        # plate spring case anchor
        ('box', (12.3, 9.0, 1.95), (0, 0, 0), (1.0, 2.0, 2.0), 'case'),
    ]
    w_mesh(w, 'world')
    for kind, xyz, rpy, size, mat in vis:
        w_visual(w, kind, xyz, rpy, size, mat, tag='collision')
    w('  </link>')

    for name in ['handle', 'rod', 'hook', 'plate', 'moving_contact', 'trip_bar', 'needle', 'probe']:
        b = BODIES[name]
        o, R = pose(name)
        I = np.array(b['I']) * GMM2
        w('  <link name="%s">' % name)
        w('    <inertial>')
        w('      <origin xyz="%s"/>' % fmt(b['com']))
        w('      <mass value="%.9g"/>' % (b['m'] * G))
        w('      <inertia ixx="%.9g" ixy="%.9g" ixz="%.9g" iyy="%.9g" iyz="%.9g" izz="%.9g"/>' %
          (I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]))
        w('    </inertial>')
        w_mesh(w, name)
        for v in body_visuals(name):
            w_visual(w, *v, tag='collision')
        w('  </link>')
        w('  <joint name="place_%s" type="floating">' % name)
        w('    <parent link="world"/><child link="%s"/>' % name)
        w('    <origin xyz="%s" rpy="%s"/>' % (fmt(o), fmt_rpy(R)))
        w('  </joint>')

    if bench:
        # Test-bench table [OWN]: a prescribed pusher on linear guides along world +x, its
        # face flush with the moving contact's arc (where the fixed contact touches it).
        w('  <link name="table">')
        w('    <inertial><origin xyz="0 0 0"/><mass value="0.05"/>'
          '<inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>')
        w_visual(w, 'box', (-2.0, 0.0, 0.0), (0, 0, 0), (4.0, 6.0, 2.0), 'table')
        w('  </link>')
        w('  <joint name="place_table" type="floating">')
        w('    <parent link="world"/><child link="table"/>')
        w('    <origin xyz="%s"/>' % fmt(pose('table')[0]))
        w('  </joint>')

    # ---- joint pivot frames: massless links fixed to the bodies, on the joint axis at
    # mid-bearing, axes parallel to the world axes at ON (so every joint angle is 0 at ON).
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints() + [P3_AXIS]:
        zc = 0.5 * (ringz[0] + ringz[1])
        c = np.array([axy[0], axy[1], zc])
        o, R = pose(child)
        w('  <link name="%s_%s"/>' % (child, jn))
        w('  <joint name="%s_%s_mount" type="fixed">' % (child, jn))
        w('    <parent link="%s"/><child link="%s_%s"/>' % (child, child, jn))
        w('    <origin xyz="%s" rpy="%s"/>' % (fmt(R.T @ (c - o)), fmt_rpy(R.T)))
        w('  </joint>')

    w('  <nscd>')
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints() + [P3_AXIS]:
        zc = 0.5 * (ringz[0] + ringz[1])
        c = np.array([axy[0], axy[1], zc])
        if parent == 'world':
            xyz, Rp = c, np.eye(3)
        else:
            o, R = pose(parent)
            xyz, Rp = R.T @ (c - o), R.T
        w('    <joint name="%s" type="revolute" parent="%s" child="%s_%s">' % (jn, parent, child, jn))
        w('      <origin xyz="%s" rpy="%s"/><axis xyz="0 0 1"/>' % (fmt(xyz), fmt_rpy(Rp)))
        w('    </joint>')
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints():
        L = ringz[1] - ringz[0]
        crs = max(cr * cscale, MIN_CLEARANCE)
        w('    <clearance joint="%s" journal="%s" radius="%.9g" radial="%.9g" length="%.9g" axial="%.9g"'
          ' bumps="%d" bump_radius="%.9g" mu="%.9g" e="0"/>' %
          (jn, journal, rj * MM, crs * MM, L * MM, max(AXIAL * cscale, MIN_CLEARANCE) * MM, BUMPS,
           BUMP_R * MM, mu * fscale))
    # P3 needs a joint to define its axis and angle; this one has a 1 m clearance and no
    # bumps, so it never makes a contact: it constrains nothing (see docs/c60.md).
    w('    <clearance joint="P3_axis" journal="parent" radius="1e-3" radial="1" length="1e-3" axial="1"'
      ' bumps="0" mu="0" e="0"/>')

    # ---- springs
    w('    <spring name="P1_handle" type="torsion" joint="J1" stiffness="%.9g" rest_angle="%.9g"/>' %
      (K_HANDLE * NMM, A0_HANDLE))
    w('    <spring name="P2_plate" type="linear" stiffness="%.9g" rest_length="%.9g">' %
      (K_PLATE * NPMM, L0_PLATE * MM))
    w('      <end link="world" xyz="%s"/><end link="plate" xyz="%s"/>' %
      (fmt(PLATE_ANCHOR_CASE), fmt(PLATE_ANCHOR_PLATE)))
    w('    </spring>')
    w('    <spring name="P3_contact" type="torsion" joint="P3_axis" stiffness="%.9g" rest_angle="%.9g"/>' %
      (K_P3 * NMM, p3_rest))

    # ---- contacts
    for c in contacts(bench, fscale, x_fixed):
        w(c)

    # ---- inputs
    w('    <actuator name="handle" type="position" joint="J1" kp="%.9g" kd="%.9g" max_effort="%.9g"/>' %
      (HANDLE_KP, HANDLE_KD, HANDLE_MAX))
    w('    <actuator name="probe" type="prescribed" link="probe" axis="-1 0 0"/>')
    if bench:
        w('    <actuator name="table" type="prescribed" link="table" axis="1 0 0"/>')
    # [OWN] see docs/c60.md "Numerics": positions projected to 1 nm; contacts within 0.1 um
    # stay active (activation_margin), else loaded contacts chatter.
    w('    <simulation dt="%.9g" theta="0.5" gravity="0 0 0" tolerance="1e-8" max_iterations="2000"'
      ' projection="true" projection_tolerance="1e-9" activation_margin="1e-7"/>' % dt)
    w('  </nscd>')
    w('</robot>')
    return '\n'.join(out) + '\n'


TABLE_GAP = 0.001       # mm [OWN]
MIN_CLEARANCE = 0.001   # mm: the "x0" clearance runs use 1 um (the engine needs c > 0)
HANDLE_KP = 0.3         # N m/rad [OWN] handle servo (a user's hand)
HANDLE_KD = 3e-4        # N m s/rad [OWN] about critical for the handle inertia
HANDLE_MAX = 0.1        # N m [OWN]
P3_AXIS = ('P3_axis', 'plate', 'moving_contact', 'parent', (0.0, 0.0), (2.0, 2.0 + 1e-3), 1.0, 1000.0, 0.0)
# [OWN, calibrated] the one parameter fitted to the paper's bench figure (docs/c60.md):
# the P3 preload, so that the bench force at 2.0 mm is 15.28 N.
P3_REST_CALIBRATED = -1.130

# --------------------------------------------------------------------------- contacts


def shape(link, kind, xyz_mm, R=None, **dims):
    R = np.eye(3) if R is None else R
    attrs = ' '.join('%s="%s"' % (k, v) for k, v in dims.items())
    return ('      <shape link="%s" type="%s" %s><origin xyz="%s" rpy="%s"/></shape>' %
            (link, kind, attrs, fmt(xyz_mm), fmt_rpy(R))).replace('  >', '>')


def plane_R(n_world, body=None):
    """Rotation (in the body frame) whose z axis is the world direction n at ON."""
    n = np.asarray(n_world, float)
    n = n / np.linalg.norm(n)
    if body is not None:
        n = pose(body)[1].T @ n
    z = n
    x = np.cross([0, 0, 1.0], z) if abs(z[2]) < 0.9 else np.array([1.0, 0, 0])
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def zcap(link, centre_world, z0, z1, r):
    """A capsule with axis along world z from z0 to z1 (mm) at world xy of centre_world."""
    c = np.array([centre_world[0], centre_world[1], 0.5 * (z0 + z1)])
    R = pose(link)[1].T if link != 'world' else np.eye(3)
    loc = to_local(link, c) if link != 'world' else c
    return shape(link, 'capsule', loc, R, radius='%.9g' % (r * MM), length='%.9g' % ((z1 - z0) * MM))


def plane(link, point_world, n_world):
    loc = to_local(link, point_world) if link != 'world' else np.asarray(point_world, float)
    return shape(link, 'plane', loc, plane_R(n_world, None if link == 'world' else link))


def contact(name, mu, a, b):
    return '    <contact name="%s" mu="%.9g" e="0">\n%s\n%s\n    </contact>' % (name, mu, a, b)


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def perp(v):  # +90 deg about z
    return np.array([-v[1], v[0], 0.0])


def latch_geometry():
    """C4 latch [OWN design on Q-code points]. Why not the published wedge: the bar wedge arc
    (r 5.9 about bar-local (5.957, 4.864)) puts its normal at the nose along (-0.975, -0.222);
    the hook load then turns the bar clockwise, and the nose slides off the arc only when the
    bar turns clockwise too, which the probe (pushing +x below the bar pivot: anticlockwise)
    cannot do, and FC stops. Our face keeps the published nose and makes the probe's
    direction the release direction.

    The hook nose (half rings r 0.5 at hook-local
    (-5.675, -0.519), z 0..2) rests on a flat latch face of the tripping bar. The face
    normal (force on the hook) points at LATCH_ANGLE from +x: it passes 4.4 mm from the
    hook pivot J3 (holds the hook) and just beside the bar pivot J4, so the latch load
    presses the bar against its end stop FC with a small moment (a stable latch); turning
    the bar anticlockwise slides the face along the nose until the nose passes its edge."""
    N = to_world('hook', (-5.675, -0.519, 0.0))[:2]
    n = np.array([math.cos(LATCH_ANGLE * DEG), math.sin(LATCH_ANGLE * DEG)])
    P = N - 0.5 * n                                       # contact point on the face
    t = np.array([n[1], -n[0]])                           # along the face, towards the edge
    return N, n, P, t


LATCH_ANGLE = 150.0    # deg [OWN]
LATCH_ENGAGE = 0.5     # mm [OWN] face length from the contact point to the edge
LATCH_DEPTH = 1.5      # mm [OWN]
LATCH_BACK = 2.0       # mm [OWN] face length behind the contact point


def contacts(bench, fs, x_fixed):
    out = []
    # C1 handle ON stop [OWN position; Q-code: handle flat face vs case rings r 0.5]: a case
    # pin r 0.5 (z 1.5..9.5) against a flat face of the handle at handle-local x = -1.0.
    pin_local = np.array([-1.5, -5.0, 0.0])
    pin = to_world('handle', pin_local)
    n_face = pose('handle')[1] @ np.array([-1.0, 0, 0])
    face_pt = to_world('handle', (-1.0, -5.0, 0.0))
    out.append(contact('C1', 0.3 * fs, zcap('world', pin, 1.5, 9.5, 0.5), plane('handle', face_pt, n_face)))

    # C3 plate stop [OWN position; Q-code: case rings r 0.1 vs plate face]: stops the plate
    # turning clockwise (closing over-travel); touches at ON, unloaded while latched.
    q = np.array([-4.0, 6.0, 5.0])
    u = unit(perp(q) * -1.0)                 # direction q moves when the plate turns clockwise
    ring = q + 0.1 * np.append(u[:2], 0) * 1.0
    out.append(contact('C3', 0.1 * fs, zcap('world', ring, 4.0, 6.0, 0.1), plane('plate', q, u)))

    # C4 latch (hook nose on the bar's latch face) [OWN design, see latch_geometry].
    N, n, P, t = latch_geometry()
    zb0, zb1 = 7.1 - 0.5, 7.1 + 2.5        # bar-local z -0.5..2.5 [Q-code wedge z range]
    centre = P - 0.5 * LATCH_DEPTH * n + 0.5 * (LATCH_ENGAGE - LATCH_BACK) * t
    Rw = np.column_stack([np.append(t, 0), np.append(-n, 0), [0, 0, 1.0]])  # box axes in world
    Rw[:, 1] = np.cross(Rw[:, 2], Rw[:, 0])
    Rb = pose('trip_bar')[1].T @ Rw
    box = shape('trip_bar', 'box', to_local('trip_bar', np.append(centre, 0.5 * (zb0 + zb1))), Rb,
                size=fmt((LATCH_ENGAGE + LATCH_BACK, LATCH_DEPTH, zb1 - zb0)))
    nose = zcap('hook', np.append(N, 0), 7.1, 9.1, 0.5)
    out.append(contact('C4', 0.1 * fs, nose, box))

    # C5 [Q-code]: hook end face = arc r 5.63 about J3 (hook z -0.5..2.5) vs bar half rings
    # r 0.48 at bar-local (-0.75, 7.2), z 0.3 and 2.0. Open at ON (gap 0.036 mm).
    J3 = np.array([7.766977, 7.637695, 0.0])
    ring5 = to_world('trip_bar', (-0.75, 7.2, 0.0))
    out.append(contact('C5', 0.1 * fs, zcap('hook', J3, 6.6, 9.6, 5.63), zcap('trip_bar', ring5, 7.4, 9.1, 0.48)))

    # C6 [Q-code MC stopper circle r 0.2 at MC-local (-9.42, 0.04, 1.8)] vs a plate side face
    # [OWN] placed so that it engages when the plate has turned DELTA_ON anticlockwise relative
    # to the moving contact (the P3 reference angle of the public code).
    s = to_world('moving_contact', (-9.42, 0.04, 1.8))
    s_eng = rotz(-DELTA_ON / DEG) @ s     # the stopper where it meets the face (MC frame turned cw)
    v = unit(perp(s_eng) * -1.0)          # its direction of travel (MC clockwise rel. plate)
    face = s_eng + 0.2 * v
    out.append(contact('C6', 0.1 * fs, zcap('moving_contact', s, 1.3, 2.3, 0.2), plane('plate', face, -v)))

    # C7 [D-code]: MC arc r 5.2 (z 3.5..5.5) vs the fixed contact plane, touching at ON.
    c7 = geometry_points()['c7_centre']
    out.append(contact('C7', 0.1 * fs, zcap('moving_contact', c7, 3.5, 5.5, 5.2),
                       plane('world', (x_fixed, c7[1], 4.5), (1, 0, 0))))

    # TRIP [Q-code bar circles r 6.0, z -1.2..1.4 bar-local; OWN centre so the contact is on
    # the probe axis y = -8.9]: bar arm vs the probe's end face, 0.01 mm apart at ON [Q-code].
    arm = np.array([1.0, -8.9, 0.0])
    out.append(contact('TRIP', 0.1 * fs, zcap('trip_bar', arm, 5.9, 8.5, 6.0),
                       plane('probe', (-5.01, -8.9, 4.65), (1, 0, 0))))
    # FC: bar arm vs the case wall x = -5 [Q-code], touching at ON: the bar's clockwise stop.
    out.append(contact('FC', 0.3 * fs, zcap('trip_bar', arm, 5.9, 8.5, 6.0),
                       plane('world', (-5.0, -8.9, 4.65), (1, 0, 0))))

    if bench:
        # TABLE [OWN]: the table face pushes the MC arc in the C7 band (z 3.5..5.5), starting
        # 1 um behind the fixed contact's plane (so the breaker settles on C7 first);
        # frictionless, so the hysteresis comes from the joints only.
        out.append(contact('TABLE', 0.0, zcap('moving_contact', c7, 3.5, 5.5, 5.2),
                           plane('table', (x_fixed - TABLE_GAP, c7[1], 4.5), (1, 0, 0))))
    return out

# --------------------------------------------------------------------------- visuals


MATERIALS = {'case': (0.55, 0.55, 0.6, 0.35), 'copper': (0.85, 0.5, 0.2, 1), 'handle': (1.0, 0.55, 0.1, 1),
             'rod': (0.95, 0.6, 0.55, 1), 'hook': (0.6, 0.3, 0.85, 1), 'plate': (0.2, 0.7, 0.3, 1),
             'mc': (0.2, 0.4, 0.9, 1), 'bar': (0.9, 0.85, 0.2, 1), 'steel': (0.7, 0.7, 0.75, 1),
             'probe': (0.8, 0.2, 0.2, 1), 'table': (0.3, 0.3, 0.3, 1)}


# The parts as the authors' CAD has them (meshes/README.md): STL in mm, each in its
# part's CAD frame, which is our link frame, except the needle's (ours is turned
# back by 90 deg about x, MESH_RPY).
MESHES = {'world': 'boitier.stl', 'handle': 'manette.stl', 'rod': 'biellette.stl',
          'hook': 'crochet.stl', 'plate': 'platine.stl', 'moving_contact': 'equipage.stl',
          'trip_bar': 'barre.stl', 'needle': 'aiguille.stl', 'probe': 'probe.stl'}
MESH_RPY = {'needle': (math.pi / 2, 0, 0)}
MESH_MATERIAL = {'world': 'case', 'handle': 'handle', 'rod': 'rod', 'hook': 'hook', 'plate': 'plate',
                 'moving_contact': 'mc', 'trip_bar': 'bar', 'needle': 'steel', 'probe': 'probe'}


def w_material(w, mat):
    w('      <material name="%s"><color rgba="%s"/></material>' % (mat, ' '.join('%g' % c for c in MATERIALS[mat])))


def w_mesh(w, link):
    """The part's mesh as the link's visual."""
    w('    <visual>')
    w('      <origin xyz="0 0 0" rpy="%s"/>' % ' '.join('%.12g' % snap(a) for a in MESH_RPY.get(link, (0, 0, 0))))
    w('      <geometry><mesh filename="package://nscd_sim/meshes/%s" scale="0.001 0.001 0.001"/></geometry>'
      % MESHES[link])
    w_material(w, MESH_MATERIAL[link])
    w('    </visual>')


def w_visual(w, kind, xyz, rpy, size, mat, local=True, tag='visual'):
    """A box or cylinder: a <visual>, or a <collision> (the schematic shapes, shown in
    RViz with the RobotModel's collision display; nscd takes no geometry from either)."""
    w('    <%s>' % tag)
    w('      <origin xyz="%s" rpy="%s"/>' % (fmt(xyz), ' '.join('%.9g' % snap(a) for a in rpy)))
    if kind == 'box':
        w('      <geometry><box size="%s"/></geometry>' % fmt(size))
    else:
        w('      <geometry><cylinder radius="%.9g" length="%.9g"/></geometry>' % (size[0] * MM, size[1] * MM))
    if tag == 'visual':
        w_material(w, mat)
    w('    </%s>' % tag)


def bar_between(name, a_world, b_world, width, thick, z, mat):
    """A box visual from world point a to b (xy), in the body's frame."""
    a = to_local(name, (a_world[0], a_world[1], z))
    b = to_local(name, (b_world[0], b_world[1], z))
    d = b - a
    L = math.hypot(d[0], d[1])
    return ('box', 0.5 * (a + b), (0, 0, math.atan2(d[1], d[0])), (L + width, width, thick), mat)


def cyl_at(name, p_world, z0, z1, r, mat):
    c = to_local(name, (p_world[0], p_world[1], 0.5 * (z0 + z1)))
    R = pose(name)[1]
    return ('cyl', c, rpy_of(R.T) if name != 'probe' else (0, 0, 0), (r, z1 - z0), mat)


def body_visuals(name):
    J = {j[0]: j[4] for j in JOINTS}
    v = []
    if name == 'handle':
        top = to_world('handle', (3.0, 12.0, 0))
        v.append(cyl_at(name, J['J1'], 1.0, 10.1, 3.6, 'handle'))
        v.append(bar_between(name, J['J1'], top, 4.0, 6.0, 5.5, 'handle'))
        v.append(bar_between(name, J['J1'], J['J5'], 2.5, 4.0, 6.9, 'handle'))
        v.append(bar_between(name, J['J1'], to_world('handle', (-1.0, -5.0, 0)), 2.0, 6.0, 5.5, 'handle'))
    elif name == 'rod':
        v.append(bar_between(name, J['J5'], J['J6'], 1.8, 1.8, 8.0, 'rod'))
        v.append(cyl_at(name, J['J5'], 3.9, 10.4, 0.9, 'rod'))
        v.append(cyl_at(name, J['J6'], 6.1, 10.4, 0.9, 'rod'))
    elif name == 'hook':
        nose = to_world('hook', (-5.675, -0.519, 0))
        v.append(bar_between(name, J['J3'], nose, 1.6, 2.9, 9.0, 'hook'))
        v.append(cyl_at(name, J['J3'], 7.6, 10.5, 1.8, 'hook'))
        v.append(cyl_at(name, nose, 7.1, 9.1, 0.5, 'hook'))
    elif name == 'plate':
        for a, b in [((0, 0), J['J3']), ((0, 0), J['J4']), (J['J3'], J['J4']), ((0, 0), (-4.0, 6.0))]:
            v.append(bar_between(name, a, b, 2.5, 1.0, 9.2, 'plate'))
        v.append(cyl_at(name, J['J3'], 5.7, 12.7, 1.25, 'steel'))
        v.append(cyl_at(name, J['J4'], 5.7, 12.7, 1.1, 'steel'))
        v.append(cyl_at(name, (0, 0), 4.2, 9.7, 1.6, 'plate'))
    elif name == 'moving_contact':
        tip = to_world('moving_contact', (20.97, 0, 0))
        v.append(bar_between(name, (0, 0), tip, 3.0, 3.0, 2.2, 'mc'))
        v.append(cyl_at(name, tip, 3.5, 5.5, 5.2, 'copper'))
        v.append(cyl_at(name, (0, 0), 0.5, 3.8, 1.8, 'mc'))
        v.append(bar_between(name, (0, 0), to_world('moving_contact', (-9.42, 0.04, 0)), 2.0, 1.5, 1.8, 'mc'))
    elif name == 'trip_bar':
        N, n, P, t = latch_geometry()
        v.append(cyl_at(name, J['J4'], 7.3, 11.2, 1.6, 'bar'))
        v.append(bar_between(name, J['J4'], (1.0, -8.9), 2.0, 2.6, 7.2, 'bar'))
        v.append(bar_between(name, J['J4'], P, 2.0, 3.0, 8.1, 'bar'))
        v.append(cyl_at(name, (1.0, -8.9), 5.9, 8.5, 1.2, 'bar'))
    elif name == 'needle':
        v.append(('cyl', (0, 0, 0), (0, 0, 0), (1.0, 15.6), 'steel'))
    elif name == 'probe':
        # CAD x points along world -x: the body is a cylinder along local x from the face.
        v.append(('cyl', (2.844, 0, 0), (0, math.pi / 2, 0), (1.19, 7.5), 'probe'))
        v.append(('cyl', (-0.5, 0, 0), (0, math.pi / 2, 0), (3.1, 0.8), 'probe'))
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--out', help='write one scene (the options below) to this file')
    ap.add_argument('--out-dir', help='write the shipped scenes (c60.urdf, c60_bench.urdf) here '
                    'instead of the repository\'s urdf/')
    ap.add_argument('--bench', action='store_true')
    ap.add_argument('--clearance-scale', type=float, default=1.0)
    ap.add_argument('--friction-scale', type=float, default=1.0)
    ap.add_argument('--p3-rest', type=float)
    ap.add_argument('--dt', type=float, default=1e-5)
    ap.add_argument('--info', action='store_true')

    a = ap.parse_args()
    if a.info:
        for k, v in geometry_points().items():
            print(k, v)
        print('P3 rest (code)', P3_REST_CODE, 'calibrated', P3_REST_CALIBRATED)
        return
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if a.out:
        text = build(a.bench, a.clearance_scale, a.friction_scale, a.p3_rest, a.dt)
        with open(a.out, 'w') as f:
            f.write(text)
        return
    out_dir = a.out_dir or os.path.join(repo, 'urdf')
    for bench, fn in [(False, 'c60.urdf'), (True, 'c60_bench.urdf')]:
        with open(os.path.join(out_dir, fn), 'w') as f:
            f.write(build(bench))


if __name__ == '__main__':
    main()
