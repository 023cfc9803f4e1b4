//! `analyzer compare`: several report directories side by side, in the layout of the
//! paper's Tables 6 and 7, with the published figures and the differences.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::doc::{to_html, to_markdown, Block};
use crate::error::{AnalyzerError, Result};
use crate::metric::distances::ObstacleDistance;
use crate::metric::run_info::{architecture_name, scheme_name};
use crate::metric::Metrics;
use crate::paper::{self, SCENARIO_CAPTIONS, SCENARIO_TARGETS};
use crate::rows::VESSELS;

/// The parts of one run's `metrics.json` the tables use.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    /// The report directory (or a label).
    pub run: String,
    /// Architecture code.
    pub architecture: Option<i32>,
    /// Scheme code.
    pub scheme: Option<i32>,
    /// Target name of scenario 1, 2, 3.
    pub targets: [Option<String>; 3],
    /// `D` of ship, tug 1, tug 2 per scenario.
    pub d: [[Option<f64>; 3]; 3],
    /// COLREGS compliance per scenario (`None`: no encounter assessed).
    pub colregs: [Option<bool>; 3],
    /// Settling time, s.
    pub settling_time_s: Option<f64>,
    /// Maximum elongation errors, fractions.
    pub elongation: [Option<f64>; 2],
    /// Ship travel, m.
    pub ship_travel_m: Option<f64>,
    /// The log was truncated.
    pub truncated: bool,
}

impl RunSummary {
    /// Reads the summary from a run's typed metrics. Scenario `k` is the target ship
    /// named as the paper's (A, B, C) if present, else the `k`-th target ship by slot.
    #[must_use]
    pub fn from_metrics(run: &str, m: &Metrics) -> RunSummary {
        let mut ships: Vec<&ObstacleDistance> = m
            .distances
            .normalized_min_distance
            .iter()
            .filter(|o| o.kind == "ship")
            .collect();
        ships.sort_by_key(|o| o.slot);
        let by_paper_names: Vec<Option<&ObstacleDistance>> = SCENARIO_TARGETS
            .iter()
            .map(|n| ships.iter().copied().find(|o| o.obstacle == *n))
            .collect();
        let chosen: Vec<Option<&ObstacleDistance>> = if by_paper_names.iter().all(Option::is_some) {
            by_paper_names
        } else {
            (0..3).map(|k| ships.get(k).copied()).collect()
        };
        let mut targets: [Option<String>; 3] = Default::default();
        let mut d = [[None; 3]; 3];
        let mut colregs = [None; 3];
        for (k, o) in chosen.iter().enumerate() {
            let Some(o) = o else { continue };
            for (j, v) in VESSELS.iter().enumerate() {
                d[k][j] = o.vessels.get(*v).map(|x| x.normalized);
            }
            colregs[k] = m
                .colregs
                .colregs
                .iter()
                .find(|e| e.target == o.obstacle)
                .and_then(|e| match e.verdict.as_str() {
                    "compliant" => Some(true),
                    "violation" => Some(false),
                    _ => None,
                });
            targets[k] = Some(o.obstacle.clone());
        }
        RunSummary {
            run: run.to_owned(),
            architecture: m.run.architecture.as_ref().map(|c| c.code),
            scheme: m.run.scheme.as_ref().map(|c| c.code),
            targets,
            d,
            colregs,
            settling_time_s: m.settling.settling_time_s,
            elongation: m.elongation.max_towline_elongation_error,
            ship_travel_m: Some(m.travel.ship_travel_m).filter(|v| v.is_finite()),
            truncated: m.run.truncated,
        }
    }

    /// `distributed, scheme I` (or what is known).
    #[must_use]
    pub fn label(&self) -> String {
        let a = self
            .architecture
            .map_or_else(|| "architecture ?".to_owned(), architecture_name);
        let s = self.scheme.map_or_else(
            || "scheme ?".to_owned(),
            |s| format!("scheme {}", scheme_name(s)),
        );
        format!("{a}, {s}")
    }
}

pub use crate::doc::num;

/// A signed difference or a dash.
#[must_use]
pub fn diff(a: Option<f64>, b: Option<f64>, prec: usize) -> String {
    match (a, b) {
        (Some(a), Some(b)) if a.is_finite() && b.is_finite() => format!("{:+.prec$}", a - b),
        _ => "-".to_owned(),
    }
}

fn yes_no(v: Option<bool>) -> String {
    match v {
        Some(true) => "yes".to_owned(),
        Some(false) => "no".to_owned(),
        None => "-".to_owned(),
    }
}

const VESSEL_ROWS: [&str; 3] = ["S", "T1", "T2"];

