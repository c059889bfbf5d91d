#!/usr/bin/env python3
"""Writes docs/performance.md (and docs/stress.png, docs/soak_memory.png) from the
raw results scripts/performance.sh leaves in build/perf. Run by performance.sh."""
import argparse
import csv
import datetime
import json
import os
import platform
import statistics
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from machine import cpu  # noqa: E402

PEN_TOL = 0.01
GAIN_TOL = 1e-9


def jline(path):
    """The last JSON line of a text file (the tools print one summary line)."""
    if not os.path.exists(path):
        return None
    for line in reversed(open(path).read().splitlines()):
        line = line.strip()
        if line.startswith("{"):
            return json.loads(line)
    return None


def git_rev(repo):
    """HEAD's short hash, marked when files outside docs/ (which the run writes) differ from it."""
    try:
        rev = subprocess.check_output(["git", "-C", repo, "rev-parse", "--short", "HEAD"], text=True).strip()
        dirty = subprocess.check_output(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no",
                                         "--", ".", ":!docs"], text=True)
        changed = [line[3:] for line in dirty.splitlines() if line.strip()]
        return rev + ("` with uncommitted changes to `" + ", ".join(changed) if changed else "")
    except Exception:
        return "unknown"


def read_text(path):
    return open(path).read() if os.path.exists(path) else None


STAGES = ("c60", "c60dt", "wp", "stress", "seeds", "soak", "sweep", "bench", "speed")


def elapsed_section(out, elapsed):
    """How long the run took, and which stages' raw results come from an earlier run
    (performance.sh writes ran_STAGE.txt, 'COMMIT|DATE|LOAD', when a stage runs)."""
    text = "%d min %d s" % divmod(elapsed, 60)
    skipped = os.environ.get("PERF_SKIP", "").split()
    runs = {}  # commit -> [(stage, date, load)]
    for st in STAGES:
        if st not in skipped:
            continue
        ran = read_text(os.path.join(out, "ran_%s.txt" % st))
        commit, date, load = (ran.strip().split("|") + ["?"])[:3] if ran else ("?", "an unknown date", "?")
        runs.setdefault(commit, []).append((st, date, load))
    if runs:
        parts = []
        for commit, stages in runs.items():
            dates = sorted(d for _, d, _ in stages)
            when = dates[0] if dates[0] == dates[-1] else "%s to %s" % (dates[0], dates[-1][11:])
            loads = sorted({ld for _, _, ld in stages}, key=lambda x: float(x) if x.replace(".", "", 1).isdigit() else 0)
            load = loads[0] if len(loads) == 1 else "%s-%s as each stage ended" % (loads[0], loads[-1])
            parts.append("%s at commit `%s` (%s, load %s)" % (", ".join(st for st, _, _ in stages), commit, when, load))
        if all(st in skipped for st in STAGES):
            text += " to make the page again from the raw results of earlier runs: " + "; ".join(parts)
        else:
            text += " for the stages it ran; the raw results of the others come from earlier runs: " + "; ".join(parts)
    return text


def load_section(out):
    start, end = read_text(os.path.join(out, "load_start.txt")), read_text(os.path.join(out, "load_end.txt"))
    if not start:
        return "unknown"
    return "%s at the start and %s at the end (1-, 5-, 15-minute averages, %d cores)" % (
        start.strip(), (end or "?").strip(), os.cpu_count())


