"""The side-by-side baseline (benches/baseline, docs/benchmarks.md) solves the same problem as
ours, on a handful of recorded states (t = 398-405 s of the paper scenario, centralized,
scheme I: target B's crossing given way to while the tow slows, the heading floor on, four
obstacles; until 2026-12-06 t = 360-367 s, before the tow detects B, where the floor is no
longer set since only a held situation sets it; until 2026-12-04 t = 184-191 s, where the tow now lies stopped for target A with the tugs at
rest, so a tug's velocity weight multiplies nothing and the cross check below cannot see it):

- the Python model of the problem (benches/baseline/centralized_nlp.py) gives the merit that
  Rust's `Centralized::evaluate` gives, on our plans and on IPOPT's, within 1e-9 relative
  (measured over the whole 1200 s run: 1.7e-13);
- IPOPT solves every sample, and the two optima, evaluated by the same Rust code, agree:
  |ours - IPOPT| / max(|IPOPT|, 1) <= 1e-4. Why 1e-4: ours stops when the first move changes
  by less than 1e-4 (N, rad, N m) or the model predicts a decrease below 1e-6 of the cost,
  and IPOPT's tol = 1e-8 applies to its scaled problem (the objective scaled by 1e-2
  because of the 1e4 clearance penalty), which leaves about 1e-5 of the merit (measured:
  3.9e-5 at t = 968 s, 9e-7 with tol = 1e-10 unscaled); two local solvers on the same
  problem from the same warm start land within 1e-4 of each other, while a different
  problem (a term, weight or bound off) moves the merit by far more. Measured here: at most
  9.2e-7 (2026-12-04; 4e-7 on the earlier window). The strict known-defect mark this test
  carried (our SCP up to 0.29 % above IPOPT at t = 186 s, with the ship's motion-limit rows)
  is gone: on the paper run of 2026-12-04 the two agree on both windows (184-191 s: at most
  1.9e-6); those states no longer occur, so the defect is not shown fixed, only not seen.

No skipping: casadi is in masters/requirements.txt, which `cargo xtask test` installs.
"""

import json
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benches" / "baseline"))

import casadi_centralized as cc  # noqa: E402
import centralized_nlp as cn  # noqa: E402

WINDOW = ("398", "8")  # --from, --samples
SAME_FUNCTION = 1e-9
SAME_OPTIMUM = 1e-4


def target_dir():
    t = os.environ.get("CARGO_TARGET_DIR")
    return pathlib.Path(t) if t else ROOT / "target"


@pytest.fixture(scope="module")
def recorder(fmus):
    """Built by the fixture's `cargo xtask fmu` (the one workspace build every command uses)."""
    return target_dir() / "release" / "examples" / "record_centralized"


@pytest.fixture(scope="module")
def bench(recorder, tmp_path_factory):
    """Records the window, replays ours, solves it with IPOPT and evaluates IPOPT's plans."""
    d = tmp_path_factory.mktemp("baseline")
    subprocess.run([str(recorder), "record", "--from", WINDOW[0], "--samples", WINDOW[1], "--out", str(d)],
                   cwd=ROOT, check=True)
    recorded = cc.read(d / "recorded.json")
    options = dict(cc.IPOPT_OPTIONS)
    options.update(cc.WARM_OPTIONS)
    seq = cc.Sequence(recorded["problem"], options, warm_multipliers=True)
    ipopt = seq.run(recorded["samples"])
    cc.write(d / "ipopt.json", {"samples": ipopt})
    subprocess.run([str(recorder), "evaluate", str(d / "recorded.json"), str(d / "ipopt.json"), "--out",
                    str(d / "evaluated.json")], cwd=ROOT, check=True)
    return {
        "recorded": recorded,
        "ours": cc.read(d / "ours.json")["samples"],
        "ipopt": ipopt,
        "evaluated": cc.read(d / "evaluated.json")["samples"],
        "seq": seq,
    }


def test_the_window_is_a_real_encounter(bench):
    samples = bench["recorded"]["samples"]
    assert len(samples) == int(WINDOW[1])
    assert all(s["heading_floor"] is not None for s in samples)
    assert all(len(s["obstacles"]) == 4 for s in samples)
    # (That the recorded inputs are exact, the replay reproducing the loop's commands bit for
    # bit from 0 s, is crates/towing-control/tests/mpc_input.rs; here the replay starts cold
    # at 184 s, as IPOPT does, while the loop was warm.)


def test_the_python_problem_is_the_rust_problem(bench):
    for sample, o, r, e in zip(bench["recorded"]["samples"], bench["ours"], bench["ipopt"], bench["evaluated"]):
        ours_python = bench["seq"].merit_of(sample, o["plan"])
        assert abs(cc.relative(ours_python, o["merit"])) <= SAME_FUNCTION, (sample["time"], ours_python, o["merit"])
        assert abs(cc.relative(r["merit_python"], e["merit"])) <= SAME_FUNCTION, (sample["time"], r["merit_python"],
                                                                                   e["merit"])


def optimum_gaps(bench):
    """(time, relative merit gap ours - IPOPT) per sample, after checking IPOPT solved it."""
    gaps = []
    for o, r, e in zip(bench["ours"], bench["ipopt"], bench["evaluated"]):
        assert r["success"], (o["time"], r["status"])
        assert r["violation"] <= 1e-6, (o["time"], r["violation"])
        gaps.append((o["time"], cc.relative(o["merit"], e["merit"])))
    return gaps


# A gap seen on 2026-12-06 in this window (t = 404 s: our SCP stopped after 18 iterations,
# converged by its own test, 6.3e-4 of the merit above IPOPT) was marked as a known defect,
# strictly. Since 2026-12-08 (the holding tension while the way is off,
# docs/controller-design.md, "Standing on") the window's recorded states have changed, and
# every sample agrees within 2.5e-5: the strict mark failed and is gone.
# The gap was never explained (a stopping test met early, or another local optimum), so it
# may return on other states.
def test_ipopt_and_ours_reach_the_same_optimum(bench):
    for t, d in optimum_gaps(bench):
        assert abs(d) <= SAME_OPTIMUM, f"t = {t:.0f} s: {d:.2e}"


def test_the_cross_check_sees_a_changed_problem(bench):
    """The check above can fail: with one parameter of the problem off by 1 % (a weight of the
    tugs or of the ship, a damping derivative), the Python merit of our plans leaves
    Rust's by far more than SAME_FUNCTION."""
    # A sample under way (at the first one the tugs are still at rest, so their velocity
    # weight multiplies almost nothing).
    k = len(bench["ours"]) // 2
    sample, o = bench["recorded"]["samples"][k], bench["ours"][k]
    for path in (("tug", "velocity_weights", 0), ("ship", "terminal", "weight"), ("ship_hull", "damping", "y_v")):
        problem = json.loads(json.dumps(bench["recorded"]["problem"]))
        *parents, leaf = path
        node = problem
        for key in parents:
            node = node[key]
        node[leaf] *= 1.01
        merit = float(cn.merit_function(problem, len(sample["obstacles"]))(cn.plan_vector(o["plan"]),
                                                                            cn.parameters(sample))[0])
        assert abs(cc.relative(merit, o["merit"])) > 1e3 * SAME_FUNCTION, (path, merit, o["merit"])
