#!/usr/bin/python3
"""Generates the C-60 breaker scene (URDF + <nscd>) from the published data.

All input numbers are in the authors' units (mm, g, g mm^2, N, N mm) with their
source tags from model-facts.md ([Q-code], [D-code], [Q-paper], [INF], [OWN] =
our own choice); the writer converts to SI. docs/c60.md explains every choice.

  scripts/c60_model/c60_scene.py                       writes urdf/c60.urdf, c60_bench.urdf, c60_ideal.urdf,
                                             c60_bench_ideal.urdf, c60_authors.urdf and
                                             c60_authors_bench.urdf
  scripts/c60_model/c60_scene.py --out F [--bench] [--clearance-scale S] [--friction-scale S]
                       [--p3-rest R]          writes one variant (sensitivity runs)
  scripts/c60_model/c60_scene.py --variant authors [--bench] [--spring-pairs] [--out F]
                                             the authors' model (urdf/c60_authors.urdf):
                                             their clearances, mu, preloads, spring loads;
                                             handle free
"""
import argparse
import json
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
        c7 = geometry_points()['c7_centre']
        return np.array([c7_plane_x() - TABLE_GAP, c7[1], 4.5]), np.eye(3)
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
    if abs(R[2, 0]) > 1 - 1e-12:   # pitch +-90 deg: roll and yaw merge; take roll 0
        return 0.0, p, math.atan2(-R[0, 1], R[1, 1])
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
    # S3: the needle held in the case/cover bores [CAD rows 6-7: rings r 1.3 / 1.15 at z -0.5 /
    # 10.7, offsets 0.294 / 0.144: radial gap 0.006 mm; mu 0.2].
    ('S3', 'world',          'needle',         'child',  (0.0, 0.0),        (-0.5, 10.7),  1.0,  0.006, 0.2),
]
# The authors' model [Q-code + D-code, model-facts 2.2]: every bearing ring drawn 0.5 mm
# larger than its journal, contactOffset = 0.5 - 0.001 - 0.02: radial clearance 0.021 mm in
# J1-J7, 0.041 on J1's top ring (0.52 larger); S3 0.006. mu 0.1 in every joint, 0.2 in S3
# [Q-code, model-facts 2.3]. J1: its clearance joint carries the top ring's 0.041 (both
# rings), and the contact J1_bottom (contacts()) the bottom ring's 0.021: at one height the
# smaller clearance always closes first, so the joint's own bottom ring never acts.
AUTHORS_CLEARANCE = 0.021
AUTHORS_J1_TOP = 0.041
AUTHORS_JOINT_MU = 0.1


def joints(variant='main'):
    if variant == 'main':
        return JOINTS
    out = []
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in JOINTS:
        if jn != 'S3':
            cr, mu = (AUTHORS_J1_TOP if jn == 'J1' else AUTHORS_CLEARANCE), AUTHORS_JOINT_MU
        out.append((jn, parent, child, journal, axy, ringz, rj, cr, mu))
    return out


AXIAL = 0.1          # mm, total axial play of every joint [OWN; D-code: ~0.1 mm handle-case]
BUMPS = 3            # per bearing face [Q-paper: three semi-circular rings]
AUTHORS_BUMPS = 0    # the authors' model: its axial contacts are commented out [Q-code, 2.2]
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
# P3 reads the angle of the moving contact's CAD frame relative to the plate's about z
# (<angle>), -69.25 deg at ON; its rest angle is given from ON (p3_rest) and written
# from that zero.
P3_ANGLE_ON = (-71.25 - (-2.0)) * DEG

# The published loads [Q-code plugin1.cpp, model-facts 2.4]: the plugin writes each spring
# as forces and couples fixed in a body, multiples of the spring's moment or force (its
# outputs are subtracted by the Newton-Euler body after it negates them: they act as
# computed). Points and directions in the body's CAD frame (mm); the spring's scalar
# (docs/scene-format.md) is the torque on the second body for a torsion spring, the
# tension k (L - L0) for a linear one.
P1_POINT = (0.0, -5.65, -0.9)          # handle: C/5.65 along handle-local +x here
P1_ARM = 5.65                          # mm: F = C / 5.65
P3_PLATE_DIR = (-1.1, 0.9, 0.0)        # plate: M / 5.48 along this, at the plate's CoM
P3_PLATE_ARM = 5.48                    # mm [Q-code d_gplatine, "updated 26 May 2015"]
P3_PLATE_COUPLE = 0.2513               # plate: + 0.2513 M about z [Q-code lva1r]
P3_MC_DIR = (0.6, -1.1, -0.01)         # moving contact: M / 6.06 along this, at its CoM
P3_MC_ARM = 6.06                       # mm [Q-code d_gequipage]


def draw_axial_offsets(rng, joint_list, play, loop_joint='S3'):
    """Axial offsets (mm, journal - bore along +z) uniform in +-play/2 for every joint,
    conditioned on the loop closing: the offsets are differences of the bodies' axial
    shifts, so around the loop world-J1-handle-J5-rod-J6-hook-J3-plate-J2-needle-S3-world
    they add up to zero. The tree joints (all but loop_joint) are drawn, the bodies'
    shifts follow, and the draw is kept if the loop joint's offset is inside its play
    (rejection: uniform on the feasible set)."""
    half = 0.5 * play * (1 - 1e-3)
    tree = [j for j in joint_list if j[0] != loop_joint]
    closing = [j for j in joint_list if j[0] == loop_joint][0]
    while True:
        off = {jn: rng.uniform(-half, half) for (jn, *_r) in tree}
        shift = {'world': 0.0}
        pending = list(tree)
        while pending:  # offset = shift(journal body) - shift(bearing body)
            for j in list(pending):
                jn, parent, child, journal = j[:4]
                jb, bb = (parent, child) if journal == 'parent' else (child, parent)
                if bb in shift:
                    shift[jb] = shift[bb] + off[jn]
                elif jb in shift:
                    shift[bb] = shift[jb] - off[jn]
                else:
                    continue
                pending.remove(j)
        jn, parent, child, journal = closing[:4]
        jb, bb = (parent, child) if journal == 'parent' else (child, parent)
        off[jn] = shift[jb] - shift[bb]
        if abs(off[jn]) <= half:
            return off


