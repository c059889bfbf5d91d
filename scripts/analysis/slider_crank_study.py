#!/usr/bin/env python3
"""Why the slider-crank's work-precision flattens near 1e-4 m (docs/work_precision.md).

Runs urdf/slider_crank.urdf (0.2 s, positions every 1 ms) with nscd_run at a ladder of
h in three configurations (the defaults; solver tolerance 1e-12; contact rows built at
q_k, contact_prediction=0), each against a reference at h = 1e-7 in the same
configuration; a second reference (h = 2e-7) and a run with a tighter projection
tolerance answer "is it the reference?" and "is it the projection?". For every run: the largest position error (which body, when) and the
slider's largest tilt about z (the exact slider never tilts: it is pinned at its
centre of mass and both lower corners strike together). Writes OUT/crank_study.md
(Markdown tables) and OUT/crank_*.csv (nscd_run's time series).

    slider_crank_study.py --bin DEVEL/lib/nscd_sim --scene urdf/slider_crank.urdf --out OUT [--quick]
"""
import argparse
import csv
import json
import math
import os
import subprocess

BODIES = ("crank", "rod", "slider")
HALF_LENGTH = 0.05  # the slider's corners from its pin, m (urdf/slider_crank.urdf)


def run(args, name, h, sets):
    """nscd_run at step h with settings `sets`; returns (samples, summary). Reuses an existing CSV."""
    path = os.path.join(args.out, "crank_%s.csv" % name)
    jpath = path[:-4] + ".json"
    if not (os.path.exists(path) and os.path.exists(jpath)):
        every = max(1, round(1e-3 / h))
        cmd = [os.path.join(args.bin, "nscd_run"), args.scene, "--duration", "0.2", "--dt", "%g" % h,
               "--csv", path, "--every", str(every), "--quiet"]
        for s in sets:
            cmd += ["--set", s]
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        open(jpath, "w").write(out.strip().splitlines()[-1] + "\n")
    rows = []
    for r in csv.DictReader(open(path)):
        rows.append({k: float(v) for k, v in r.items() if k == "t" or k.split(".")[0] in BODIES})
    return rows, json.loads(open(jpath).read())


def tilt(r):
    return 2 * math.atan2(r["slider.qz"], r["slider.qw"])


def compare(a, b):
    """Largest centre-of-mass distance over bodies and common samples: (err, t, body)."""
    best = (0.0, 0.0, "")
    for ra, rb in zip(a, b):
        if abs(ra["t"] - rb["t"]) > 1e-9:
            continue
        for bd in BODIES:
            d = math.sqrt(sum((ra["%s.%s" % (bd, k)] - rb["%s.%s" % (bd, k)]) ** 2 for k in "xyz"))
            if d > best[0]:
                best = (d, ra["t"], bd)
    return best


def max_tilt(rows):
    m = max(rows, key=lambda r: abs(tilt(r)))
    return abs(tilt(m)), m["t"]


def first_tilt(rows, level):
    return next((r["t"] for r in rows if abs(tilt(r)) > level), None)


def slope(hs, errs):
    pts = [(math.log(h), math.log(e)) for h, e in zip(hs, errs) if e > 0]
    n = len(pts)
    if n < 2:
        return float("nan")
    sx = sum(x for x, _ in pts); sy = sum(y for _, y in pts)
    sxx = sum(x * x for x, _ in pts); sxy = sum(x * y for x, y in pts)
    return (n * sxy - sx * sy) / (n * sxx - sx * sx)


def g(x, d=3):
    return "%.*g" % (d, x) if x is not None and x == x else "—"


def tilted_scene(args, tilt0):
    """The scene with the slider turned by tilt0 rad on its pin at the start (rod along +x: the tilt)."""
    path = os.path.join(args.out, "crank_tilt%g.urdf" % tilt0)
    text = open(args.scene).read()
    anchor = '<initial link="crank"'
    if anchor not in text:
        raise SystemExit("%s: no %s to put the slider's initial angle before" % (args.scene, anchor))
    open(path, "w").write(text.replace(anchor, '<initial joint="slider_joint" position="%r"/>\n    %s' % (tilt0, anchor), 1))
    return path


