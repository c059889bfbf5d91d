#!/usr/bin/env python3
"""Which problems each stage of the solver's schedule finishes that the others leave
unsolved (docs/solver.md, "What each stage is for").

  bench/solver_stage_needs.py DUMP_ROOT [--bin DIR] [--skip-also STAGE,...] [--json OUT]

DUMP_ROOT holds one folder per run of problems dumped by bench/solver_stages.sh
--dump (or nscd_run / nscd_stress --dump-problems): folders named c60_* were run with
the C-60 scenes' budget (max_iterations 2000), the others with the default 200. Every
problem is solved again as its run solved it (nscd_solve_problems from its warm start:
the same stage finishes it, bit for bit; a rescue's _longer file with 10 times the
budget), then the problems each stage finished are solved once more without that
stage (--skip-stage; with --skip-also, without those too). Prints per stage: the
problems it finished, how many stay unsolved without it and which stages take the
others, and the solve time with and without it (wall clock of this machine: compare
within one run).
"""
import argparse
import json
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENTRY = ('local_solver', 'warm_start', 'no_rows', 'unsolved', 'failed')  # not stages of the schedule


def solve(binary, files, extra):
    """{path: (converged, iterations, stage, us)}; files of one folder (names repeat across folders)."""
    res = {}
    by_name = {os.path.basename(f): f for f in files}
    for i in range(0, len(files), 1500):
        out = subprocess.run([binary] + extra + files[i:i + 1500], capture_output=True, text=True).stdout
        for line in out.splitlines()[1:]:
            t = line.split()
            if len(t) == 9 and t[0] in by_name:
                res[by_name[t[0]]] = (t[2] == 'yes', int(t[3]), t[7], float(t[8]))
    missing = [f for f in files if f not in res]
    if len(missing) > 1:  # a crash cut a batch short: one by one
        for f in missing:
            res.update(solve(binary, [f], extra))
    elif missing:
        res[missing[0]] = (False, 0, 'crash', 0.0)
    return res


def budget(path):
    n = 2000 if os.path.basename(os.path.dirname(path)).startswith('c60_') else 200
    return ['--max-iter', str(10 * n if '_longer' in path else n)]


def solve_all(binary, files, extra):
    groups = {}
    for f in files:
        groups.setdefault((os.path.dirname(f), budget(f)[1]), []).append(f)
    res = {}
    with ThreadPoolExecutor(2) as ex:
        jobs = [ex.submit(solve, binary, fs[i:i + 3000], ['--max-iter', b] + extra)
                for (d, b), fs in groups.items() for i in range(0, len(fs), 3000)]
        for j in jobs:
            res.update(j.result())
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('root')
    ap.add_argument('--bin', default=os.path.join(os.environ.get('NSCD_WS', os.path.join(REPO, '.build', 'ws')),
                                                   'devel', 'lib', 'nscd_sim'))
    ap.add_argument('--skip-also', default='')
    ap.add_argument('--json')
    a = ap.parse_args()
    binary = os.path.join(a.bin, 'nscd_solve_problems')
    also = [s for s in a.skip_also.split(',') if s]
    files = [os.path.join(a.root, d, f) for d in sorted(os.listdir(a.root))
             for f in sorted(os.listdir(os.path.join(a.root, d)))]
    base = solve_all(binary, files, [])
    by_stage = {}
    for f, r in base.items():
        by_stage.setdefault(r[2], []).append(f)
    report = {}
    print('| stage | finished | unsolved without it | taken by, without it | time with / without (s) |')
    print('|---|---:|---:|---|---|')
    for stage, fs in sorted(by_stage.items(), key=lambda kv: -len(kv[1])):
        entry = {'finished': len(fs), 'us': sum(base[f][3] for f in fs)}
        if stage not in ENTRY:
            skip = [x for s in [stage] + also for x in ('--skip-stage', s)]
            r = solve_all(binary, fs, skip)
            taken = {}
            for f in fs:
                taken[r[f][2]] = taken.get(r[f][2], 0) + 1
            entry.update(unsolved=sum(1 for f in fs if not r[f][0]), us_without=sum(r[f][3] for f in fs),
                         taken_by=taken, unsolved_examples=[f for f in fs if not r[f][0]][:5])
            by = ', '.join(f'{k} {v}' for k, v in sorted(taken.items(), key=lambda kv: -kv[1]))
            print(f"| `{stage}` | {len(fs)} | {entry['unsolved']} | {by} | "
                  f"{entry['us'] / 1e6:.2f} / {entry['us_without'] / 1e6:.2f} |", flush=True)
        else:
            print(f'| `{stage}` | {len(fs)} | | | {entry["us"] / 1e6:.2f} |', flush=True)
        report[stage] = entry
    if a.json:
        json.dump(report, open(a.json, 'w'), indent=1)


if __name__ == '__main__':
    main()
