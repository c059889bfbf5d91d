#!/usr/bin/env python3
"""Dumps friction-contact problems from two Siconos scenes (python3-siconos).

usage: fclib_generate.py OUT_DIR
Writes OUT_DIR/<name>.dat in Siconos numerics' own format
(siconos.numerics.frictionContact_printInFilename on the FrictionContact
one-step problem of a running simulation); `nscd_fclib --convert` turns each
into an FCLib HDF5 file (the Debian Siconos is built without FCLib, so its
python module cannot write FCLib directly).

Scenes (Moreau-Jean time stepping, LagrangianLinearTIDS bodies, relations
linearised about the initial configuration, 3D Coulomb friction):
  box_stack   N cubes stacked on the ground, 4 corner contacts per face:
              hyperstatic (12 rows per face for 6 relative DOF), top boxes
              launched sideways and spinning so that faces slide and stick;
  sphere_pile a triangular pile of spheres between two walls (10 spheres:
              24 contacts, 72 rows for 60 DOF; 21 spheres: 51 contacts),
              settling, the top sphere pushed out of plane.
"""
import os
import sys

import numpy as np
import siconos.kernel as sk
import siconos.numerics as sn

G = 9.81


def cross_matrix_row(d, t):
    """Row mapping (v, omega) to t . (v + omega x d) = t.v + (d x t).omega."""
    return np.concatenate([t, np.cross(d, t)])


def frame(n):
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return n, t1, np.cross(n, t1)


def contact(nsds, law, n, A, dA, B=None, dB=None, gap0=0.0):
    """Linearised point contact between body A (offset dA from its centre) and
    body B (offset dB) or the ground, normal n (from B to A). gap0: the gap at
    the initial configuration. Output rows: normal gap, two tangents."""
    n, t1, t2 = frame(np.asarray(n, float))
    HA = np.array([cross_matrix_row(dA, t) for t in (n, t1, t2)])
    qA0 = np.array(A.q())
    if B is None:
        H = HA
        b = np.array([gap0 - HA[0] @ qA0, 0.0, 0.0])
        rel = sk.LagrangianLinearTIR(H, b)
        inter = sk.Interaction(law, rel)
        nsds.link(inter, A)
    else:
        HB = -np.array([cross_matrix_row(dB, t) for t in (n, t1, t2)])
        qB0 = np.array(B.q())
        H = np.hstack([HA, HB])
        b = np.array([gap0 - HA[0] @ qA0 - HB[0] @ qB0, 0.0, 0.0])
        rel = sk.LagrangianLinearTIR(H, b)
        inter = sk.Interaction(law, rel)
        nsds.link(inter, A, B)
    return inter


def body(nsds, m, inertia, x, v=(0, 0, 0), w=(0, 0, 0)):
    M = np.diag([m, m, m, inertia, inertia, inertia])
    ds = sk.LagrangianLinearTIDS(list(x) + [0, 0, 0], list(v) + list(w), M)
    ds.setFExtPtr([0, 0, -m * G, 0, 0, 0])
    nsds.insertDynamicalSystem(ds)
    return ds


def run(nsds, h, steps, dump_at, out, name, tol=1e-10):
    steps = max(dump_at)
    fc = sk.FrictionContact(3)
    fc.numericsSolverOptions().dparam[sn.SICONOS_DPARAM_TOL] = tol
    fc.numericsSolverOptions().iparam[sn.SICONOS_IPARAM_MAX_ITER] = 100000
    s = sk.TimeStepping(nsds, sk.TimeDiscretisation(0, h), sk.MoreauJeanOSI(0.5), fc)
    s.initialize()
    written = []
    for k in range(1, steps + 1):
        s.computeOneStep()
        if k in dump_at:
            p = fc.frictionContactProblemPtr()
            if p is not None and p.numberOfContacts > 0:
                fn = os.path.join(out, f"{name}_step{k}.dat")
                sn.frictionContact_printInFilename(p, fn)
                written.append((fn, p.numberOfContacts))
        s.nextStep()
    return written