def c60_solver_section(out):
    """The table of scripts/c60_solver_bench.sh's fixed-width output."""
    text = read_text(os.path.join(out, "c60_solver.txt"))
    if not text:
        return "_(missing: run scripts/c60_solver_bench.sh)_\n"
    rows = []
    for line in text.splitlines()[1:]:
        f = line.split()
        if len(f) != 10:
            continue
        rows.append(dict(scenario=f[0], model=f[1], dt=f[2], unconv=int(f[3]), it_mean=float(f[4]),
                         it_max=int(f[5]), res=float(f[6]), fl=int(f[7]), cap=int(f[8]), wall=float(f[9])))
    s = ["| scenario | model | dt | unconverged steps | iterations mean / max | largest residual "
         "| frictionless / energy cap | wall s |\n|---|---|---|---|---|---|---|---|\n"]
    for r in rows:
        s.append("| %s | %s | %s | %d | %.1f / %d | %.2g | %d / %d | %.2f |\n" % (
            r["scenario"], r["model"], r["dt"], r["unconv"], r["it_mean"], r["it_max"], r["res"], r["fl"],
            r["cap"], r["wall"]))
    bad = [r for r in rows if r["unconv"] or r["fl"] or r["cap"]]
    s.append("\n%d of %d scenarios end with no unconverged step and no physics-changing fallback.%s\n" % (
        len(rows) - len(bad), len(rows),
        "" if not bad else " The others: " + ", ".join("%s %s %s" % (r["scenario"], r["model"], r["dt"])
                                                       for r in bad) + "."))
    return "".join(s)


def c60_speed_section(out):
    """The speed stage: per run the minimum over the repetitions of the stepping's wall
    time and of the process's CPU time."""
    path = os.path.join(out, "speed.csv")
    if not os.path.exists(path):
        return "_(missing: the speed stage of scripts/performance.sh)_\n"
    runs = {}
    for r in csv.DictReader(open(path)):
        runs.setdefault(r["run"], []).append(r)
    what = {"trip_1e-5": "the trip, 20.7 ms, dt 1e-5", "trip_1e-6": "the trip, 20.7 ms, dt 1e-6",
            "rest_1e-5": "at rest, 100 ms from the assembled state, dt 1e-5"}
    s = ["| run (`urdf/c60.urdf`) | steps | repetitions | wall s of the stepping, min | µs per step (wall) "
         "| CPU s of the process, min | iterations mean |\n|---|---|---|---|---|---|---|\n"]
    for name, rs in runs.items():
        steps = int(rs[0]["steps"])
        wall = min(float(r["wall_s"]) for r in rs)
        cpu = min(float(r["cpu_s"]) for r in rs)
        s.append("| %s | %d | %d | %.3f | %.1f | %.3f | %s |\n" % (
            what.get(name, name), steps, len(rs), wall, 1e6 * wall / steps, cpu, rs[0]["iters_mean"]))
    return "".join(s)


def c60_dt_section(out):
    text = read_text(os.path.join(out, "c60_dt.md"))
    if not text:
        return "_(missing: run scripts/analysis/c60_trip_convergence.py)_\n"
    s = text.strip() + "\n"
    res = read_text(os.path.join(out, "c60_dt.json"))
    if res:
        fine = [r for r in json.loads(res)["rows"] if r["dt"] <= 1.0000001e-6]
        t0 = 0.0007  # the probe's start: times are compared from it
        spread = []
        for key, label, is_time in (("release_s", "release", True), ("c7_open_s", "C7 opens", True),
                                    ("mean_push_N", "mean push", False), ("peak_0.1ms_N", "0.1-ms peak", False)):
            v = [r[key] - t0 if is_time else r[key] for r in fine if r.get(key) is not None]
            if len(v) >= 2:
                mean = sum(v) / len(v)
                spread.append("%s ±%.1f %%" % (label, 50.0 * (max(v) - min(v)) / abs(mean)))
        if len(fine) >= 2 and spread:
            s += ("\nSpread among the %d runs at dt ≤ 1e-6 (the reference included; half the range over their "
                  "mean, times from the probe's start): %s.\n" % (len(fine), ", ".join(spread)))
    return s


