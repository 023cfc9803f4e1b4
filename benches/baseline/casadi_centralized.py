"""The side-by-side baseline's IPOPT half (docs/benchmarks.md, `cargo xtask bench-baseline`):
solves the centralized MPC's recorded problems with CasADi + IPOPT and compares with ours.

    python benches/baseline/casadi_centralized.py solve DIR/recorded.json --out DIR/ipopt.json
        [--ours DIR/ours.json] [--repeats N] [--limit N] [--cold-multipliers] [--ipopt KEY=VALUE ...]
    python benches/baseline/casadi_centralized.py report DIR

`solve` builds the NLP of centralized_nlp.py once per number of obstacles (SX, single
shooting through the RK4 substeps, `expand=True`, IPOPT with the exact Hessian of the
Lagrangian; building is not timed) and solves the recorded samples in order, each from the
previous solution shifted by one sample (the last sample repeated; the first sample from the
previous command repeated, as ours starts), the slacks set to make that start feasible, and
IPOPT's own warm start (`warm_start_init_point`) from the previous multipliers shifted the
same way (unless --cold-multipliers, or the number of obstacles changed). Only the solver
call is timed (time.perf_counter around it). It writes per sample the times, IPOPT's
iterations and status, the plan, and the merit of the plan (centralized_nlp.merit_function);
with --ours also the merit of our plans by the same Python code, for the cross-check against
Rust's `Centralized::evaluate`.

`report` reads DIR/ours.json, DIR/ipopt.json and DIR/evaluated.json (IPOPT's plans evaluated
by Rust, `record_centralized evaluate`) and prints the table (also DIR/summary.json).

IPOPT's options (module constant IPOPT_OPTIONS; --ipopt overrides): tol = 1e-8 (IPOPT's
default: the scaled NLP error of the KKT conditions), acceptable_tol = 1e-6 (default),
max_iter = 500, mu_init = 1e-4 with the warm start (a barrier parameter near the previous
solution's instead of 0.1: the iterate starts close to optimal), the bound pushes of the
warm start at 1e-6, the exact Hessian (hessian_approximation = exact, the default), MUMPS
(the wheel's linear solver), no output.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import statistics
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import casadi as ca  # noqa: E402

import centralized_nlp as cn  # noqa: E402

IPOPT_OPTIONS = {
    "tol": 1e-8,
    "acceptable_tol": 1e-6,
    "max_iter": 500,
    "hessian_approximation": "exact",
    "linear_solver": "mumps",
    "print_level": 0,
    "sb": "yes",
}
WARM_OPTIONS = {
    "warm_start_init_point": "yes",
    "mu_init": 1e-4,
    "warm_start_bound_push": 1e-6,
    "warm_start_slack_bound_push": 1e-6,
    "warm_start_mult_bound_push": 1e-6,
}


def read(path) -> dict:
    with open(path) as f:
        return json.load(f)


def write(path, value) -> None:
    with open(path, "w") as f:
        json.dump(value, f)


def parse_overrides(items: list[str]) -> dict:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise SystemExit(f"--ipopt {item}: expected KEY=VALUE")
        try:
            out[key] = int(value)
        except ValueError:
            try:
                out[key] = float(value)
            except ValueError:
                out[key] = value
    return out


def shift_blocks(values: list[float], first: int, count: int, size: int) -> list[float]:
    """values[first:first + count * size] as `count` blocks of `size`, block j replaced by
    block min(j + 1, count - 1) (the warm start's shift of anything indexed by sample)."""
    out = list(values)
    for j in range(count):
        src = first + min(j + 1, count - 1) * size
        out[first + j * size:first + (j + 1) * size] = values[src:src + size]
    return out


def shift_multipliers(nlp: cn.Nlp, lam_x: list[float], lam_g: list[float]) -> tuple[list, list]:
    """The previous multipliers moved one sample ahead, as the primal plan is: variables
    [u (10 per sample), t (6 per sample), s (3 n per sample)], rows [rate (4 per sample
    1..H-1), consensus (12 per sample), clearance (3 n per sample)]."""
    H, n = nlp.problem["horizon"], nlp.n_obs
    lam_x = shift_blocks(lam_x, 0, H, cn.PER_STEP)
    lam_x = shift_blocks(lam_x, nlp.n_u, H, nlp.n_cons // H)
    if n:
        lam_x = shift_blocks(lam_x, nlp.n_u + nlp.n_cons, H, nlp.n_gaps // H)
    lam_g = shift_blocks(lam_g, 0, H - 1, 4)
    lam_g = shift_blocks(lam_g, nlp.n_rate, H, 2 * nlp.n_cons // H)
    if n:
        lam_g = shift_blocks(lam_g, nlp.n_rate + 2 * nlp.n_cons, H, nlp.n_gaps // H)
    return lam_x, lam_g


def check_problem(recorded: dict) -> None:
    """Refuses what the NLP does not model: more obstacles than clearance slots."""
    p = recorded["problem"]
    slots = min(p["ship"]["clearance"]["max_obstacles"], p["tug"]["clearance"]["max_obstacles"])
    for k, s in enumerate(recorded["samples"]):
        if len(s["obstacles"]) > slots:
            raise SystemExit(f"samples[{k}] holds {len(s['obstacles'])} obstacles, more than the "
                             f"{slots} clearance slots the problem has")


class Sequence:
    """Solves the recorded samples in order with warm starts (module docs)."""

    def __init__(self, problem: dict, options: dict, warm_multipliers: bool):
        self.problem, self.options, self.warm_multipliers = problem, options, warm_multipliers
        self.nlps: dict[int, cn.Nlp] = {}
        self.merits: dict[int, ca.Function] = {}
        self.build_s: dict[int, float] = {}

    def nlp(self, n_obs: int) -> cn.Nlp:
        if n_obs not in self.nlps:
            start = time.perf_counter()
            self.nlps[n_obs] = cn.Nlp(self.problem, n_obs, self.options)
            self.merits[n_obs] = cn.merit_function(self.problem, n_obs)
            self.build_s[n_obs] = time.perf_counter() - start
        return self.nlps[n_obs]

    def run(self, samples: list[dict]) -> list[dict]:
        H = self.problem["horizon"]
        out, last = [], None  # last: (n_obs, x, lam_x, lam_g)
        for sample in samples:
            n = len(sample["obstacles"])
            nlp = self.nlp(n)
            p = cn.parameters(sample)
            lbx, ubx = nlp.bounds(sample["previous"]["ship"])
            u0 = cn.shifted(last[1][:nlp.n_u], H) if last else cn.cold_start(sample, H)
            args = {"x0": u0 + nlp.initial_slacks(u0, p), "p": p, "lbx": lbx, "ubx": ubx,
                    "lbg": nlp.lbg, "ubg": nlp.ubg}
            if self.warm_multipliers and last and last[0] == n:
                args["lam_x0"], args["lam_g0"] = shift_multipliers(nlp, last[2], last[3])
            start = time.perf_counter()
            sol = nlp.solver(**args)
            spent = time.perf_counter() - start
            stats = nlp.solver.stats()
            x = [float(v) for v in ca.vertsplit(sol["x"])]
            finite = all(math.isfinite(v) for v in x)
            last = (n, x, [float(v) for v in ca.vertsplit(sol["lam_x"])],
                    [float(v) for v in ca.vertsplit(sol["lam_g"])]) if finite else None
            merit = float(self.merits[n](x[:nlp.n_u], p)[0]) if finite else None
            out.append({"time": sample["time"], "time_s": spent, "iterations": stats["iter_count"],
                        "status": stats["return_status"], "success": bool(stats["success"]),
                        "merit_python": merit, "plan": cn.plan_dict(x[:nlp.n_u], H) if finite else None,
                        "violation": violation(nlp, x[:nlp.n_u], lbx, ubx) if finite else None})
        return out

    def merit_of(self, sample: dict, plan: dict) -> float:
        n = len(sample["obstacles"])
        self.nlp(n)
        return float(self.merits[n](cn.plan_vector(plan), cn.parameters(sample))[0])


def violation(nlp: cn.Nlp, u: list[float], lbx: list[float], ubx: list[float]) -> float:
    """Largest violation of a bound or rate bound by the plan `u`."""
    worst = max(max(lbx[k] - u[k], u[k] - ubx[k], 0.0) for k in range(nlp.n_u))
    H = nlp.problem["horizon"]
    for k, h in enumerate(range(1, H)):
        for c in range(4):
            d = u[cn.PER_STEP * h + c] - u[cn.PER_STEP * (h - 1) + c]
            worst = max(worst, d - nlp.ubg[4 * k + c], nlp.lbg[4 * k + c] - d)
    return worst


def solve(args) -> None:
    recorded = read(args.recorded)
    check_problem(recorded)
    samples = recorded["samples"][:args.limit] if args.limit else recorded["samples"]
    options = dict(IPOPT_OPTIONS)
    if not args.cold_multipliers:
        options.update(WARM_OPTIONS)
    options.update(parse_overrides(args.ipopt))
    seq = Sequence(recorded["problem"], options, not args.cold_multipliers)
    runs = []
    for repeat in range(args.repeats):
        print(f"casadi_centralized: IPOPT on {len(samples)} samples (repeat {repeat + 1} of {args.repeats})",
              file=sys.stderr)
        runs.append(seq.run(samples))
    result = runs[0]
    for k, r in enumerate(result):
        r["times_s"] = [run[k]["time_s"] for run in runs]
        del r["time_s"]
    if args.ours:
        ours = read(args.ours)["samples"]
        for r, sample, o in zip(result, samples, ours):
            r["ours_merit_python"] = seq.merit_of(sample, o["plan"])
    write(args.out, {"ipopt_options": options, "warm_multipliers": not args.cold_multipliers,
                     "casadi": ca.__version__, "build_s": seq.build_s, "samples": result})
    print(f"casadi_centralized: wrote {args.out}", file=sys.stderr)


# ---- report ---------------------------------------------------------------------------------


def quantile(values: list[float], q: float) -> float:
    """The q-quantile of `values` by the nearest-rank method (index floor(q n), as the
    Rust closed-loop example and the analyzer quote p99)."""
    s = sorted(values)
    return s[min(int(q * len(s)), len(s) - 1)]


def relative(a: float, b: float) -> float:
    return (a - b) / max(abs(b), 1.0)


def stats(values: list[float]) -> dict:
    return {"median": statistics.median(values), "p90": quantile(values, 0.9), "p99": quantile(values, 0.99),
            "max": max(values)}


def summary(directory: pathlib.Path) -> dict:
    """The comparison of ours.json, ipopt.json and evaluated.json (module docs)."""
    ours = read(directory / "ours.json")["samples"]
    ipopt = read(directory / "ipopt.json")
    evaluated = read(directory / "evaluated.json")["samples"]
    n = len(ipopt["samples"])
    ours = ours[:n]
    t_ours = [statistics.median(o["times_s"]) * 1e3 for o in ours]
    t_ipopt = [statistics.median(r["times_s"]) * 1e3 for r in ipopt["samples"]]
    solved = [k for k, r in enumerate(ipopt["samples"]) if r["plan"] is not None]
    if not solved:
        raise SystemExit(f"{directory / 'ipopt.json'}: IPOPT gave no finite plan for any sample")
    diffs = [relative(ours[k]["merit"], evaluated[k]["merit"]) for k in solved]
    check = [abs(relative(ipopt["samples"][k]["merit_python"], evaluated[k]["merit"])) for k in solved]
    check += [abs(relative(r["ours_merit_python"], o["merit"])) for r, o in zip(ipopt["samples"], ours)
              if "ours_merit_python" in r]
    return {
        "samples": n,
        "window": [ours[0]["time"], ours[-1]["time"]] if ours else None,
        "ours_ms": stats(t_ours),
        "ipopt_ms": stats(t_ipopt),
        "ratio_of_medians": statistics.median(t_ipopt) / statistics.median(t_ours),
        "ours_iterations": stats([o["iterations"] for o in ours]),
        "ours_not_converged": sum(not o["converged"] for o in ours),
        "ipopt_iterations": stats([r["iterations"] for r in ipopt["samples"]]),
        "ipopt_not_solved": [(r["time"], r["status"]) for r in ipopt["samples"] if not r["success"]],
        "ipopt_max_bound_violation": max((r["violation"] for r in ipopt["samples"] if r["violation"] is not None),
                                         default=None),
        "merit_relative_difference": {
            "definition": "(ours - IPOPT) / max(|IPOPT|, 1), both merits by Centralized::evaluate",
            "median": statistics.median(diffs), "min": min(diffs), "max": max(diffs),
            "p99_abs": quantile([abs(d) for d in diffs], 0.99),
            "ours_lower_by_1e-6": sum(d < -1e-6 for d in diffs),
            "ipopt_lower_by_1e-6": sum(d > 1e-6 for d in diffs),
            "within_1e-6": sum(abs(d) <= 1e-6 for d in diffs),
        },
        "python_vs_rust_merit_max_relative": max(check) if check else None,
        "ipopt_options": ipopt["ipopt_options"],
        "warm_multipliers": ipopt["warm_multipliers"],
        "casadi": ipopt["casadi"],
    }


def table(s: dict) -> str:
    def ms(d: dict) -> str:
        return f"{d['median']:9.3f} {d['p90']:9.3f} {d['p99']:9.3f} {d['max']:9.3f}"

    m = s["merit_relative_difference"]
    violation = s["ipopt_max_bound_violation"]
    lines = [
        f"centralized MPC, {s['samples']} samples (t = {s['window'][0]:.0f}-{s['window'][1]:.0f} s), "
        f"per-sample solve time in ms",
        f"{'':28} {'median':>9} {'p90':>9} {'p99':>9} {'max':>9}",
        f"{'ours (SCP on Clarabel)':28} {ms(s['ours_ms'])}",
        f"{'IPOPT (CasADi ' + s['casadi'] + ')':28} {ms(s['ipopt_ms'])}",
        f"ratio of medians IPOPT / ours: {s['ratio_of_medians']:.1f}x (IPOPT: exact Hessian, tol "
        f"{s['ipopt_options']['tol']:g}, warm start of the plan{' and the multipliers' if s['warm_multipliers'] else ''})",
        f"iterations: ours SCP median {s['ours_iterations']['median']:g} p99 {s['ours_iterations']['p99']:g} "
        f"(not converged {s['ours_not_converged']}); IPOPT median {s['ipopt_iterations']['median']:g} "
        f"p99 {s['ipopt_iterations']['p99']:g} (not solved {len(s['ipopt_not_solved'])})",
        f"merit agreement, (ours - IPOPT) / max(|IPOPT|, 1), both by Centralized::evaluate: median "
        f"{m['median']:.2e}, min {m['min']:.2e}, max {m['max']:.2e}; within 1e-6: {m['within_1e-6']}, "
        f"ours lower: {m['ours_lower_by_1e-6']}, IPOPT lower: {m['ipopt_lower_by_1e-6']}",
        f"same problem: Python merit vs Rust evaluate on the same plans, max relative difference "
        f"{s['python_vs_rust_merit_max_relative']:.1e}; IPOPT's largest bound violation "
        f"{'-' if violation is None else format(violation, '.1e')}",
    ]
    return "\n".join(lines)


def report(args) -> None:
    directory = pathlib.Path(args.dir)
    s = summary(directory)
    write(directory / "summary.json", s)
    print(table(s))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("solve", help="solve the recorded samples with IPOPT")
    p.add_argument("recorded")
    p.add_argument("--out", required=True)
    p.add_argument("--ours", help="ours.json: evaluate our plans with the Python merit too")
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--limit", type=int, default=0, help="only the first N samples")
    p.add_argument("--cold-multipliers", action="store_true",
                   help="no IPOPT warm start of the multipliers (primal warm start only)")
    p.add_argument("--ipopt", action="append", default=[], metavar="KEY=VALUE", help="an IPOPT option")
    r = sub.add_parser("report", help="print the comparison table of a benchmark directory")
    r.add_argument("dir")
    args = parser.parse_args()
    if args.command == "solve":
        if args.repeats < 1:
            raise SystemExit("--repeats must be >= 1")
        solve(args)
    else:
        report(args)


if __name__ == "__main__":
    main()
