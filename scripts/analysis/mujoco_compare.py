#!/usr/bin/env python3
"""Tables of the MuJoCo comparison (scripts/mujoco_compare.sh) from the raw results of
nscd_mujoco_compare: OUT/runs.csv, OUT/references.csv, OUT/load.txt and, when made,
OUT/instructions.csv. Prints Markdown.

    mujoco_compare.py OUT_DIR [--target 1e-4]
"""
import argparse
import csv
import math
import os

METHODS = ("nscd_fixed", "nscd_adaptive", "mujoco_euler", "mujoco_rk4")
LABEL = {"nscd_fixed": "nscd fixed dt", "nscd_adaptive": "nscd adaptive (rtol = atol)",
         "mujoco_euler": "MuJoCo Euler", "mujoco_rk4": "MuJoCo RK4"}
SCENES = ("pendulum", "double_pendulum", "fourbar", "ball")


def g(x, digits=3):
    return "%.*g" % (digits, x) if x == x else "—"


def read_runs(out):
    rows = []
    for r in csv.DictReader(open(os.path.join(out, "runs.csv"))):
        for k in ("setting", "wall_s", "cpu_s", "us_per_step", "err_angle", "err_pos"):
            r[k] = float(r[k]) if r[k] not in ("", "nan", "-nan") else float("nan")
        for k in ("steps", "rejected", "unconverged", "repetitions"):
            r[k] = int(r[k])
        rows.append(r)
    return rows