def box_stack(out, n_boxes, mu, dump_at, e=0.0):
    a, m = 0.1, 1.0
    inertia = m * a * a / 6
    nsds = sk.NonSmoothDynamicalSystem(0, 10)
    law = sk.NewtonImpactFrictionNSL(e, 0.0, mu, 3)
    boxes = []
    for i in range(n_boxes):
        # small gaps so that the stack lands; the upper boxes slide and spin
        z = a / 2 + i * a + (i + 1) * 2e-4
        v = (0.3 * i * (-1) ** i, 0.1 * i, 0.0)
        w = (0, 0, 0.5 * i)
        boxes.append(body(nsds, m, inertia, (0, 0, z), v, w))
    corners = [(sx * a / 2, sy * a / 2) for sx in (-1, 1) for sy in (-1, 1)]
    for i, A in enumerate(boxes):
        for cx, cy in corners:
            dA = np.array([cx, cy, -a / 2])
            if i == 0:
                contact(nsds, law, (0, 0, 1), A, dA, gap0=2e-4)
            else:
                contact(nsds, law, (0, 0, 1), A, dA, boxes[i - 1], np.array([cx, cy, a / 2]), gap0=2e-4)
    return run(nsds, 1e-3, 0, dump_at, out, f"box_stack{n_boxes}_mu{mu:g}")


def sphere_pile(out, rows, mu, dump_at, e=0.0):
    r, m = 0.05, 1.0
    inertia = 0.4 * m * r * r
    nsds = sk.NonSmoothDynamicalSystem(0, 10)
    law = sk.NewtonImpactFrictionNSL(e, 0.0, mu, 3)
    gap = 1e-5
    spheres = {}
    for j in range(rows):
        for i in range(rows - j):
            x = r + (2 * i + j) * (r + gap / 2)
            z = r + gap + j * np.sqrt(3) * (r + gap / 2)
            v = (0, 0.2, 0) if j == rows - 1 else (0, 0, 0)
            spheres[(i, j)] = body(nsds, m, inertia, (x, 0, z), v)
    width = 2 * r * rows + (rows - 1) * gap + 2 * gap
    for (i, j), A in spheres.items():
        xA = np.array(A.q()[:3])
        if j == 0:
            contact(nsds, law, (0, 0, 1), A, np.array([0, 0, -r]), gap0=gap)
        if j == 0 and i == 0:
            contact(nsds, law, (1, 0, 0), A, np.array([-r, 0, 0]), gap0=xA[0] - r)
        if j == 0 and i == rows - 1:
            contact(nsds, law, (-1, 0, 0), A, np.array([r, 0, 0]), gap0=width - xA[0] - r)
        neighbours = [(i - 1, j)] + ([(i, j - 1), (i + 1, j - 1)] if j > 0 else [])
        for nb in neighbours:
            if nb in spheres:
                B = spheres[nb]
                d = xA - np.array(B.q()[:3])
                n = d / np.linalg.norm(d)
                contact(nsds, law, n, A, -r * n, B, r * n, gap0=np.linalg.norm(d) - 2 * r)
    n = rows * (rows + 1) // 2
    return run(nsds, 1e-3, 0, dump_at, out, f"sphere_pile{n}_mu{mu:g}")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(out, exist_ok=True)
    written = []
    written += box_stack(out, 2, 1.0, {40, 300})
    written += box_stack(out, 4, 0.5, {40, 150, 300})
    written += box_stack(out, 8, 0.5, {40, 150})
    written += sphere_pile(out, 4, 0.3, {30})
    written += sphere_pile(out, 6, 0.3, {10, 25, 60})
    for fn, nc in written:
        print(f"{fn}: {nc} contacts")


if __name__ == "__main__":
    main()