def geometry_points():
    """Derived ON-state points (mm, world) used by the contacts; printed by --info."""
    P = {}
    # C7: contact arc r 5.2003 about MC-local (20.967, 0.0003), z 3.5..5.5 [CAD row 24].
    P['c7_centre'] = to_world('moving_contact', (20.967, 0.0003, 4.5))
    # Hook nose half-rings [Q-code hook-local (-5.675, -0.519), z 0 and 2].
    P['nose'] = to_world('hook', (-5.675, -0.519, 1.0))
    return P


def build(bench=False, cscale=1.0, fscale=1.0, p3_rest=None, dt=1e-5, variant='main',
          radial_scale=1.0, axial_scale=1.0, radial_mm=None, journal_seed=None, spring_pairs=False):
    """variant 'authors': the authors' model (docs/c60.md, "Main model vs the authors' model"):
    their clearances and joint mu, no axial contacts, the code's P3 preload (not the
    calibrated one) and their springs' loads as the plugin applies them, the J1
    top/bottom rings, the seat F4 and fillet F3 as their code uses them, and no handle
    servo (the handle free); with bench, the bench table as in the main model's.
    spring_pairs (authors only): its springs as springs (moment pairs, a line force),
    not as the plugin's loads: what the loads change (scripts/c60_loads_compare.sh).
    radial_scale / axial_scale scale the radial / axial clearances only (on top of cscale);
    radial_mm sets every radial clearance of J1-J7 to one value (S3, the needle in the case, kept); journal_seed draws
    each journal's initial position uniformly inside its clearance (<clearance
    initial_offset>; numpy's default_rng(seed), so a seed gives the same scene anywhere)."""
    authors = variant == 'authors'
    assert variant in ('main', 'authors') and (authors or not spring_pairs)
    loads = authors and not spring_pairs
    if p3_rest is None:
        p3_rest = P3_REST_CODE if authors else P3_REST_CALIBRATED
    out = []
    w = out.append
    w('<?xml version="1.0"?>')
    w('<!-- C-60 miniature circuit breaker mechanism in the ON (closed, latched) state.')
    w('     GENERATED by scripts/c60_model/c60_scene.py (edit that, not this file); docs/c60.md explains')
    w('     every number and its source. SI units; joint axes along world z; no gravity.')
    extra = ''.join(t for t, on in [(', radial scale %g' % radial_scale, radial_scale != 1.0),
                                    (', axial scale %g' % axial_scale, axial_scale != 1.0),
                                    (', J1-J7 radial clearances %g mm' % (radial_mm or 0), radial_mm is not None),
                                    (', journals placed at random (seed %s)' % journal_seed, journal_seed is not None)] if on)
    w('     clearance scale %g, friction scale %g%s%s -->' % (cscale, fscale, extra, ', with bench table' if bench else ''))
    if authors:
        w('<!-- The AUTHORS\' MODEL (--variant authors): their clearances, friction, preloads and')
        w('     spring loads%s, no axial contacts, the handle free; docs/c60.md "Main model vs the'
          % (' (here as moment pairs and a line force: --spring-pairs)' if spring_pairs else ''))
        w('     authors\' model". -->')
    w('<robot name="c60%s%s">' % ('_authors' if authors else '', '_bench' if bench else ''))

    # ---- ground: case + cover. Visuals only (contacts are declared in <nscd>).
    w('  <link name="world">')
    c7 = geometry_points()['c7_centre']
    x_fixed = c7_plane_x()
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
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints(variant):
        zc = 0.5 * (ringz[0] + ringz[1])
        c = np.array([axy[0], axy[1], zc])
        o, R = pose(child)
        w('  <link name="%s_%s"/>' % (child, jn))
        w('  <joint name="%s_%s_mount" type="fixed">' % (child, jn))
        w('    <parent link="%s"/><child link="%s_%s"/>' % (child, child, jn))
        w('    <origin xyz="%s" rpy="%s"/>' % (fmt(R.T @ (c - o)), fmt_rpy(R.T)))
        w('  </joint>')

    w('  <nscd>')
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints(variant):
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
    rng = np.random.default_rng(journal_seed) if journal_seed is not None else None
    if rng is not None:
        axial_offsets = draw_axial_offsets(rng, joints(variant), max(AXIAL * cscale * axial_scale, MIN_CLEARANCE))
    for (jn, parent, child, journal, axy, ringz, rj, cr, mu) in joints(variant):
        if cscale == 0:
            continue  # clearance x0: the ideal revolute joint, its 5 bilateral rows
        L = ringz[1] - ringz[0]
        crs = max((radial_mm if radial_mm is not None and jn != 'S3' else cr) * cscale * radial_scale, MIN_CLEARANCE)
        cax = max(AXIAL * cscale * axial_scale, MIN_CLEARANCE)
        offset = ''
        if rng is not None:  # uniform in the bore's disc (a hair inside); axial: drawn above
            r, phi = crs * math.sqrt(rng.uniform()) * (1 - 1e-3), rng.uniform(0, 2 * math.pi)
            offset = ' initial_offset="%.9g %.9g %.9g"' % (r * math.cos(phi) * MM, r * math.sin(phi) * MM,
                                                          axial_offsets[jn] * MM)
        w('    <clearance joint="%s" journal="%s" radius="%.9g" radial="%.9g" length="%.9g" axial="%.9g"'
          ' bumps="%d" bump_radius="%.9g" mu="%.9g" e="0"%s/>' %
          (jn, journal, rj * MM, crs * MM, L * MM, cax * MM, AUTHORS_BUMPS if authors else BUMPS,
           BUMP_R * MM, mu * fscale, offset))

    # ---- springs: the main model's as springs (a moment pair, a line force); the authors'
    # as their plugin applies them (P1_POINT ... above), the same laws and numbers.
    w('    <spring name="P1_handle" type="torsion" joint="J1" stiffness="%.9g" rest_angle="%.9g"%s' %
      (K_HANDLE * NMM, A0_HANDLE, '>' if loads else '/>'))
    if loads:  # C / 5.65 at handle (0, -5.65, -0.9) along handle-local x; the scalar is C
        w('      <force link="handle" xyz="%s" direction="1 0 0" scale="%.9g"/>' % (fmt(P1_POINT), 1 / (P1_ARM * MM)))
        w('    </spring>')
    w('    <spring name="P2_plate" type="linear" stiffness="%.9g" rest_length="%.9g">' %
      (K_PLATE * NPMM, L0_PLATE * MM))
    w('      <end link="world" xyz="%s"/><end link="plate" xyz="%s"/>' %
      (fmt(PLATE_ANCHOR_CASE), fmt(PLATE_ANCHOR_PLATE)))
    if loads:  # k (L0 - L) = -tension along plate-local -x, at the plate anchor
        w('      <force link="plate" xyz="%s" direction="-1 0 0" scale="-1"/>' % fmt(PLATE_ANCHOR_PLATE))
    w('    </spring>')
    w('    <spring name="P3_contact" type="torsion" stiffness="%.9g" rest_angle="%.9g">' %
      (K_P3 * NMM, P3_ANGLE_ON + p3_rest))
    w('      <angle link_a="plate" link_b="moving_contact" axis="0 0 1"/>')
    if loads:  # the scalar is the torque on the moving contact, -M
        w('      <force link="plate" xyz="%s" direction="%s" scale="%.9g"/>' %
          (fmt(BODIES['plate']['com']), fmt(P3_PLATE_DIR, 1), -1 / (P3_PLATE_ARM * MM)))
        w('      <couple link="plate" axis="0 0 1" scale="%.9g"/>' % -P3_PLATE_COUPLE)
        w('      <force link="moving_contact" xyz="%s" direction="%s" scale="%.9g"/>' %
          (fmt(BODIES['moving_contact']['com']), fmt(P3_MC_DIR, 1), -1 / (P3_MC_ARM * MM)))
    w('    </spring>')

    # ---- contacts
    for c in contacts(bench, fscale, variant):
        w(c)

    # ---- inputs
    if not authors:  # the authors' handle is free: it only carries its spring [Q-code, 2.4]
        w('    <actuator name="handle" type="position" joint="J1" kp="%.9g" kd="%.9g" max_effort="%.9g"/>' %
          (HANDLE_KP, HANDLE_KD, HANDLE_MAX))
    # The probe's x (its CoM along world +x) is prescribed; its other 5 DOF are free in the
    # plunger bearing [model-facts 0].
    w('    <actuator name="probe" type="prescribed" link="probe" axis="-1 0 0" constrain="axis"/>')
    # The tripping bar's seating moment [Q-code plugin: m[2] = 15 N mm for t < 1 ms; its sign
    # per model-facts 0: the Newton-Euler body subtracts it, so -15 N mm about +z, clockwise,
    # seating the bar towards its clockwise stop C5].
    w('    <actuator name="bar_seating" type="torque" link="trip_bar" axis="0 0 1" schedule="0:%.9g,%.9g:%.9g,%.9g:0"/>'
      % (SEAT_MOMENT * NMM, SEAT_UNTIL, SEAT_MOMENT * NMM, SEAT_UNTIL))
    if bench:
        w('    <actuator name="table" type="prescribed" link="table" axis="1 0 0"/>')
    # [OWN] see docs/c60.md "Numerics": positions projected to 1 nm; contacts within 0.1 um
    # stay active (activation_margin), else loaded contacts chatter.
    w('    <simulation dt="%.9g" theta="0.5" gravity="0 0 0" tolerance="1e-8" max_iterations="2000"'
      ' projection="true" projection_tolerance="1e-9" activation_margin="1e-7"/>' % dt)
    w('  </nscd>')
    w('</robot>')
    return '\n'.join(out) + '\n'


