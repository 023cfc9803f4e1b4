#!/usr/bin/env python3
"""Checks that the analyzer's outputs did not change: for each run directory under
BASELINE (default /work/baseline; each with logs/plant.mcap, logs/controller.mcap and the
report files an older analyzer wrote, run from BASELINE with relative log paths), runs
`analyzer report -q` the same way into OUT/<run> and compares

- encounters.csv: byte for byte;
- metrics.json: equal as JSON after removing the wall-time fields (`sample_time_ms`) and
  the top-level keys the baseline lacks (sections added since: `verdict`, `thresholds`,
  new metrics; listed, not compared). A key the baseline has and the new output lacks,
  or any changed value, is a difference.

Usage: tests/tools/compare_baseline.py [--baseline DIR] [--out DIR] [--analyzer BIN]
Exit status 0 when every run matches, 1 otherwise (each difference is printed).
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

# Measured in wall time, not a property of the run.
TIMING_KEYS = {"sample_time_ms"}
# Keys added since the baseline.
NEW_KEYS = {"verdict", "thresholds"}


def strip(metrics):
    return {k: v for k, v in metrics.items() if k not in TIMING_KEYS | NEW_KEYS}


def diff(a, b, path="$"):
    """Paths where two JSON values differ (first few)."""
    if type(a) is not type(b):
        return [f"{path}: {a!r} != {b!r}"]
    if isinstance(a, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'after' if k in b else 'baseline'}")
            else:
                out += diff(a[k], b[k], f"{path}.{k}")
        return out
    if isinstance(a, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} != {len(b)}"]
        out = []
        for i, (x, y) in enumerate(zip(a, b)):
            out += diff(x, y, f"{path}[{i}]")
        return out
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--baseline", type=Path, default=Path("/work/baseline"))
    p.add_argument("--out", type=Path, default=Path("/tmp/after"))
    p.add_argument("--analyzer", type=Path, default=Path("target/release/analyzer"))
    args = p.parse_args()
    runs = sorted(d for d in args.baseline.iterdir() if (d / "logs" / "plant.mcap").is_file())
    if not runs:
        print(f"no runs under {args.baseline}", file=sys.stderr)
        return 1
    failed = 0
    for run in runs:
        out = args.out / run.name
        # From the baseline folder with relative log paths, as the baseline was made:
        # the paths are recorded in metrics.json (`files`, `scenario_source`).
        cmd = [str(args.analyzer.resolve()), "report", "-q", "--out", str(out.resolve()),
               f"{run.name}/logs/plant.mcap", f"{run.name}/logs/controller.mcap"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, cwd=args.baseline)
        problems = []
        if (run / "encounters.csv").read_bytes() != (out / "encounters.csv").read_bytes():
            problems.append("encounters.csv differs")
        before = json.loads((run / "metrics.json").read_text())
        after = json.loads((out / "metrics.json").read_text())
        for k in NEW_KEYS:
            if k not in after:
                problems.append(f"metrics.json lacks the new key {k}")
        added = sorted(set(after) - set(before))
        verdict = after.get("verdict", {})
        after = {k: v for k, v in after.items() if k in before}
        problems += [f"metrics.json {d}" for d in diff(strip(before), strip(after))[:20]]
        status = "identical" if not problems else "DIFFERENT"
        print(f"{run.name}: {status} (verdict passed={verdict.get('passed')}, "
              f"{len(verdict.get('reasons', []))} reasons; new sections: {', '.join(added)})")
        for pr in problems:
            print(f"  {pr}")
        failed += bool(problems)
    print(f"{len(runs) - failed} of {len(runs)} runs unchanged")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
