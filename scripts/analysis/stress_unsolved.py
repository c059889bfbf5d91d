#!/usr/bin/env python3
"""The stress suite's unsolved friction-contact problems, and whether they can be solved.

  scripts/analysis/stress_unsolved.py [--csv build/perf/stress.csv] [--every 6] [--per-case 8]
                             [--out build/stress_unsolved] [--tol 1e-8] [--max-iter 200]

1. From a stress run's CSV (scripts/stress.sh), takes every EVERY-th case with
   unconverged steps, writes its scene (nscd_stress --case N --write), reruns it
   with nscd_run --dump-problems (unconverged solves only) and keeps PER_CASE of
   its problems, evenly spaced; the cases go alternately to samples A and B. As a
   control, PER_CASE problems the same runs solved (every 25th step, converged ones).
2. Solves each unsolved one again with nscd_solve_problems (warm-started as in the
   run) with a budget of MAX_ITER (10 x the default): which more work would settle.
3. Tests each for strict feasibility, the hypothesis of the existence theorem of
   Acary, Cadoux, Lemarechal and Malick (2011) for the discrete frictional contact
   problem U = W P + b, W = H M^-1 H^T: is there a velocity, i.e. a P (free, not in
   the cones), whose U lies strictly inside every contact's dual cone
   (U_N > mu |U_T|), with every frictionless U > 0 and every bilateral U = 0? A
   linear program maximises the smallest margin t of U_N - mu (cos a U_T1 + sin a
   U_T2) over 16 angles a, each contact's row scaled by 1 / sqrt(W_NN), reported
   relative to |b|. Those 16 facets cut out a polygon that contains the cone, so
   t <= 0 shows that no such P exists: the theorem does not apply, and a solution
   need not exist. t > 0 on the polygon inscribed in the cone (facets divided by
   cos(pi/16)) proves that one does.
Needs numpy and scipy (apt-get install python3-scipy) and a build (scripts/build.sh).
"""
import argparse
import csv
import os
import subprocess
import sys

try:
    import numpy as np
    from scipy.optimize import linprog
except ImportError as e:
    sys.exit(f"stress_unsolved.py needs numpy and scipy ({e}): apt-get install python3-scipy")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(os.environ.get("NSCD_WS", os.path.join(REPO, ".build", "ws")), "devel", "lib", "nscd_sim")
FACETS = 16
MARGIN = 1e-6  # |t| below this (relative to |b|): borderline, counted apart


def read_problem(path):
    """W, b and the blocks (kind letter, first row, size, mu) of an nscd problem file."""
    W, b, blocks = [], None, []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "W":
                W.append([float(x) for x in t[1:]])
            elif t[0] == "b":
                b = np.array([float(x) for x in t[1:]])
            elif t[0] == "block":
                blocks.append((t[1], int(t[2]), int(t[3]), float(t[4])))
    return np.array(W), b, blocks


def strict_margin(W, b, blocks, inner):
    """The largest t with some P making every contact's margin >= t (None if the LP fails)."""
    m = len(b)
    angles = np.arange(FACETS) * 2 * np.pi / FACETS
    widen = 1 / np.cos(np.pi / FACETS) if inner else 1.0
    A, ub, Aeq, beq = [], [], [], []
    for kind, r, size, mu in blocks:
        s = 1 / np.sqrt(max(W[r, r], 1e-300))
        if kind == "F":
            for a in angles:
                g = W[r] - mu * widen * (np.cos(a) * W[r + 1] + np.sin(a) * W[r + 2])
                h = b[r] - mu * widen * (np.cos(a) * b[r + 1] + np.sin(a) * b[r + 2])
                A.append(np.r_[-g * s, 1.0])  # g P + h >= t
                ub.append(h * s)
        elif kind == "N":
            A.append(np.r_[-W[r] * s, 1.0])
            ub.append(b[r] * s)
        else:
            for i in range(r, r + size):
                Aeq.append(np.r_[W[i], 0.0])
                beq.append(-b[i])
    if not A:
        return None
    bound = 1e8 * np.abs(b).max() / max(np.diag(W).max(), 1e-300)  # impulses: 1e8 x the scale of b
    res = linprog(np.r_[np.zeros(m), -1.0], A_ub=np.array(A), b_ub=np.array(ub),
                  A_eq=np.array(Aeq) if Aeq else None, b_eq=np.array(beq) if beq else None,
                  bounds=[(-bound, bound)] * m + [(None, 1.0)], method="highs")
    if res.status != 0:
        return None
    return res.x[-1] / max(np.linalg.norm(b), 1e-300)


def converged_in_run(path):
    with open(path) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "residual":
                return t[3] == "1"
    return False