SEAT_MOMENT = -15.0     # N mm about +z [Q-code, sign model-facts 0]
SEAT_UNTIL = 1e-3       # s [Q-code: t < 1.0 ms]
TABLE_GAP = 0.001       # mm [OWN]
MIN_CLEARANCE = 0.001   # mm: the "x0" clearance runs use 1 um (the engine needs c > 0)
HANDLE_KP = 0.3         # N m/rad [OWN] handle servo (a user's hand)
HANDLE_KD = 3e-4        # N m s/rad [OWN] about critical for the handle inertia
HANDLE_MAX = 0.1        # N m [OWN]
# [OWN, calibrated] the one parameter fitted to the paper's bench figure (docs/c60.md):
# the P3 preload, so that the bench force at 2.0 mm is 15.28 N.
P3_REST_CALIBRATED = -1.130

# --------------------------------------------------------------------------- contacts


def shape(link, kind, xyz_mm, R=None, **dims):
    R = np.eye(3) if R is None else R
    attrs = ' '.join('%s="%s"' % (k, v) for k, v in dims.items())
    return ('      <shape link="%s" type="%s" %s><origin xyz="%s" rpy="%s"/></shape>' %
            (link, kind, attrs, fmt(xyz_mm), fmt_rpy(R))).replace('  >', '>')


def contact(name, mu, a, b):
    return '    <contact name="%s" mu="%.9g" e="0">\n%s\n%s\n    </contact>' % (name, mu, a, b)


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