def stress_seeds_section(out):
    rows = []
    for name in ("stress_summary.json", "stress_seed2.json", "stress_seed3.json"):
        j = jline(os.path.join(out, name))
        if j:
            rows.append(j)
    if not rows:
        return "_(missing)_\n"
    s = ["| seed | runs × steps | unconverged steps (runs) | steps halved (most substeps) | longer last solves "
         "| plastic retries | frictionless re-solves | energy caps | max pen. / clearance | max energy gain / scale "
         "| NaN / crash | wall s |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n"]
    for j in rows:
        s.append("| %d | %d × %d | %d (%d) | %d (%d) | %d | %d | %d | %d | %.2g | %.2g | %d | %.1f |\n" % (
            j["seed"], j["runs"], j["steps_per_run"], j["unconverged_steps"], j["unconverged_runs"],
            j.get("halved_steps", 0), j.get("substeps_max", 0), j.get("longer_solve_steps", 0),
            j.get("plastic_retry_steps", 0), j.get("frictionless_fallback_steps", 0),
            j.get("energy_capped_steps", 0), j["pen_rel_max"], j["energy_gain_rel_max"], j["failed"], j["wall_s"]))
    return "".join(s)


def bench_medians(path):
    """Benchmark name -> median CPU time per iteration in µs (Google Benchmark's JSON)."""
    if not os.path.exists(path):
        return {}
    out, by_name = {}, {}
    unit = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
    for b in json.load(open(path)).get("benchmarks", []):
        name = b.get("run_name", b["name"])
        t = b["cpu_time"] * unit[b.get("time_unit", "ns")]
        if b.get("aggregate_name") == "median":
            out[name] = t
        elif b.get("run_type", "iteration") == "iteration":
            by_name.setdefault(name, []).append(t)
    for name, ts in by_name.items():
        out.setdefault(name, statistics.median(ts))
    return out


def skips_section(out):
    b = bench_medians(os.path.join(out, "bench.json"))
    m = bench_medians(os.path.join(out, "bench_markers.json"))
    if not b:
        return "_(missing: run nscd_bench)_\n"

    def us(d, k):
        return d.get(k)

    def row(what, bench, without, with_):
        if without is None or with_ is None:
            return "| %s | %s | — | — | — |\n" % (what, bench)
        return "| %s | %s | %.3g µs | %.3g µs | %.1f× |\n" % (what, bench, without, with_, without / with_)

    s = ["| skip | benchmark (without vs with) | without | with | gain |\n|---|---|---|---|---|\n"]
    s.append(row("contacts that cannot close stay out of the solver",
                 "journal at rest (8 candidate points, 2 closed): `BM_JournalAtRest/no_skip` vs `/skip`",
                 us(b, "BM_JournalAtRest/no_skip"), us(b, "BM_JournalAtRest/skip")))
    s.append(row("the same", "3D clearance pendulum: `BM_ClearancePendulumNoSkip` vs `BM_ClearancePendulum/three_d`",
                 us(b, "BM_ClearancePendulumNoSkip"), us(b, "BM_ClearancePendulum/three_d")))
    s.append(row("μ = 0 contacts are one row",
                 "12 frictionless contacts, cold solve: `BM_FrictionlessContacts/three_rows:1` vs `:0`",
                 us(b, "BM_FrictionlessContacts/three_rows:1"), us(b, "BM_FrictionlessContacts/three_rows:0")))
    s.append(row("planar scenes: 3 DOF per body, one ring per joint, contacts in closed form",
                 "clearance pendulum: `BM_ClearancePendulum/three_d` vs `/planar`",
                 us(b, "BM_ClearancePendulum/three_d"), us(b, "BM_ClearancePendulum/planar")))
    on, off = us(b, "BM_JournalProjection/on"), us(b, "BM_JournalProjection/off")
    if on is not None and off is not None:
        s.append("| no projection pass when nothing is violated | journal at rest: `BM_JournalProjection/on` (the "
                 "step measures the violation and returns) against `/off` (the same measurement, made when "
                 "`stats()` is read, as the benchmark does every step) | off: %.3g µs | on: %.3g µs | on costs "
                 "%.2f of off |\n" % (off, on, on / off))
    step, markers, contacts = us(m, "BM_C60Step"), us(m, "BM_C60MarkerArray"), us(m, "BM_C60ContactsMessage")
    if step and markers:
        s.append("| markers built only with subscribers | C-60 at rest: `BM_C60MarkerArray` (one publication) against "
                 "`BM_C60Step` (one step) | %.3g µs per publication | 0 | %.2f of a step's %.3g µs; %.2g ms of CPU per "
                 "second at 30 Hz |\n" % (markers, markers / step, step, 30 * markers / 1000))
    if contacts:
        s.append("| the same, for `~contacts` | `BM_C60ContactsMessage` | %.3g µs per publication | 0 | — |\n"
                 % contacts)
    s.append("\nNothing is allocated inside a step once warm: the soak (§5) counts the heap allocations.\n")
    return "".join(s)