def first_impact(args):
    """The slider's largest spin in the first 3.5 ms (its first impact, at 1.95 ms) against its initial tilt and h."""
    tilts = [0, 1e-6, 1e-4] if args.quick else [0, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4]
    hs = [1e-5, 1e-6] if args.quick else [1e-5, 1e-6, 1e-7]
    md = ["The first impact (t = 1.95 ms, both lower corners at once when flat): the slider's largest |wz| "
          "(rad/s) in the first 3.5 ms against its initial tilt on the pin (`<initial joint=\"slider_joint\" "
          "position=...>`) and h; `nscd_run SCENE --duration 0.0035 --dt H --set tolerance=1e-12`:\n\n",
          "| initial tilt rad | " + " | ".join("h = %g" % h for h in hs) + " |\n", "|---|" + "---|" * len(hs) + "\n"]
    for t0 in tilts:
        cells = []
        for h in hs:
            path = os.path.join(args.out, "crank_first_tilt%g_h%g.csv" % (t0, h))
            if not os.path.exists(path):
                subprocess.run([os.path.join(args.bin, "nscd_run"), tilted_scene(args, t0), "--duration", "0.0035",
                                "--dt", "%g" % h, "--csv", path, "--every", str(max(1, round(1e-5 / h))), "--quiet",
                                "--set", "tolerance=1e-12"], check=True, capture_output=True)
            cells.append(g(max(abs(float(r["slider.wz"])) for r in csv.DictReader(open(path))), 2))
        md.append("| %g | %s |\n" % (t0, " | ".join(cells)))
    return md + ["\n"]


def read_problem(path):
    """A --dump-problems file: (header, contact blocks [(row, b_N, P_N, U_N)], residual, |b|)."""
    lines = open(path).read().split("\n")
    vec = lambda tag: [float(x) for x in next(l for l in lines if l.startswith(tag + " ")).split()[1:]]
    W = [[float(x) for x in l.split()[1:]] for l in lines if l.startswith("W ")]
    b, P = vec("b"), vec("P")
    U = [sum(w * p for w, p in zip(W[i], P)) + b[i] for i in range(len(b))]
    rows = [int(l.split()[2]) for l in lines if l.startswith("block F") or l.startswith("block N")]
    residual = float(lines[2].split()[1])
    return [(r, b[r], P[r], U[r]) for r in rows], residual, math.sqrt(sum(x * x for x in b))


def kick_problem(args, sets, h, step):
    """The problems of the step that ends at row `step` of an every-step CSV, in solve order."""
    d = os.path.join(args.out, "crank_kick_%s_%d" % ("_".join(x.replace("=", "") for x in sets), step))
    if not os.path.isdir(d):
        os.makedirs(d)
        cmd = [os.path.join(args.bin, "nscd_run"), args.scene, "--dt", "%g" % h, "--duration", "%r" % ((step + 1) * h),
               "--quiet", "--dump-problems", d, "--dump-when", str(step - 1)]
        for x in sets:
            cmd += ["--set", x]
        subprocess.run(cmd, check=True, capture_output=True)
    names = sorted(f for f in os.listdir(d) if f.startswith("step%08d_" % step))
    return [(f, read_problem(os.path.join(d, f))) for f in names]