# The authors' 39 contacts worked out of their STEP patches (shared/c60/cad/, a copy in
# scripts/c60_model/c60_cad_contacts.json; docs/c60.md "Contacts" gives its provenance). Every
# number a contact below uses is read from this table by the contact's CAD name, in the
# link frame (the CAD "local" frame is our link frame; mm). The CAD gap at ON is the
# patches' distance minus the contact's offset: the offset becomes a shift of the face
# along its outward normal, or a larger cylinder radius.
CAD_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'c60_cad_contacts.json')
with open(CAD_FILE) as _f:
    CAD = {c['name']: c for c in json.load(_f)}
LINK_OF = {'MANETTE': 'handle', 'BATIE': 'world', 'CROCHET': 'hook', 'BARRE': 'trip_bar',
           'PLATINE': 'plate', 'EQUIPAGE': 'moving_contact', 'PROBE': 'probe', 'AIGUILLE': 'needle'}
ROUND = 2e-3          # mm: the tables give 4 decimals; derived points are checked to this
# mm [OWN]: every face grows by 1 nm on each side, so that an arc lying exactly on a face's
# edge in the CAD (C6: the MC arc at z 1.8 on the plate face's edge z 1.8) is on the face
# despite round-off (the ring-face pair keeps a point whose foot is on the closed rectangle).
FACE_PAD = 1e-6


def frame(z, x):
    """Rotation with columns x, y = z cross x, z (x made orthogonal to z)."""
    z = unit(z)
    x = unit(np.asarray(x, float) - np.dot(x, z) * z)
    return np.column_stack([x, np.cross(z, x), z])


def ring_of(patch, link, radius=None):
    """A `ring` from a CAD 'circle arc' patch: frame z = the arc's axis, x = towards its
    middle, so the arc is -span/2 + [0, span] about z. Its tabulated start is checked."""
    assert patch['kind'] == 'circle arc', patch['kind']
    c, r = np.array(patch['centre_local']), patch['radius']
    R = frame(patch['axis_local'], np.array(patch['mid_local']) - c)
    span = patch['span_deg'] * DEG
    start = c + r * (math.cos(span / 2) * R[:, 0] - math.sin(span / 2) * R[:, 1])
    assert np.linalg.norm(start - patch['start_local']) < ROUND, (patch, start)
    return shape(link, 'ring', c, R, radius='%.9g' % ((radius or r) * MM), start='%.9g' % (-span / 2),
                 span='%.9g' % span)


def face_of(patch, link, outward, offset, x0=None, x1=None):
    """A `face` from a CAD plane patch (a vertical rectangle: normal in the xy plane), its
    outward normal `outward` (link frame), shifted by `offset` along it. The rectangle is
    the patch's bounding box, centred on the tabulated point; x0/x1 override its
    extent along the link's x axis (for F4, see C4)."""
    assert patch['kind'] == 'plane', patch['kind']
    n = unit(outward)
    assert abs(abs(np.dot(n, unit(patch['normal_local']))) - 1) < 1e-6 and abs(n[2]) < 1e-9
    lo, hi = np.array(patch['bbox_local'][0]), np.array(patch['bbox_local'][1])
    # The tabulated point is the rectangle's centre (4 decimals; the box has 3).
    centre = np.array(patch['point_local'], float)
    assert np.linalg.norm(centre - 0.5 * (lo + hi)) < ROUND, (patch, centre)
    R = frame(n, np.cross([0, 0, 1.0], n))          # x horizontal in the face, y = +z
    sx, sy = math.hypot(*(hi - lo)[:2]), (hi - lo)[2]
    if x0 is not None:   # a face along the link's x axis: its extent x0..x1 (link frame)
        assert abs(abs(R[0, 0]) - 1) < 1e-9
        centre[0], sx = 0.5 * (x0 + x1), x1 - x0
    return shape(link, 'face', centre + offset * n, R, size=fmt((sx + 2 * FACE_PAD, sy + 2 * FACE_PAD)))


def cylinder_arc(link, centre, axis, r, length, a0, span, hollow=False):
    """A `cylinder` (lateral surface) limited to the angles a0 + [0, span] (rad) about `axis`,
    measured from the link frame's +x when axis is +z; hollow: the material outside it."""
    R = frame(axis, [1.0, 0, 0])
    extra = {'hollow': 'true'} if hollow else {}
    return shape(link, 'cylinder', centre, R, radius='%.9g' % (r * MM), length='%.9g' % (length * MM),
                 start='%.9g' % a0, span='%.9g' % span, **extra)


def circle_angle(centre, r, y, side):
    """Angle (rad) of the point of the circle (centre, r) at ordinate y, on the side
    sign(x - x_centre) = side."""
    dy = y - centre[1]
    return math.atan2(dy, side * math.sqrt(max(0.0, r * r - dy * dy)))


def links(cad):
    return LINK_OF[cad['body1']], LINK_OF[cad['body2']]


def outward_from_points(cad, on_body, patch):
    """Outward normal (link frame of body on_body = 1 or 2) of that body's face: towards the
    other body's nearest point at ON."""
    p1, p2 = np.array(cad['on']['P1_world']), np.array(cad['on']['P2_world'])
    d = (p2 - p1) if on_body == 1 else (p1 - p2)
    link = links(cad)[on_body - 1]
    n = np.array(patch['normal_local'], float)
    n_world = pose(link)[1] @ n if link != 'world' else n
    return n if np.dot(n_world, d) > 0 else -n