def stress_section(out, docs):
    path = os.path.join(out, "stress.csv")
    summ = jline(os.path.join(out, "stress_summary.json"))
    txt = open(os.path.join(out, "stress.txt")).read() if os.path.exists(os.path.join(out, "stress.txt")) else ""
    if not os.path.exists(path) or summ is None:
        return "_(stress results missing: run scripts/stress.sh)_\n"
    rows = list(csv.DictReader(open(path)))
    for r in rows:
        for k in ("radial", "mu", "e", "dt", "mass_ratio", "pen_rel", "energy_gain_rel", "unconverged_residual_max",
                  "iters_mean"):
            r[k] = float(r[k])
        r["unconverged_steps"] = int(r["unconverged_steps"])
        r["steps"] = int(r["steps"])
    ok = [r for r in rows if r["status"] == "ok"]
    steps_per_run = summ["steps_per_run"]

    def group(name, pred):
        g = [r for r in ok if pred(r)]
        if not g:
            return "| %s | 0 | | | | | |\n" % name
        return "| %s | %d | %d | %.3g | %d | %.3g | %d (%.2f%% of steps) |\n" % (
            name, len(g), sum(r["pen_rel"] > PEN_TOL for r in g), max(r["pen_rel"] for r in g),
            sum(r["energy_gain_rel"] > GAIN_TOL for r in g), max(r["energy_gain_rel"] for r in g),
            sum(r["unconverged_steps"] > 0 for r in g),
            100.0 * sum(r["unconverged_steps"] for r in g) / max(1, sum(r["steps"] for r in g)))

    s = []
    s.append("| | value |\n|---|---|\n")
    s.append("| runs (seed %d, %d steps each) | %d |\n" % (summ["seed"], steps_per_run, summ["runs"]))
    s.append("| total steps / wall time | %d / %.1f s |\n" % (summ["total_steps"], summ["wall_s"]))
    s.append("| **NaN / crash / exception** | **%d** |\n" % summ["failed"])
    s.append("| max penetration / clearance (projection on) | %.3g (runs over 1%%: **%d**) |\n"
             % (summ["pen_rel_max"], summ["pen_rel_over_1pct"]))
    s.append("| max energy gain / energy scale | %.3g (runs over %.0e: **%d**) |\n"
             % (summ["energy_gain_rel_max"], GAIN_TOL, summ["energy_gain_over_tol"]))
    s.append("| runs with unconverged solver steps | %d (%d steps, %.2f%% of all; worst residual %.3g) |\n"
             % (summ["unconverged_runs"], summ["unconverged_steps"],
                100.0 * summ["unconverged_steps"] / max(1, summ["total_steps"]), summ["unconverged_residual_max"]))
    if "halved_steps" in summ:
        s.append("| steps taken again in halves (most substeps in one step) | %d (%d) |\n"
                 % (summ["halved_steps"], summ["substeps_max"]))
    if "longer_solve_steps" in summ:
        s.append("| steps whose problem, unsolved where the step could not be halved, was solved once more with 10 times the budget (answer kept) | %d |\n"
                 % summ["longer_solve_steps"])
    if "plastic_retry_steps" in summ:
        s.append("| plastic retries (restitution unsolved, solved with e = 0) / frictionless fallbacks | %d / %d |\n"
                 % (summ["plastic_retry_steps"], summ["frictionless_fallback_steps"]))
    rerun = [l for l in txt.splitlines() if l.startswith("rerun")]
    s.append("| rerun on 1 thread, CSV compared byte for byte | %s |\n\n" % (rerun[0].split(": ", 1)[1] if rerun else "not run"))
    s.append("By kind and time step (runs over the thresholds):\n\n")
    s.append("| group | runs | pen > 1% | max pen/c | gain > tol | max gain | runs with unconverged steps |\n")
    s.append("|---|---|---|---|---|---|---|\n")
    s.append(group("planar, 1 link", lambda r: r["planar"] == "1" and r["links"] == "1"))
    s.append(group("planar, 2 links", lambda r: r["planar"] == "1" and r["links"] == "2"))
    s.append(group("3D, 1 link", lambda r: r["planar"] == "0" and r["links"] == "1"))
    s.append(group("3D, 2 links", lambda r: r["planar"] == "0" and r["links"] == "2"))
    for lo in (1e-6, 1e-5, 1e-4):
        s.append(group("h in [%g, %g)" % (lo, lo * 10), lambda r, lo=lo: lo <= r["dt"] < lo * 10))
    s.append(group("clearance < 10 µm", lambda r: r["radial"] < 1e-5))
    s.append(group("clearance >= 10 µm", lambda r: r["radial"] >= 1e-5))
    s.append(group("mass ratio > 10 or < 0.1", lambda r: r["mass_ratio"] > 10 or r["mass_ratio"] < 0.1))
    s.append("\nWorst runs (replay any with `nscd_stress --seed %d --case K --write case.urdf`, which prints the "
             "`nscd_run` command):\n\n" % summ["seed"])
    s.append("| case | kind | clearance | mu | e | h | mass ratio | pen/c | gain | unconverged steps | worst residual |\n")
    s.append("|---|---|---|---|---|---|---|---|---|---|---|\n")
    worst = sorted(ok, key=lambda r: -r["pen_rel"])[:5] + sorted(ok, key=lambda r: -r["energy_gain_rel"])[:3]
    seen = set()
    for r in worst:
        if r["case"] in seen:
            continue
        seen.add(r["case"])
        s.append("| %s | %s, %s link%s | %.3g | %.2f | %.2f | %.3g | %.3g | %.3g | %.3g | %d | %.3g |\n" % (
            r["case"], "planar" if r["planar"] == "1" else "3D", r["links"], "s" if r["links"] == "2" else "",
            r["radial"], r["mu"], r["e"], r["dt"], r["mass_ratio"], r["pen_rel"], r["energy_gain_rel"],
            r["unconverged_steps"], r["unconverged_residual_max"]))

    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for planar, col, lab in (("1", "tab:blue", "planar"), ("0", "tab:red", "3D")):
        g = [r for r in ok if r["planar"] == planar]
        ax[0].loglog([r["dt"] for r in g], [max(r["pen_rel"], 1e-12) for r in g], ".", color=col, ms=3, label=lab)
        ax[1].loglog([r["dt"] for r in g], [max(r["energy_gain_rel"], 1e-18) for r in g], ".", color=col, ms=3, label=lab)
        ax[2].loglog([r["radial"] for r in g], [max(r["unconverged_steps"], 0.5) for r in g], ".", color=col, ms=3, label=lab)
    ax[0].axhline(PEN_TOL, color="k", ls=":")
    ax[1].axhline(GAIN_TOL, color="k", ls=":")
    ax[0].set(xlabel="h, s", ylabel="max penetration / clearance", title="penetration (floor 1e-12)")
    ax[1].set(xlabel="h, s", ylabel="max (E(t) - E(0)) / energy scale", title="energy gain (floor 1e-18)")
    ax[2].set(xlabel="radial clearance, m", ylabel="unconverged steps (0 shown at 0.5)",
              title="solver non-convergence (of %d steps)" % steps_per_run)
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(docs, "stress.png"), dpi=100)
    s.append("\n![stress](stress.png)\n")
    return "".join(s)