/// Table 6 layout: per run three rows (ship, tug 1, tug 2), a column per scenario, and the
/// COLREGS compliance; the paper's values and the differences in the same cell.
#[must_use]
pub fn table6(runs: &[RunSummary]) -> Block {
    let mut headers = vec!["Collision avoidance scheme".to_owned(), "vessel".to_owned()];
    headers.extend(SCENARIO_CAPTIONS.iter().map(|s| (*s).to_owned()));
    headers.push("COLREGS compliance (ours / paper)".to_owned());
    let mut rows = Vec::new();
    for r in runs {
        let paper = paper::distances_for(r.architecture, r.scheme);
        for (j, v) in VESSEL_ROWS.iter().enumerate() {
            let mut row = vec![
                if j == 0 {
                    format!("{} ({})", r.label(), r.run)
                } else {
                    String::new()
                },
                (*v).to_owned(),
            ];
            for k in 0..3 {
                let ours = r.d[k][j];
                let theirs = paper.map(|p| p.0[k][j]);
                let target = r.targets[k].as_deref().unwrap_or("-");
                row.push(format!(
                    "D_ob{}{v} = {} (paper {}, {}) [{target}]",
                    k + 1,
                    num(ours, 2),
                    num(theirs, 2),
                    diff(ours, theirs, 2)
                ));
            }
            row.push(format!(
                "Scenario {}: {} / {}",
                j + 1,
                yes_no(r.colregs[j]),
                yes_no(paper.and_then(|p| p.1).map(|c| c[j]))
            ));
            rows.push(row);
        }
    }
    Block::Table { headers, rows }
}

/// Table 7 layout: per run its row and the paper's (same architecture, scheme I) with the
/// differences.
#[must_use]
pub fn table7(runs: &[RunSummary]) -> Block {
    let mut headers = vec!["Control architecture".to_owned(), "source".to_owned()];
    headers.extend(
        SCENARIO_CAPTIONS
            .iter()
            .map(|s| format!("{s}: D S / T1 / T2")),
    );
    headers.extend(
        [
            "Settling time (s)",
            "Max elongation error towline 1 (%)",
            "Max elongation error towline 2 (%)",
            "Ship travel (m)",
        ]
        .iter()
        .map(|s| (*s).to_owned()),
    );
    let triple =
        |d: [Option<f64>; 3]| format!("{} / {} / {}", num(d[0], 2), num(d[1], 2), num(d[2], 2));
    let pct = |v: Option<f64>| v.map(|v| v * 100.0);
    let mut rows = Vec::new();
    for r in runs {
        let p = paper::table7_for(r.architecture, r.scheme);
        let mut ours = vec![format!("{} ({})", r.label(), r.run), "ours".to_owned()];
        for k in 0..3 {
            ours.push(triple(r.d[k]));
        }
        ours.push(num(r.settling_time_s, 1));
        ours.push(num(pct(r.elongation[0]), 2));
        ours.push(num(pct(r.elongation[1]), 2));
        ours.push(num(r.ship_travel_m, 2));
        rows.push(ours);
        let mut theirs = vec![String::new(), "paper".to_owned()];
        let mut delta = vec![String::new(), "difference".to_owned()];
        for k in 0..3 {
            let pd = p.map(|p| p.d[k].map(Some)).unwrap_or([None; 3]);
            theirs.push(triple(pd));
            delta.push(format!(
                "{} / {} / {}",
                diff(r.d[k][0], pd[0], 2),
                diff(r.d[k][1], pd[1], 2),
                diff(r.d[k][2], pd[2], 2)
            ));
        }
        let ps = p.map(|p| p.settling_time_s);
        let pe = [p.map(|p| p.elongation[0]), p.map(|p| p.elongation[1])];
        let pt = p.map(|p| p.ship_travel_m);
        theirs.push(num(ps, 0));
        theirs.push(num(pct(pe[0]), 2));
        theirs.push(num(pct(pe[1]), 2));
        theirs.push(num(pt, 2));
        delta.push(diff(r.settling_time_s, ps, 1));
        delta.push(diff(pct(r.elongation[0]), pct(pe[0]), 2));
        delta.push(diff(pct(r.elongation[1]), pct(pe[1]), 2));
        delta.push(diff(r.ship_travel_m, pt, 2));
        rows.push(theirs);
        rows.push(delta);
    }
    Block::Table { headers, rows }
}

/// One row of `compare.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompareRow {
    /// The run.
    #[serde(flatten)]
    pub ours: RunSummary,
    /// The paper's `D` (Table 6 for distributed runs, Table 7 for centralized scheme I).
    pub paper_d: Option<[[f64; 3]; 3]>,
    /// `D` ours minus paper.
    pub d_difference: [[Option<f64>; 3]; 3],
    /// The paper's COLREGS compliance (Table 6).
    pub paper_colregs: Option<[bool; 3]>,
    /// The paper's settling time, s (Table 7).
    pub paper_settling_time_s: Option<f64>,
    /// Ours minus paper, s.
    pub settling_time_difference_s: Option<f64>,
    /// The paper's elongation errors, fractions (Table 7).
    pub paper_elongation: Option<[f64; 2]>,
    /// Ours minus paper, fractions.
    pub elongation_difference: [Option<f64>; 2],
    /// The paper's ship travel, m (section 4.2.3).
    pub paper_ship_travel_m: Option<f64>,
    /// Ours minus paper, m.
    pub ship_travel_difference_m: Option<f64>,
}