def ring_face(name, cad_name, fs, ring_body, face_patch=None, x0=None, x1=None, outward=None):
    """CAD edge-face contact: a ring (the arc patch of body ring_body) against a face."""
    cad = CAD[cad_name]
    la, lb = links(cad)
    face_body = 3 - ring_body
    arc = (cad['patch1'] if ring_body == 1 else cad['patch2'])[0]
    fp = face_patch or (cad['patch1'] if face_body == 1 else cad['patch2'])[0]
    n = outward_from_points(cad, face_body, fp) if outward is None else outward
    ring = ring_of(arc, la if ring_body == 1 else lb)
    face = face_of(fp, lb if ring_body == 1 else la, n, cad['offset'], x0, x1)
    a, b = (ring, face) if ring_body == 1 else (face, ring)
    return contact(name, cad['mu'] * fs, a, b)


# Our contact names (those the scenes, scripts and tests read) for the CAD contacts; a CAD
# contact with several point pairs keeps the bare name on the pair that carries the load at
# ON (C4: the hook's half-ring on the seat F4) or on the first pair.
C4_SEAT_X = (-0.45, 0.20)   # bar-local x of the seat F4 [D-code, model-facts 0; see contacts()]
# The authors' code gives faces 3, 4 of a patch file face 2's parameter box (cad/README):
# F4 becomes x -0.45 .. 0.14 (its `bbox_local` with uv_used), and F3's box (0 .. 0.59 rad)
# lands on the fillet's inner side (bbox x 0.152 .. 0.159, inside the bar): no contact.
AUTHORS_C4_SEAT_X = (-0.45, 0.14)
J1_BOTTOM_Z = 1.0           # mm, J1's bottom ring [D-code]
J1_PIN = (2.3, 0.5, 7.3)    # mm: the case pin's radius and z span [D-code, model-facts 2.2]


