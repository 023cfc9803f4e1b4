"""A campaign's outputs from its run records (docs/campaigns.md, "Outputs").

`write_all(DIR, name, records, keep_logs)` writes DIR/summary.json, DIR/runs.parquet,
DIR/report.md with its plots in DIR/plots/, and DIR/report.html (self-contained: the same
text with the plots inline as SVG). The records are the DIR/runs/<id>/result.json
documents in the campaign's order; everything here follows from them, so an interrupted
campaign's reports can be rebuilt from its finished runs (`--resume`).
"""

import collections
import html
import io
import json
import math
import re

import numpy as np

# Measured, not results: they differ between two runs of the same campaign. The run's
# `wall_time_s`; the analyzer's `sample_time_ms` (the controller's computation time per
# sample) and the log files' sizes `files[].bytes` (the logs hold those times as text, and
# the worker's paths). Left out of the plots; tests compare everything else.
MEASURED_FIELDS = ("wall_time_s", "sample_time_ms", "bytes")
# Top-level entries of metrics.json that describe the run rather than measure it (not plotted).
DESCRIPTIVE = ("architecture", "scheme", "config", "start_s", "end_s", "plant_steps", "control_samples", "thresholds", "files")
MAX_PLOTS = 16
TOP_REASONS = 10


def flatten(value, prefix=""):
    """{dotted.name[index]: scalar} of every number, boolean and string in a JSON value."""
    out = {}
    if isinstance(value, dict):
        for k, v in value.items():
            out.update(flatten(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out.update(flatten(v, f"{prefix}[{i}]"))
    elif value is not None:
        out[prefix] = value
    return out


def summary(name, records):
    """The summary.json document: totals and one entry per run in campaign order."""
    keys = ("id", "scenario", "configuration", "parameters", "passed", "reasons", "metrics", "stop_time_s", "wall_time_s")
    return {"name": name, "total": len(records), "passed": sum(r["passed"] for r in records),
            "runs": [{k: r.get(k) for k in keys} for r in records]}


def parquet_columns(records):
    """Columns of runs.parquet: the run's identity and verdict, its parameters, then every
    scalar metric flattened (union over the runs; None where a run lacks one)."""
    rows = []
    for r in records:
        row = {"id": r["id"], "scenario": r["scenario"], "configuration": r["configuration"], "passed": r["passed"],
               "reasons": len(r["reasons"]), "first_reason": r["reasons"][0]["message"] if r["reasons"] else None,
               "stop_time_s": r.get("stop_time_s"), "wall_time_s": r.get("wall_time_s")}
        row.update({f"parameters.{k}": v for k, v in r["parameters"].items()})
        row.update({f"metrics.{k}": v for k, v in flatten(r.get("metrics") or {}).items()})
        rows.append(row)
    names = list(dict.fromkeys(k for row in rows for k in row))
    return {n: [row.get(n) for row in rows] for n in names}


def write_parquet(path, records):
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrays = {}
    for name, values in parquet_columns(records).items():
        kinds = {type(v) for v in values if v is not None}
        if kinds <= {int, float} and float in kinds:
            values = [None if v is None else float(v) for v in values]
        elif len(kinds) > 1:
            values = [None if v is None else json.dumps(v) for v in values]
        arrays[name] = pa.array(values)
    pq.write_table(pa.table(arrays), path)


def key_metrics(records):
    """Names of the metrics plotted: numeric scalars at the top level of metrics.json or
    one level down (no per-target or per-vessel lists), neither measured (MEASURED_FIELDS)
    nor describing the run (DESCRIPTIVE), and not the same in every run."""
    values = collections.defaultdict(list)
    skip = set(MEASURED_FIELDS) | set(DESCRIPTIVE)
    for r in records:
        for k, v in (r.get("metrics") or {}).items():
            items = v.items() if isinstance(v, dict) else [(None, v)]
            for sub, x in items:
                if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and k not in skip:
                    values[k if sub is None else f"{k}.{sub}"].append(float(x))
    return [k for k, v in values.items() if len(set(v)) > 1][:MAX_PLOTS], values


def reason_counts(records):
    """[(metric, runs failing on it, reasons)] most common first, then by name."""
    runs, reasons = collections.Counter(), collections.Counter()
    for r in records:
        for m in {x.get("metric") or "?" for x in r["reasons"]}:
            runs[m] += 1
        for x in r["reasons"]:
            reasons[x.get("metric") or "?"] += 1
    return sorted(((m, runs[m], reasons[m]) for m in runs), key=lambda t: (-t[1], t[0]))


def message_counts(records):
    """[(message pattern, reasons)] most common first: messages with their numbers as `#`,
    so one rule broken at different times and by different amounts counts as one."""
    counts = collections.Counter(re.sub(r"-?\d+(\.\d+)?(e-?\d+)?", "#", _one_line(x.get("message", "")))
                                 for r in records for x in r["reasons"])
    return sorted(counts.items(), key=lambda t: (-t[1], t[0]))


def plot_distributions(records):
    """{metric: (png bytes, svg text)}: a histogram per key metric, one series per configuration."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names, _ = key_metrics(records)
    configs = list(dict.fromkeys(r["configuration"] for r in records))
    out = {}
    for name in names:
        fig, ax = plt.subplots(figsize=(5.0, 3.0), dpi=100)
        series = []
        for cfg in configs:
            xs = [_metric(r, name) for r in records if r["configuration"] == cfg]
            series.append([x for x in xs if x is not None])
        everything = [x for s in series for x in s]
        bins = np.histogram_bin_edges(everything, bins=min(20, max(len(set(everything)), 1)))
        ax.hist(series, bins=bins, label=configs, alpha=0.8)
        ax.set_xlabel(name)
        ax.set_ylabel("runs")
        ax.legend(fontsize=7)
        fig.tight_layout()
        png, svg = io.BytesIO(), io.StringIO()
        fig.savefig(png, format="png", metadata={"Software": None})
        fig.savefig(svg, format="svg", metadata={"Date": None})
        plt.close(fig)
        out[name] = (png.getvalue(), svg.getvalue())
    return out


def _metric(record, name):
    head, _, sub = name.partition(".")
    v = (record.get("metrics") or {}).get(head)
    v = v.get(sub) if sub and isinstance(v, dict) else v
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def matrix(records, keep_logs):
    """(configurations, [(scenario, [cell text per configuration])]) of the pass/fail matrix."""
    configs = list(dict.fromkeys(r["configuration"] for r in records))
    cells = collections.defaultdict(dict)
    for r in records:
        text = "pass" if r["passed"] else "FAIL"
        cells[r["scenario"]][r["configuration"]] = f"[{text}](runs/{r['id']}/report.html)" if keep_logs and r.get("metrics") else text
    return configs, [(s, [cells[s].get(c, "-") for c in configs]) for s in cells]


def markdown(name, records, plots, keep_logs):
    """report.md; plots referenced as plots/<n>.png."""
    passed = sum(r["passed"] for r in records)
    lines = [f"# Campaign {name}", "", f"{passed} of {len(records)} runs passed.", "", "## Pass/fail matrix", ""]
    configs, rows = matrix(records, keep_logs)
    lines += ["| scenario | " + " | ".join(configs) + " |", "|---|" + "---|" * len(configs)]
    lines += [f"| {s} | " + " | ".join(cells) + " |" for s, cells in rows]
    lines += ["", "## Failure reasons", "", "| metric or rule | failed runs | reasons |", "|---|---|---|"]
    lines += [f"| {m} | {n} | {k} |" for m, n, k in reason_counts(records)]
    lines += ["", f"The most common messages (numbers as #, at most {TOP_REASONS}):", "", "| message | reasons |", "|---|---|"]
    lines += [f"| {_cell(m)} | {k} |" for m, k in message_counts(records)[:TOP_REASONS]]
    lines += ["", "### Every failed run", ""]
    for r in records:
        if not r["passed"]:
            lines.append(f"- {r['scenario']}, {r['configuration']} (`{r['id'][:12]}`):")
            for x in r["reasons"]:
                where = (f", target {x['target']}" if x.get("target") is not None else "") + \
                    (f", t = {x['t_s']:.1f} s" if isinstance(x.get("t_s"), (int, float)) else "")
                lines.append(f"  - {x.get('metric')}{where}: {_one_line(x.get('message', ''))}")
    lines += ["", "## Distributions of the key metrics", ""]
    lines += [f"![{m}](plots/{i:02d}.png)" for i, m in enumerate(plots)] or ["No metric varies across the runs."]
    return "\n".join(lines) + "\n"


def _one_line(text):
    return " ".join(str(text).split())


def _cell(text):
    """Text for a Markdown table cell (no pipe, one line, at most 200 characters)."""
    text = _one_line(text).replace("|", "/")
    return text if len(text) <= 200 else text[:199] + "..."


def html_page(md_text, plots):
    """report.html: the Markdown's tables and lists as HTML, the plots inline as SVG."""
    svgs = [svg[svg.index("<svg"):] for _, svg in plots.values()]
    body, table = [], []
    for line in md_text.splitlines():
        if line.startswith("|"):
            table.append(line)
            continue
        if table:
            body.append(_html_table(table))
            table = []
        if line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            body.append(f"<h{level}>{_inline(line.lstrip('#').strip())}</h{level}>")
        elif line.startswith("![") and svgs:
            body.append(f"<figure>{svgs.pop(0)}</figure>")
        elif line.lstrip().startswith("- "):
            body.append(f"<p style='margin:0 0 0 {2 * (len(line) - len(line.lstrip()))}em'>&bull; {_inline(line.strip()[2:])}</p>")
        elif line:
            body.append(f"<p>{_inline(line)}</p>")
    if table:
        body.append(_html_table(table))
    style = "body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #999;padding:2px 6px}" \
            "figure{display:inline-block;margin:4px}"
    return f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>campaign</title><style>{style}</style></head>" \
           f"<body>\n" + "\n".join(body) + "\n</body></html>\n"


def _inline(text):
    """Markdown links [t](u) as <a>, `code` as <code>, the rest escaped."""
    out, rest = [], text
    while "[" in rest and "](" in rest:
        a = rest.index("[")
        b = rest.find("](", a)
        c = rest.find(")", b)
        if b < 0 or c < 0:
            break
        out.append(html.escape(rest[:a]) + f"<a href='{html.escape(rest[b + 2:c])}'>{html.escape(rest[a + 1:b])}</a>")
        rest = rest[c + 1:]
    out.append(html.escape(rest))
    return "".join(out).replace("`", "")


def _html_table(lines):
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in lines if not set(line) <= set("|-: ")]
    head, *body = rows
    cell = lambda c, tag: f"<{tag} style='{'color:#b00' if 'FAIL' in c else ''}'>{_inline(c)}</{tag}>"  # noqa: E731
    return "<table><tr>" + "".join(cell(c, "th") for c in head) + "</tr>" + \
        "".join("<tr>" + "".join(cell(c, "td") for c in r) + "</tr>" for r in body) + "</table>"


def write_all(out, name, records, keep_logs):
    """Every campaign output into `out` (see the module documentation)."""
    (out / "summary.json").write_text(json.dumps(summary(name, records), indent=1) + "\n")
    write_parquet(out / "runs.parquet", records)
    plots = plot_distributions(records)
    (out / "plots").mkdir(exist_ok=True)
    for old in (out / "plots").glob("*.png"):  # an earlier report's
        old.unlink()
    for i, (png, _) in enumerate(plots.values()):
        (out / "plots" / f"{i:02d}.png").write_bytes(png)
    md_text = markdown(name, records, plots, keep_logs)
    (out / "report.md").write_text(md_text)
    (out / "report.html").write_text(html_page(md_text, plots))