fn sub(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some(a? - b?)
}

/// Builds the comparison rows.
#[must_use]
pub fn compare_rows(runs: &[RunSummary]) -> Vec<CompareRow> {
    runs.iter()
        .map(|r| {
            let pd = paper::distances_for(r.architecture, r.scheme);
            let p7 = paper::table7_for(r.architecture, r.scheme);
            let dd: [[Option<f64>; 3]; 3] = std::array::from_fn(|k| {
                std::array::from_fn(|j| sub(r.d[k][j], pd.map(|p| p.0[k][j])))
            });
            CompareRow {
                ours: r.clone(),
                paper_d: pd.map(|p| p.0),
                d_difference: dd,
                paper_colregs: pd.and_then(|p| p.1),
                paper_settling_time_s: p7.map(|p| p.settling_time_s),
                settling_time_difference_s: sub(r.settling_time_s, p7.map(|p| p.settling_time_s)),
                paper_elongation: p7.map(|p| p.elongation),
                elongation_difference: [
                    sub(r.elongation[0], p7.map(|p| p.elongation[0])),
                    sub(r.elongation[1], p7.map(|p| p.elongation[1])),
                ],
                paper_ship_travel_m: p7.map(|p| p.ship_travel_m),
                ship_travel_difference_m: sub(r.ship_travel_m, p7.map(|p| p.ship_travel_m)),
            }
        })
        .collect()
}

/// What `compare` wrote.
#[derive(Debug, Clone)]
pub struct CompareOutcome {
    /// The runs compared.
    pub runs: Vec<RunSummary>,
    /// Files written.
    pub written: Vec<PathBuf>,
}

fn read_metrics(dir: &Path) -> Result<Metrics> {
    let path = if dir.is_file() {
        dir.to_owned()
    } else {
        dir.join("metrics.json")
    };
    let text = std::fs::read_to_string(&path).map_err(|e| AnalyzerError::Metrics {
        path: path.clone(),
        reason: format!("cannot read: {e} (give a directory written by `analyzer report`)"),
    })?;
    if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(&text) {
        return Err(AnalyzerError::Metrics {
            path,
            reason: format!("not a metrics.json: {e}"),
        });
    }
    serde_json::from_str(&text).map_err(|e| AnalyzerError::Metrics {
        path,
        reason: format!("not a metrics.json of `analyzer report`: {e}"),
    })
}

/// Writes `compare.md`, `compare.html` and `compare.json` into `out`.
///
/// # Errors
/// A directory has no readable `metrics.json`, or an output cannot be written.
pub fn compare(out: &Path, dirs: &[PathBuf]) -> Result<CompareOutcome> {
    if dirs.is_empty() {
        return Err(AnalyzerError::Usage(
            "no run directory given: analyzer compare --out DIR RUN_DIR...".to_owned(),
        ));
    }
    let mut runs = Vec::new();
    for d in dirs {
        let m = read_metrics(d)?;
        runs.push(RunSummary::from_metrics(&d.display().to_string(), &m));
    }
    // Order: distributed before centralized, then by scheme.
    runs.sort_by_key(|r| (r.architecture.unwrap_or(9), r.scheme.unwrap_or(9)));
    std::fs::create_dir_all(out).map_err(|e| AnalyzerError::write(out, e))?;

    let mut blocks = vec![
        Block::Heading(1, "Comparison with Du, Negenborn, Reppa (2022)".to_owned()),
        Block::Para(
            "Normalised minimum distance D = min distance / own length (eq. (30)); scenario k \
             is the encounter with the paper's target ship A, B, C (or the k-th target ship \
             by slot). The paper's values: Table 6 (distributed control, by scheme) and Table 7 \
             (distributed vs centralized, scheme I; ship travel from section 4.2.3). \
             Differences are ours minus the paper's."
                .to_owned(),
        ),
    ];
    if runs.iter().any(|r| r.truncated) {
        blocks.push(Block::Para(
            "WARNING: at least one run comes from a truncated log.".to_owned(),
        ));
    }
    blocks.push(Block::Heading(
        2,
        "Table 6 layout: normalised minimum distance by avoidance scheme".to_owned(),
    ));
    blocks.push(table6(&runs));
    blocks.push(Block::Heading(
        2,
        "Table 7 layout: avoidance and control performance by architecture".to_owned(),
    ));
    blocks.push(table7(&runs));

    let md = out.join("compare.md");
    let html = out.join("compare.html");
    let json = out.join("compare.json");
    std::fs::write(&md, to_markdown(&blocks)).map_err(|e| AnalyzerError::write(&md, e))?;
    std::fs::write(&html, to_html("Comparison with Du et al. (2022)", &blocks))
        .map_err(|e| AnalyzerError::write(&html, e))?;
    let rows = compare_rows(&runs);
    let text = serde_json::to_string_pretty(&rows).map_err(|e| AnalyzerError::write(&json, e))?;
    std::fs::write(&json, text).map_err(|e| AnalyzerError::write(&json, e))?;
    Ok(CompareOutcome {
        runs,
        written: vec![md, html, json],
    })
}