def contacts(bench, fs, variant='main'):
    authors = variant == 'authors'
    out = []
    if authors:
        # J1's bottom ring r 2.3 + 0.021 (handle) around the case pin r 2.3, z 0.5 .. 7.3
        # (world) [D-code]; the clearance joint J1 carries the top ring's 0.041 (joints()).
        J1 = [j for j in JOINTS if j[0] == 'J1'][0]
        ax, ay = J1[4]
        o, R = pose('handle')
        out.append(contact('J1_bottom', AUTHORS_JOINT_MU * fs,
                           shape('handle', 'ring', R.T @ (np.array([ax, ay, J1_BOTTOM_Z]) - o), R.T,
                                 radius='%.9g' % ((J1_PIN[0] + AUTHORS_CLEARANCE) * MM)),
                           shape('world', 'cylinder', (ax, ay, 0.5 * (J1_PIN[1] + J1_PIN[2])), None,
                                 radius='%.9g' % (J1_PIN[0] * MM), length='%.9g' % ((J1_PIN[2] - J1_PIN[1]) * MM))))
    # C1, the handle's ON stop [CAD rows 2-5]: handle face vs two case arcs r 0.5 (z -0.1),
    # handle arcs r 0.463 / 0.5 vs the cover's stopper face (z 8.2..).
    out.append(ring_face('C1', 'Case_handle_C1_ON_1', fs, ring_body=2))
    out.append(ring_face('C1_2', 'Case_handle_C1_ON_2', fs, ring_body=2))
    out.append(ring_face('C1_3', 'Cover_handle_C1_ON_3', fs, ring_body=1))
    out.append(ring_face('C1_4', 'Cover_handle_C1_ON_4', fs, ring_body=1))

    # C3, the plate's stop after the trip (closes at plate +22 deg), 3.8-4.7 mm open at ON
    # [CAD rows 25-28]: plate face vs case arcs r 0.1; plate arcs r 0.1 vs a case face.
    out.append(ring_face('C3', 'Plate_case_C3_ON_1', fs, ring_body=2))
    out.append(ring_face('C3_2', 'Plate_case_C3_ON_2', fs, ring_body=2))
    out.append(ring_face('C3_3', 'Plate_case_C3_ON_3', fs, ring_body=1))
    out.append(ring_face('C3_4', 'Plate_case_C3_ON_4', fs, ring_body=1))

    # C4, the latch [CAD rows 14-17; model-facts 0]. The bar's patch has four faces: F1 a
    # cylinder r 5.9 (the tip's guide after release), F2 the plane x = 0.25, F3 a fillet
    # r 0.045, F4 the seat y = 7.0 (bar material below). C4 / C4_2: the hook's vertical
    # half-rings r 0.5 (z 0 and 2) on F4. F4 spans x -0.45..0.20 in the STEP face (uv_own);
    # the authors' code clips it to x <= 0.14 (it reuses face 2's parameter box): we keep
    # the STEP face. The same half-rings also meet F2, F3 and F1 (the CAD distance is the
    # minimum over the four faces): one contact each.
    seat_x = AUTHORS_C4_SEAT_X if authors else C4_SEAT_X
    for k, (nm, cadn) in enumerate([('C4', 'Hook_Tbar_C4_1'), ('C4_2', 'Hook_Tbar_C4_2')]):
        cad = CAD[cadn]
        f1, f2, f3, f4 = cad['patch2']
        if authors:  # F4 as the authors' code clips it (face 2's box), checked on the table
            assert abs(f4['bbox_local'][1][0] - seat_x[1]) < ROUND and f4['uv_used'] != f4['uv_own']
        out.append(ring_face(nm, cadn, fs, ring_body=1, face_patch=f4, x0=seat_x[0], x1=seat_x[1]))
        # F2: x = 0.25, bar material at x < 0.25 (outward +x; its tabulated normal is -x).
        out.append(ring_face(nm + '_F2', cadn, fs, ring_body=1, face_patch=f2, outward=np.array([1.0, 0, 0])))
        ring = ring_of(cad['patch1'][0], 'hook')
        # F3: the fillet r 0.0451 about (0.197, 6.954), from F2's normal (+x) to F4's (+y).
        # (Not in the authors' model: their F3 lies inside the bar, see AUTHORS_C4_SEAT_X.)
        if not authors:
            out.append(contact(nm + '_F3', cad['mu'] * fs, ring, cylinder_arc(
                'trip_bar', f3['centre_local'], [0, 0, 1.0], f3['radius'] + cad['offset'], 3.0, 0.0, math.pi / 2)))
        # F1: r 5.9 about (5.9571, 4.8635), concave: the bar's material lies OUTSIDE the
        # circle (it continues F2, whose material is at x < 0.25, with a 14.7 deg bend; the
        # tip after release swings inside it, 0.49 mm clear), so a hollow cylinder whose
        # radius the offset makes smaller. The arc runs between its ends at y 3.367 and
        # 6.36 (bbox) on the side x < centre.
        c1 = f1['centre_local']
        a_lo = circle_angle(c1, f1['radius'], f1['bbox_local'][1][1], -1)   # y 6.36
        a_hi = circle_angle(c1, f1['radius'], f1['bbox_local'][0][1], -1)   # y 3.367 (+ 2 pi)
        span = (a_hi - a_lo) % (2 * math.pi)
        assert abs(span - (f1['uv_own'][1] - f1['uv_own'][0])) < 2e-3
        out.append(contact(nm + '_F1', cad['mu'] * fs, ring, cylinder_arc(
            'trip_bar', c1, [0, 0, 1.0], f1['radius'] - cad['offset'], 3.0, a_lo, span, hollow=True)))
    # C4_3 / C4_4: the hook flat against the bar's half-rings r 0.5 in the plane x = 0.25,
    # whose apex is the tooth corner (0.25, 7.0).
    out.append(ring_face('C4_3', 'Hook_Tbar_C4_3', fs, ring_body=2))
    out.append(ring_face('C4_4', 'Hook_Tbar_C4_4', fs, ring_body=2))
    # C4_3_tip / C4_4_tip: the hook's flat ends at the hook's tip, the edge it shares with
    # C5's arc (r 5.63 about J3); where the bar's tooth corner passes that edge the
    # contact is corner on edge, its normal the geometric one, from the edge to the
    # corner [OWN, from the CAD patches of C4_3 and C5]. The edge is a `cylinder` along
    # hook-local z through the tip, of radius the contact's offset (the CAD's distance
    # minus the offset, as the face's shift), its surface kept between the flat's
    # outward normal and the arc's: at either end the point and the normal are those of
    # the face it continues. The same rings (the tooth corner), mu and offset as
    # C4_3 / C4_4.
    tip, z_span, a_arc, span = hook_tip_edge()
    for nm, cadn in [('C4_3_tip', 'Hook_Tbar_C4_3'), ('C4_4_tip', 'Hook_Tbar_C4_4')]:
        cad = CAD[cadn]
        out.append(contact(nm, cad['mu'] * fs,
                           cylinder_arc('hook', (tip[0], tip[1], 0.5 * (z_span[0] + z_span[1])), [0, 0, 1.0],
                                        cad['offset'], z_span[1] - z_span[0], a_arc, span),
                           ring_of(cad['patch2'][0], 'trip_bar')))

    # C5, the bar's clockwise stop on the hook [CAD rows 29-30]: the hook's arc r 5.63 about
    # J3 (hook z -0.5..2.5; its end at the tip, y -1.004 (bbox), span from uv_used) vs the
    # bar's half-rings r 0.48 (130.75 deg) outside it. Offset 0.01 -> radius 5.64.
    for nm, cadn in [('C5', 'Tbar_Hook_C5_1'), ('C5_2', 'Tbar_Hook_C5_2')]:
        cad = CAD[cadn]
        cyl = cad['patch1'][0]
        span = cyl['uv_used'][1] - cyl['uv_used'][0]
        a_end = circle_angle(cyl['centre_local'], cyl['radius'], cyl['bbox_local'][0][1], -1)
        zc = 0.5 * (cyl['bbox_local'][0][2] + cyl['bbox_local'][1][2])
        length = cyl['bbox_local'][1][2] - cyl['bbox_local'][0][2]
        c = np.array([cyl['centre_local'][0], cyl['centre_local'][1], zc])
        out.append(contact(nm, cad['mu'] * fs,
                           cylinder_arc('hook', c, [0, 0, 1.0], cyl['radius'] + cad['offset'], length,
                                        a_end - span, span),
                           ring_of(cad['patch2'][0], 'trip_bar')))

    # C6, the moving contact's side stop on the plate [CAD rows 31-34], about 1.04-1.15 mm
    # open at ON: MC arcs r 0.2 vs a plate face; an MC face vs plate arcs r 0.15.
    out.append(ring_face('C6', 'Mcontact_plate_C6_side_1', fs, ring_body=1))
    out.append(ring_face('C6_2', 'Mcontact_plate_C6_side_2', fs, ring_body=1))
    out.append(ring_face('C6_3', 'Mcontact_plate_C6_side_3', fs, ring_body=2))
    out.append(ring_face('C6_4', 'Mcontact_plate_C6_side_4', fs, ring_body=2))

    # C7, the main contact [CAD row 24]: the MC's cylindrical arc r 5.2003 (z 3.5..5.5; its
    # ends at y -5.193 and -4.588 (bbox), x < centre) vs the fixed contact, the case plane
    # x = 1.5 facing +x, shifted by the offset 0.001. The face's bounds (y -22.3..-18.4,
    # z 2.55..6.75) hold the arc's contact line; `cylinder` pairs only with the unbounded
    # `plane`, which gives the arc's two end rims.
    cad = CAD['Mcontact_Fcontact_bot_1_C7']
    cyl, pl = cad['patch1'][0], cad['patch2'][0]
    out.append(contact('C7', cad['mu'] * fs, c7_arc(), shape(
        'world', 'plane', np.array(pl['point_local']) + cad['offset'] * np.array([1.0, 0, 0]),
        frame([1.0, 0, 0], [0, 1.0, 0]))))

    # TRIP [CAD rows 35-36]: the bar's arcs r 6.0 (53.18 deg, bar z -1.2 and +1.4) against
    # the probe's flat end, a 6.2 x 6.18 face at probe-local x = -0.9 facing world +x,
    # shifted 0.01 (offset). TRIP is the CAD's TRIP_2 (z -1.2, the one that touches);
    # TRIP_upper the CAD's TRIP_1 (z 1.4): it lies above the probe face and never touches.
    out.append(ring_face('TRIP', 'TRIP_2', fs, ring_body=1))
    out.append(ring_face('TRIP_upper', 'TRIP_1', fs, ring_body=1))

    # FC, the bar's clockwise end stop [CAD row 37]: the bar's cylindrical arc r 6.0 (bar z
    # -1.2..2.9; ends at y -2.085 and 0.826 (bbox), x < centre) vs the case plane x = -5.0
    # facing +x, shifted by 0.001. Open by 0.388 mm at ON.
    cad = CAD['Tbar_Magnetic_FC_X']
    cyl, pl = cad['patch1'][0], cad['patch2'][0]
    a0 = circle_angle(cyl['centre_local'], cyl['radius'], cyl['bbox_local'][1][1], -1)
    a1 = circle_angle(cyl['centre_local'], cyl['radius'], cyl['bbox_local'][0][1], -1)
    assert abs((a1 - a0) - (cyl['uv_used'][1] - cyl['uv_used'][0])) < 2e-3
    zc = 0.5 * (cyl['bbox_local'][0][2] + cyl['bbox_local'][1][2])
    c = np.array([cyl['centre_local'][0], cyl['centre_local'][1], zc])
    out.append(contact('FC', cad['mu'] * fs,
                       cylinder_arc('trip_bar', c, [0, 0, 1.0], cyl['radius'], cyl['bbox_local'][1][2] -
                                    cyl['bbox_local'][0][2], a0, a1 - a0),
                       shape('world', 'plane', np.array(pl['point_local']) + cad['offset'] * np.array([1.0, 0, 0]),
                             frame([1.0, 0, 0], [0, 1.0, 0]))))

    # Plunger bearing [CAD row 38; model-facts 0]: the probe's cylinder r 1.19 along its
    # local x (local x 0.6 .. 8.2, world x -6.5 .. -14.1 at ON) in the case bore r 1.29
    # (axis y -8.9, z 4.65, world x -15.5 .. -5.5), radial gap 0.099 (0.098973 after the
    # offset 0.001), mu 0.1. The probe's x is prescribed, its other DOF are free in the bore.
    # [OWN] The CAD pair is cylinder-cylinder; we give it as the support points of the
    # guided length, its two ends, each a circle edge against a cylinder: the probe's rear
    # end (ring r 1.19 at local x 8.2, inside the bore through the whole stroke) and its
    # front end (ring at local x 0.6) against the bore as a hollow cylinder whose radius
    # the offset makes smaller (1.289); after 1 mm of stroke the front ring leaves the bore
    # (world x -5.5) and the bore's mouth takes over: the case's ring r 1.29 at x -5.5
    # around the probe's cylinder, whose radius the offset makes larger (1.191). Each ring
    # counts only while it lies within the other part's length, so the front support
    # passes from one pair to the other at 1 mm of stroke without a gap in the guide.
    cad = CAD['plunger_bearing']
    pc, bore = cad['patch1'][0], cad['patch2'][0]
    assert all(abs(p['radius'] - pc['radius']) < 1e-9 for p in cad['patch1'])
    assert all(abs(p['radius'] - bore['radius']) < 1e-9 for p in cad['patch2'])
    px0, px1 = pc['bbox_local'][0][0], pc['bbox_local'][1][0]           # 0.6, 8.2 (probe-local)
    bx0, bx1 = bore['bbox_world'][0][0], bore['bbox_world'][1][0]       # -15.5, -5.5 (world)
    axis_probe = frame([1.0, 0, 0], [0, 1.0, 0])                        # z along the probe
    axis_case = frame([1.0, 0, 0], [0, 1.0, 0])
    bore_c = np.array([0.5 * (bx0 + bx1), bore['centre_world'][1], bore['centre_world'][2]])
    bore_cyl = shape('world', 'cylinder', bore_c, axis_case, radius='%.9g' % ((bore['radius'] - cad['offset']) * MM),
                     length='%.9g' % ((bx1 - bx0) * MM), hollow='true')
    for name, x in [('plunger_bearing', px1), ('plunger_bearing_front', px0)]:
        out.append(contact(name, cad['mu'] * fs,
                           shape('probe', 'ring', (x, 0, 0), axis_probe, radius='%.9g' % (pc['radius'] * MM)),
                           bore_cyl))
    out.append(contact('plunger_bearing_mouth', cad['mu'] * fs,
                       shape('world', 'ring', (bx1, bore_c[1], bore_c[2]), axis_case,
                             radius='%.9g' % (bore['radius'] * MM)),
                       shape('probe', 'cylinder', (0.5 * (px0 + px1), 0, 0), axis_probe,
                             radius='%.9g' % ((pc['radius'] + cad['offset']) * MM), length='%.9g' % ((px1 - px0) * MM))))

    if bench:
        # TABLE [OWN]: the table face pushes the C7 arc, starting TABLE_GAP behind the fixed
        # contact's plane (so the breaker settles on C7 first); frictionless, so the
        # hysteresis comes from the joints only.
        out.append(contact('TABLE', 0.0, c7_arc(), shape('table', 'plane', (0, 0, 0), frame([1.0, 0, 0], [0, 1.0, 0]))))
    return out