def seeds(args):
    """The first kick of the flat slider's spin, and the first impact that spins it, in runs at h = 2e-6."""
    h = 2e-6
    duration = 0.06 if args.quick else 0.14
    md = ["Where the tilt starts, h = %g, every step (`nscd_run SCENE --dt %g --duration %g --csv F --set ...`); the "
          "kick: the first step that changes the slider's wz by more than 1e-3 rad/s while its tilt is below 1e-8 rad; "
          "its problem dumped (`--dump-problems D --dump-when N`); b_N: a corner's normal free velocity with its "
          "law's shifts (e U_N,k; a late corner's gap / h); U_N = W P + b after the solve. The spin: the first step "
          "that changes wz by more than 1 rad/s, with the corners' height difference a * tilt against the "
          "slider's fall in one step h |vy| before it:\n\n" % (h, h, duration),
          "| configuration | kick at t s | wz rad/s before -> after | solves: corner blocks (b_N m/s; P_N N s; U_N m/s) | "
          "residual (normalised by ‖b‖ =) | spin at t s: wz after rad/s | tilt before rad, a * tilt m, h * vy m |\n",
          "|---|---|---|---|---|---|---|\n"]
    for label, key, sets in [("default (tolerance 1e-8)", "tol1e-08", ["tolerance=1e-08"]),
                             ("tolerance 1e-12", "tol1e-12", ["tolerance=1e-12"])]:
        path = os.path.join(args.out, "crank_every_%s.csv" % key)
        if not os.path.exists(path):
            cmd = [os.path.join(args.bin, "nscd_run"), args.scene, "--dt", "%g" % h, "--duration", "%g" % duration,
                   "--csv", path, "--quiet"]
            for x in sets:
                cmd += ["--set", x]
            subprocess.run(cmd, check=True, capture_output=True)
        rows = [{k: float(v) for k, v in r.items() if k == "t" or k.startswith("slider.")}
                for r in csv.DictReader(open(path))]
        kick = next((i for i in range(1, len(rows)) if abs(rows[i]["slider.wz"] - rows[i - 1]["slider.wz"]) > 1e-3
                     and abs(tilt(rows[i - 1])) < 1e-8), None)
        spin = next((i for i in range(1, len(rows)) if abs(rows[i]["slider.wz"] - rows[i - 1]["slider.wz"]) > 1), None)
        cells = [label]
        if kick is None:
            cells += ["—"] * 4
        else:
            solves = []
            res = ""
            for name, (blocks, residual, bnorm) in kick_problem(args, sets, h, kick):
                solves.append("%s: %s" % (name.split("_", 1)[1][:-4], ", ".join(
                    "(%.3g; %.3g; %.2g)" % (bn, pn, un) for _, bn, pn, un in blocks)))
                res = "%s (%s)" % (g(residual, 2), g(bnorm, 3))
            cells += ["%.6f" % rows[kick]["t"], "%s -> %s" % (g(rows[kick - 1]["slider.wz"], 2), g(rows[kick]["slider.wz"], 3)),
                      "<br>".join(solves) or "—", res]
        if spin is None:
            cells += ["—", "—"]
        else:
            b = rows[spin - 1]
            cells += ["%.6f: %s" % (rows[spin]["t"], g(rows[spin]["slider.wz"], 3)),
                      "%s, %s, %s" % (g(tilt(b), 2), g(HALF_LENGTH * abs(tilt(b)), 2), g(h * abs(b["slider.vy"]), 2))]
        md.append("| %s |\n" % " | ".join(cells))
    return md + ["\n"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    hs = [1e-4, 1e-5, 1e-6] if args.quick else [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6]
    href = 1e-6 / 4 if args.quick else 1e-7
    # The configurations compared: the defaults, a tighter solver, contact rows at q_k.
    configs = [("default (tolerance 1e-8)", "tol1e-08", ["tolerance=1e-08"]),
               ("tolerance 1e-12", "tol1e-12", ["tolerance=1e-12"]),
               ("contact_prediction=0", "pred0", ["tolerance=1e-08", "contact_prediction=0"])]
    md = []
    md.append("Runs: `nscd_run urdf/slider_crank.urdf --duration 0.2 --dt H --csv F --every N --set ...`, centres "
              "of mass every 1 ms, each compared with the reference of its own configuration (h = %g) "
              "(scripts/analysis/slider_crank_study.py). Tilt: the slider's rotation about z (the exact slider's "
              "is 0).\n\n" % href)
    refs = {key: run(args, "ref_" + key, href, sets) for _, key, sets in configs}
    md.append("| h | " + " | ".join("%s: max error m (t s, body) | largest tilt rad" % label for label, _, _ in configs)
              + " |\n")
    md.append("|---|" + "---|---|" * len(configs) + "\n")
    errs = {key: [] for _, key, _ in configs}
    for h in hs:
        cells = []
        for _, key, sets in configs:
            rows, _ = run(args, "h%g_%s" % (h, key), h, sets)
            e, t, bd = compare(rows, refs[key][0])
            errs[key].append(e)
            cells += ["%s (%.3f, %s)" % (g(e), t, bd), g(max_tilt(rows)[0], 2)]
        md.append("| %g | %s |\n" % (h, " | ".join(cells)))
    md.append("| %g (reference) | %s |\n\n" % (href, " | ".join(
        "— | %s" % g(max_tilt(refs[key][0])[0], 2) for _, key, _ in configs)))
    md.append("Observed order of the max error (least squares over every h): %s.\n\n" % "; ".join(
        "%s %.2f" % (label, slope(hs, errs[key])) for label, key, _ in configs))

    # The flat motion alone: the coarse runs against the finest run whose slider stays flat.
    flat_key = "tol1e-12"
    flat_h = min((h for h in hs if max_tilt(run(args, "h%g_%s" % (h, flat_key), h, ["tolerance=1e-12"])[0])[0] < 1e-9),
                 default=max(hs))
    flat, _ = run(args, "h%g_%s" % (flat_h, flat_key), flat_h, ["tolerance=1e-12"])
    coarse = [h for h in hs if h > flat_h * 1.5]
    md.append("The coarse runs at tolerance 1e-12 against the finest one whose slider stays flat (h = %g, "
              "largest tilt %s rad):\n\n| h | max error m (t s, body) |\n|---|---|\n" % (
                  flat_h, g(max_tilt(flat)[0], 2)))
    flat_errs = []
    for h in coarse:
        rows, _ = run(args, "h%g_%s" % (h, flat_key), h, ["tolerance=1e-12"])
        e, t, bd = compare(rows, flat)
        flat_errs.append(e)
        md.append("| %g | %s (%.3f, %s) |\n" % (h, g(e), t, bd))
    md.append("\nObserved order: %.2f.\n\n" % slope(coarse, flat_errs))

    # Is it the reference? Is it the projection?
    md.append("| check | compared with | max difference m | at t s (body) | slider's largest tilt rad | "
              "tilt first above 1e-9 rad at t s |\n|---|---|---|---|---|---|\n")
    for label, key, _ in configs:
        md.append("| reference h = %g, %s | — | — | — | %s | %s |\n" % (
            href, label, g(max_tilt(refs[key][0])[0], 2), g(first_tilt(refs[key][0], 1e-9))))
    if not args.quick:
        ref2, _ = run(args, "ref2_tol1e-08", 2e-7, ["tolerance=1e-08"])
        e, t, bd = compare(ref2, refs["tol1e-08"][0])
        md.append("| reference h = 2e-7, default | reference h = %g, default | %s | %.3f (%s) | %s | %s |\n" % (
            href, g(e), t, bd, g(max_tilt(ref2)[0], 2), g(first_tilt(ref2, 1e-9))))
    e, t, bd = compare(refs["tol1e-12"][0], refs["tol1e-08"][0])
    md.append("| reference h = %g, tolerance 1e-12 | reference h = %g, default | %s | %.3f (%s) | | |\n" % (
        href, href, g(e), t, bd))
    e, t, bd = compare(refs["pred0"][0], refs["tol1e-08"][0])
    md.append("| reference h = %g, contact_prediction=0 | reference h = %g, default | %s | %.3f (%s) | | |\n" % (
        href, href, g(e), t, bd))
    base, _ = run(args, "h1e-05_tol1e-08", 1e-5, ["tolerance=1e-08"])
    proj, _ = run(args, "h1e-05_proj1e-12", 1e-5, ["tolerance=1e-08", "projection_tolerance=1e-12"])
    e, t, bd = compare(proj, base)
    md.append("| h = 1e-5, projection tolerance 1e-12 | h = 1e-5, default (1e-9) | %s | %.3f (%s) | %s | %s |\n"
              % (g(e), t, bd, g(max_tilt(proj)[0], 2), g(first_tilt(proj, 1e-9))))
    md.append("\n")
    md += first_impact(args)
    md += seeds(args)
    open(os.path.join(args.out, "crank_study.md"), "w").write("".join(md))
    print("".join(md))


if __name__ == "__main__":
    main()