def wall_at(runs, key, target):
    """Wall time at error `target`: log-log interpolation along the method's cheapest
    runs (its Pareto front: each run more accurate than every cheaper one). Returns
    (wall, how): how is '=' (interpolated), '<=' (only runs below the target: the
    cheapest one's wall bounds it), or None when no run reaches it."""
    ok = sorted((r for r in runs if not r["error"] and r[key] == r[key] and r[key] > 0), key=lambda r: r["wall_s"])
    front = []
    for r in ok:
        if not front or r[key] < front[-1][key]:
            front.append(r)
    if not front or front[-1][key] > target:
        return None, None
    if front[0][key] <= target:
        return front[0]["wall_s"], "<="
    for a, b in zip(front, front[1:]):
        if a[key] > target >= b[key]:
            t = (math.log(target) - math.log(a[key])) / (math.log(b[key]) - math.log(a[key]))
            return math.exp(math.log(a["wall_s"]) + t * (math.log(b["wall_s"]) - math.log(a["wall_s"]))), "="
    return None, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--target", type=float, default=1e-4, help="angle error (rad) of the key table")
    ap.add_argument("--pick", action="store_true",
                    help="only print SCENE METHOD SETTING of each method's cheapest run at or below the target "
                         "(the double pendulum and the four-bar), for callgrind")
    a = ap.parse_args()
    runs = read_runs(a.out)
    if a.pick:
        for s in ("double_pendulum", "fourbar"):
            for m in METHODS:
                ok = [r for r in runs if r["scene"] == s and r["method"] == m and not r["error"]
                      and r["err_angle"] <= a.target]
                if ok:
                    r = min(ok, key=lambda r: r["wall_s"])
                    print(s, m, "%g" % r["setting"])
        return
    info = {}
    if os.path.exists(os.path.join(a.out, "load.txt")):
        for line in open(os.path.join(a.out, "load.txt")):
            k, _, v = line.strip().partition(" ")
            info[k] = v
    print("Run: %s, commit `%s`, MuJoCo %s (Debian libmujoco-dev); load average %s at the start, %s at the end "
          "(1-, 5-, 15-minute, 2 cores shared with other jobs: compare wall times as ratios within a table)."
          % (info.get("date", "?"), info.get("commit", "?"), info.get("mujoco", "?"), info.get("load_start", "?"),
             info.get("load_end", "?")))
    print()

    # Per-step cost at dt 1e-4.
    by = {(r["scene"], r["method"], r["setting"]): r for r in runs}
    print("#### Cost of a step at dt = 1e-4 s (wall and thread CPU time of the stepping loop, fastest repetition)")
    print()
    print("| scene | nscd µs/step | MuJoCo Euler µs/step | MuJoCo RK4 µs/step | nscd / Euler (wall) | nscd / Euler (CPU) "
          "| nscd / RK4 (CPU) |")
    print("|---|---|---|---|---|---|---|")
    for s in SCENES:
        n, e, k = (by.get((s, m, 1e-4)) for m in ("nscd_fixed", "mujoco_euler", "mujoco_rk4"))
        if not (n and e and k):
            continue
        print("| %s | %s | %s | %s | %s | %s | %s |" % (
            s, g(n["us_per_step"]), g(e["us_per_step"]), g(k["us_per_step"]), g(n["wall_s"] / e["wall_s"], 2),
            g(n["cpu_s"] / e["cpu_s"], 2), g(n["cpu_s"] / k["cpu_s"], 2)))
    print()
    ipath = os.path.join(a.out, "instructions.csv")
    if os.path.exists(ipath):
        ins = {(r["scene"], r["method"]): int(r["instructions"]) / int(r["steps"]) for r in csv.DictReader(open(ipath))
               if r["instructions"]}
        print("#### Instructions of a step at dt = 1e-4 s (callgrind, 2000 steps, inside `nscd::Simulator::step()` "
              "and `mj_step`)")
        print()
        print("| scene | nscd | MuJoCo Euler | MuJoCo RK4 | nscd / Euler | nscd / RK4 |")
        print("|---|---|---|---|---|---|")
        for s in SCENES:
            n, e, k = (ins.get((s, m)) for m in ("nscd_fixed", "mujoco_euler", "mujoco_rk4"))
            if n and e and k:
                print("| %s | %.0f | %.0f | %.0f | %.2f | %.2f |" % (s, n, e, k, n / e, n / k))
        print()

    wpath = os.path.join(a.out, "instructions_to_target.csv")
    if os.path.exists(wpath):
        print("#### Instructions of a whole run (1 s) at or below %g rad: each method's cheapest such run of the "
              "grid (callgrind, inside the step functions)" % a.target)
        print()
        print("| scene | method | dt or tolerance | steps | angle error rad | instructions | per step | "
              "/ MuJoCo RK4's |")
        print("|---|---|---|---|---|---|---|---|")
        whole = list(csv.DictReader(open(wpath)))
        for s in ("double_pendulum", "fourbar"):
            rk4 = [int(w["instructions"]) for w in whole if w["scene"] == s and w["method"] == "mujoco_rk4"
                   and w["instructions"]]
            for w in (w for w in whole if w["scene"] == s and w["instructions"]):
                r = by.get((s, w["method"], float(w["setting"])))
                n = int(w["instructions"])
                print("| %s | %s | %s | %d | %s | %.3g | %.0f | %s |" % (
                    s, LABEL[w["method"]], w["setting"], r["steps"] if r else 0, g(r["err_angle"]) if r else "?",
                    n, n / r["steps"] if r and r["steps"] else 0, g(n / rk4[0], 3) if rk4 else "—"))
        print()

    # The key figure: wall time at the target angle error.
    print("#### Wall time to %g rad at t = 1 s (the largest link-angle error against the reference)" % a.target)
    print()
    print("Interpolated log-log between the two runs of a method that bracket the error on its "
          "cheapest-runs front; \"≤\": its cheapest run is already below; \"not reached\": no run is.")
    print()
    print("| scene | " + " | ".join(LABEL[m] + " ms" for m in METHODS) + " | best nscd / MuJoCo RK4 |")
    print("|---|" + "---|" * (len(METHODS) + 1))
    for s in ("pendulum", "double_pendulum", "fourbar"):
        cells, walls = [], {}
        for m in METHODS:
            w, how = wall_at([r for r in runs if r["scene"] == s and r["method"] == m], "err_angle", a.target)
            walls[m] = (w, how)
            cells.append("not reached" if w is None else ("≤ " if how == "<=" else "") + g(1e3 * w))
        ours = min((walls[m] for m in ("nscd_fixed", "nscd_adaptive") if walls[m][0] is not None),
                   default=(None, None))
        rk4 = walls["mujoco_rk4"]
        ratio = "—"
        if ours[0] is not None and rk4[0] is not None:
            # A bound on MuJoCo's wall makes the ratio a lower bound, one on ours an upper bound.
            bound = {("=", "="): "", ("=", "<="): "≥ ", ("<=", "="): "≤ "}.get((ours[1], rk4[1]), "~ ")
            ratio = bound + g(ours[0] / rk4[0], 3)
        print("| %s | %s | %s |" % (s, " | ".join(cells), ratio))
    print()

    # Every run.
    refs = {r["scene"]: r for r in csv.DictReader(open(os.path.join(a.out, "references.csv")))}
    for s in SCENES:
        rs = [r for r in runs if r["scene"] == s]
        if not rs:
            continue
        ref = refs.get(s)
        print("#### %s" % s)
        print()
        if ref:
            print("Reference: %s; its step against twice its step: %s rad, %s m." % (
                "closed form" if s == "ball" else "RK4 in minimal coordinates, 65536 steps",
                ref["self_check_angle"], ref["self_check_pos"]))
            print()
        print("| method | dt or tolerance | steps (rejected) | wall ms | µs/step | angle error rad | position error m |")
        print("|---|---|---|---|---|---|---|")
        for m in METHODS:
            for r in sorted((r for r in rs if r["method"] == m), key=lambda r: -r["setting"]):
                steps = "%d" % r["steps"] + (" (%d)" % r["rejected"] if m == "nscd_adaptive" else "")
                err = ("error: " + r["error"]) if r["error"] else ""
                print("| %s | %g | %s | %s | %s | %s | %s |%s" % (
                    LABEL[m], r["setting"], steps, g(1e3 * r["wall_s"]), g(r["us_per_step"]),
                    "—" if s == "ball" else g(r["err_angle"]), g(r["err_pos"]), " " + err if err else ""))
        print()


if __name__ == "__main__":
    main()