def hook_tip_edge():
    """The hook's tip edge (hook-local, mm), where its flat (C4_3's face) ends and C5's arc
    r 5.63 about J3 begins: the tip's (x, y), the flat's z span, and the angles (rad, from
    hook-local +x about +z) from the arc's outward normal there to the flat's."""
    cad = CAD['Hook_Tbar_C4_3']
    flat = cad['patch1'][0]
    n = outward_from_points(cad, 1, flat)
    along = np.cross([0, 0, 1.0], n)                    # the face frame's x (face_of)
    lo, hi = np.array(flat['bbox_local'][0]), np.array(flat['bbox_local'][1])
    centre = np.array(flat['point_local'], float)
    tip = centre - 0.5 * math.hypot(*(hi - lo)[:2]) * along
    if np.dot(tip[:2] - lo[:2], tip[:2] - lo[:2]) > np.dot(centre[:2] - lo[:2], centre[:2] - lo[:2]):
        tip = centre + 0.5 * math.hypot(*(hi - lo)[:2]) * along
    arc = CAD['Tbar_Hook_C5_1']['patch1'][0]
    assert np.linalg.norm(tip[:2] - np.array(arc['centre_local'][:2])) - arc['radius'] < ROUND, tip
    assert np.linalg.norm(tip[:2] - lo[:2]) < ROUND, (tip, lo)     # the flat's lower end
    out_arc = tip[:2] - np.array(arc['centre_local'][:2])
    a_arc, a_flat = math.atan2(out_arc[1], out_arc[0]), math.atan2(n[1], n[0])
    span = (a_flat - a_arc) % (2 * math.pi)
    assert 0 < span < math.pi, span
    return tip[:2], (lo[2], hi[2]), a_arc, span