def soak_section(out, docs):
    soak = massif = None
    if os.path.exists(os.path.join(out, "soak.txt")):
        for line in open(os.path.join(out, "soak.txt")):
            if line.startswith('{"massif'):
                massif = json.loads(line)
            elif line.startswith('{"soak_steps'):
                soak = json.loads(line)
    if soak is None:
        return "_(soak results missing: run scripts/soak.sh)_\n"
    s = ["| | value |\n|---|---|\n"]
    s.append("| scene / h | `%s` / %g s |\n" % (os.path.relpath(soak["scene"], os.path.dirname(docs)), soak["dt"]))
    s.append("| steps | %d (%.3g s simulated) |\n" % (soak["soak_steps"], soak["soak_steps"] * soak["dt"]))
    s.append("| wall time | %.1f s (%.2f µs/step) |\n" % (soak["wall_s"], soak["us_per_step"]))
    s.append("| resident memory after warm-up (10 %% of the steps) / at the end | %d KiB / %d KiB |\n" % (soak["rss_kib_after_warmup"], soak["rss_kib_end"]))
    s.append("| resident memory min / max after warm-up | %d / %d KiB |\n" % (soak["rss_kib_min"], soak["rss_kib_max"]))
    s.append("| heap allocations inside `step()` after warm-up (counting `operator new`) | %d (%.3g per step) |\n"
             % (soak["allocations_after_warmup"], soak["allocations_per_step"]))
    s.append("| non-finite / unconverged steps | %d / %d |\n" % (soak["nonfinite"], soak["unconverged_steps"]))
    s.append("| max penetration | %.3g m |\n" % soak["max_penetration"])
    if massif:
        s.append("| valgrind massif (shorter soak): heap at peak / half-way / last snapshot | %d / %d / %d B (%d snapshots) |\n"
                 % (massif["heap_B_peak"], massif["heap_B_at_half"], massif["heap_B_last"], massif["massif_snapshots"]))
    mem = os.path.join(out, "soak_memory.csv")
    if os.path.exists(mem):
        rows = list(csv.DictReader(open(mem)))
        fig, ax = plt.subplots(figsize=(7, 3.2))
        ax.plot([int(r["step"]) for r in rows], [int(r["rss_kib"]) for r in rows], "-")
        ax.set(xlabel="step", ylabel="resident memory, KiB", title="soak: resident memory")
        ax.set_ylim(0, 1.2 * max(int(r["rss_kib"]) for r in rows))
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(docs, "soak_memory.png"), dpi=100)
        s.append("\n![soak memory](soak_memory.png)\n")
    return "".join(s)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--docs", required=True)
    ap.add_argument("--elapsed", type=int, default=0)
    a = ap.parse_args()
    repo = os.path.dirname(os.path.abspath(a.docs))
    wp = open(os.path.join(a.out, "work_precision.md")).read() if os.path.exists(os.path.join(a.out, "work_precision.md")) else "_(missing)_\n"
    sweep = jline(os.path.join(a.out, "sweep.json")) or {}
    tmpl = open(os.path.join(repo, "scripts", "templates", "performance_template.md")).read()
    text = (tmpl.replace("@MACHINE@", "%s, %d cores, %s" % (cpu(), os.cpu_count(), platform.platform()))
            .replace("@DATE@", datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"))
            .replace("@COMMIT@", git_rev(repo))
            .replace("@LOAD@", load_section(a.out))
            .replace("@C60_SOLVER@", c60_solver_section(a.out))
            .replace("@C60_DT@", c60_dt_section(a.out))
            .replace("@C60_SPEED@", c60_speed_section(a.out))
            .replace("@STRESS_SEEDS@", stress_seeds_section(a.out))
            .replace("@SKIPS@", skips_section(a.out))
            .replace("@ELAPSED@", elapsed_section(a.out, a.elapsed))
            .replace("@WORK_PRECISION@", wp)
            .replace("@STRESS@", stress_section(a.out, a.docs))
            .replace("@SOAK@", soak_section(a.out, a.docs))
            .replace("@SWEEP@", "| | value |\n|---|---|\n" + "".join(
                "| %s | %s |\n" % (k, v) for k, v in sweep.items())))
    open(os.path.join(a.docs, "performance.md"), "w").write(text)


if __name__ == "__main__":
    main()