def dump_case(case, steps, dt, seed, folder, per_case, when):
    """The case's problems (unconverged ones, or converged ones every WHEN-th step;
    PER_CASE of them, evenly spaced) in folder."""
    os.makedirs(folder, exist_ok=True)
    urdf = os.path.join(folder, "scene.urdf")
    subprocess.run([os.path.join(BIN, "nscd_stress"), "--seed", str(seed), "--case", str(case),
                    "--write", urdf], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([os.path.join(BIN, "nscd_run"), urdf, "--duration", repr(steps * dt), "--dt", repr(dt),
                    "--quiet", "--dump-problems", folder, "--dump-when", when],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    files = sorted(f for f in os.listdir(folder) if f.endswith(".txt"))
    if when != "unconverged":
        for f in files:
            if not converged_in_run(os.path.join(folder, f)):
                os.remove(os.path.join(folder, f))
        files = sorted(f for f in os.listdir(folder) if f.endswith(".txt"))
    if len(files) > per_case:
        keep = {files[int(i * len(files) / per_case)] for i in range(per_case)}
        for f in files:
            if f not in keep:
                os.remove(os.path.join(folder, f))
        files = sorted(keep)
    return [os.path.join(folder, f) for f in files]


def solve(paths, tol, max_iter):
    """{path: (converged, residual)} from nscd_solve_problems."""
    out = subprocess.run([os.path.join(BIN, "nscd_solve_problems"), "--tol", repr(tol), "--max-iter",
                          str(max_iter)] + paths, check=True, capture_output=True, text=True).stdout
    by_name = {os.path.basename(p): p for p in paths}
    result = {}
    for line in out.splitlines():
        t = line.split()
        if len(t) >= 7 and t[0] in by_name:
            result[by_name[t[0]]] = (t[2] == "yes", float(t[6]))
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--csv", default=os.path.join(REPO, "build", "perf", "stress.csv"))
    ap.add_argument("--seed", type=int, default=1, help="the stress run's seed")
    ap.add_argument("--every", type=int, default=6)
    ap.add_argument("--per-case", type=int, default=8)
    ap.add_argument("--out", default=os.path.join(REPO, "build", "stress_unsolved"))
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--max-iter", type=int, default=2000)
    args = ap.parse_args()
    for tool in ("nscd_stress", "nscd_run", "nscd_solve_problems"):
        if not os.access(os.path.join(BIN, tool), os.X_OK):
            sys.exit(f"no {os.path.join(BIN, tool)}: run scripts/build.sh")
    if not os.path.exists(args.csv):
        sys.exit(f"no {args.csv}: run scripts/stress.sh first")
    with open(args.csv) as f:
        rows = [r for r in csv.DictReader(f) if int(r["unconverged_steps"]) > 0]
    rows.sort(key=lambda r: int(r["case"]))
    chosen = rows[::args.every]
    print(f"{len(rows)} cases with unconverged steps; sampling {len(chosen)} (every {args.every}th), "
          f"{args.per_case} problems each", file=sys.stderr)
    samples = {"A": [], "B": [], "control": []}
    for i, r in enumerate(chosen):
        case = int(r["case"])
        print(f"  case {case} ({i + 1}/{len(chosen)})", file=sys.stderr)
        folder = os.path.join(args.out, f"case{case}")
        samples["AB"[i % 2]] += dump_case(case, int(r["steps"]), float(r["dt"]), args.seed, folder,
                                          args.per_case, "unconverged")
        samples["control"] += dump_case(case, int(r["steps"]), float(r["dt"]), args.seed,
                                        os.path.join(folder, "converged"), args.per_case, "25")
    table = []
    for name, paths in samples.items():
        if not paths:
            continue
        solved = solve(paths, args.tol, args.max_iter) if name != "control" else {p: (True, 0.0) for p in paths}
        for p in paths:
            W, b, blocks = read_problem(p)
            t_out = strict_margin(W, b, blocks, inner=False)
            t_in = strict_margin(W, b, blocks, inner=True)
            conv, res = solved.get(p, (False, float("nan")))
            table.append((name, os.path.relpath(p, args.out), len(b), conv, res, t_out, t_in))
    with open(os.path.join(args.out, "problems.csv"), "w") as f:
        f.write("sample,problem,rows,converged,residual,t_outer,t_inner\n")
        for row in table:
            f.write(",".join(str(x) for x in row) + "\n")

    def cls(t_out, t_in):
        if t_out is None or t_in is None:
            return "lp failed"
        if t_out < -MARGIN:
            return "not strictly feasible"
        if t_in > MARGIN:
            return "strictly feasible"
        return "borderline"

    kinds = ["strictly feasible", "borderline", "not strictly feasible", "lp failed"]
    print(f"\nA, B: problems the runs left unconverged; control: problems the same runs solved. "
          f"Strict feasibility: the margin t relative to |b| (borderline: |t| <= {MARGIN:g}); "
          f"solved again: at tol {args.tol:g} with budget {args.max_iter}.\n")
    print("| sample | problems | strictly feasible | borderline | not strictly feasible | LP failed "
          "| solved again (of the strictly feasible / the others) |")
    print("|---|---|---|---|---|---|---|")
    for name in ("A", "B", "control"):
        rows_s = [r for r in table if r[0] == name]
        if not rows_s:
            continue
        c = [cls(r[5], r[6]) for r in rows_s]
        again = "—" if name == "control" else (
            f"{sum(1 for r, k in zip(rows_s, c) if r[3] and k == kinds[0])} / "
            f"{sum(1 for r, k in zip(rows_s, c) if r[3] and k != kinds[0])}")
        print(f"| {name} | {len(rows_s)} | " + " | ".join(str(c.count(k)) for k in kinds) + f" | {again} |")
    print(f"\nper problem: {os.path.join(args.out, 'problems.csv')}")


if __name__ == "__main__":
    main()