def c7_arc():
    """The moving contact's arc of C7 [CAD row 24] as a `cylinder` with start/span."""
    cyl = CAD['Mcontact_Fcontact_bot_1_C7']['patch1'][0]
    c, r = cyl['centre_local'], cyl['radius']
    a0 = circle_angle(c, r, cyl['bbox_local'][0][1], -1)   # y -5.193
    a1 = circle_angle(c, r, cyl['bbox_local'][1][1], -1)   # y -4.588
    a0, a1 = min(a0, a1), max(a0, a1)
    assert abs((a1 - a0) - (cyl['uv_used'][1] - cyl['uv_used'][0])) < 2e-3
    zc = 0.5 * (cyl['bbox_local'][0][2] + cyl['bbox_local'][1][2])
    return cylinder_arc('moving_contact', (c[0], c[1], zc), [0, 0, 1.0], r,
                        cyl['bbox_local'][1][2] - cyl['bbox_local'][0][2], a0, a1 - a0)


def c7_plane_x():
    """World x of the fixed contact's plane as modelled (CAD plane + offset)."""
    cad = CAD['Mcontact_Fcontact_bot_1_C7']
    return cad['patch2'][0]['point_local'][0] + cad['offset']


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
        P = to_world('trip_bar', (-0.125, 7.0, 0))   # the latch seat F4
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
    ap.add_argument('--out-dir', help='write the shipped scenes (c60.urdf, c60_bench.urdf, '
                    'c60_ideal.urdf, c60_bench_ideal.urdf, c60_authors.urdf, c60_authors_bench.urdf) here instead of the '
                    'repository\'s urdf/')
    ap.add_argument('--bench', action='store_true')
    ap.add_argument('--clearance-scale', type=float, default=1.0,
                    help='scale of every joint clearance; 0: ideal revolute joints (c60_ideal.urdf)')
    ap.add_argument('--friction-scale', type=float, default=1.0)
    ap.add_argument('--radial-scale', type=float, default=1.0, help='scale of the radial clearances only')
    ap.add_argument('--axial-scale', type=float, default=1.0, help='scale of the axial plays only')
    ap.add_argument('--radial-mm', type=float, help='every radial clearance of J1-J7 set to this, mm (S3 kept)')
    ap.add_argument('--journal-seed', type=int,
                    help='journals start at random positions inside their clearances (this seed)')
    ap.add_argument('--p3-rest', type=float)
    ap.add_argument('--dt', type=float, default=1e-5)
    ap.add_argument('--info', action='store_true')
    ap.add_argument('--variant', choices=['main', 'authors'], default=None,
                    help="authors: the authors' model (urdf/c60_authors.urdf without --out)")
    ap.add_argument('--spring-pairs', action='store_true',
                    help="with --variant authors: its springs as moment pairs and a line force, not the "
                    "plugin's loads")

    a = ap.parse_args()
    if a.info:
        for k, v in geometry_points().items():
            print(k, v)
        print('P3 rest (code)', P3_REST_CODE, 'calibrated', P3_REST_CALIBRATED)
        return
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    variant = a.variant or 'main'
    if a.out or a.variant == 'authors':
        text = build(a.bench, a.clearance_scale, a.friction_scale, a.p3_rest, a.dt, variant,
                     a.radial_scale, a.axial_scale, a.radial_mm, a.journal_seed, a.spring_pairs)
        out = a.out or os.path.join(a.out_dir or os.path.join(repo, 'urdf'), 'c60_authors.urdf')
        with open(out, 'w') as f:
            f.write(text)
        return
    out_dir = a.out_dir or os.path.join(repo, 'urdf')
    for bench, cscale, var, fn in [(False, 1.0, 'main', 'c60.urdf'), (True, 1.0, 'main', 'c60_bench.urdf'),
                                   (False, 0.0, 'main', 'c60_ideal.urdf'), (True, 0.0, 'main', 'c60_bench_ideal.urdf'),
                                   (False, 1.0, 'authors', 'c60_authors.urdf'),
                                   (True, 1.0, 'authors', 'c60_authors_bench.urdf')]:
        with open(os.path.join(out_dir, fn), 'w') as f:
            f.write(build(bench, cscale, variant=var))


if __name__ == '__main__':
    main()
