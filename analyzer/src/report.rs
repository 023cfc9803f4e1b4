//! `analyzer report`: one run's logs to `metrics.json`, tables (CSV and Parquet), plots
//! (PNG and SVG), `report.md` and a self-contained `report.html`.

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::analysis::{analyze_run, Metrics, VESSELS};
use crate::colregs::EncounterReport;
use crate::compare::{num, table6, table7, RunSummary};
use crate::doc::{to_html, to_markdown, Block};
use crate::error::{AnalyzerError, Result};
use crate::frames::ControllerFrames;
use crate::plots::{write_plots, PlotFile};
use crate::progress;
use crate::run::load_run;
use crate::stream::{StreamOptions, TableOut};

/// What `report` wrote.
#[derive(Debug, Clone)]
pub struct ReportOutcome {
    /// The metrics (also in `metrics.json`).
    pub metrics: Metrics,
    /// Every file written.
    pub written: Vec<PathBuf>,
}

/// Reads the logs, analyses the run and writes everything into `out`.
///
/// # Errors
/// See [`crate::error::AnalyzerError`]: unusable inputs name the file and the problem.
pub fn report(out: &Path, logs: &[PathBuf], quiet: bool) -> Result<ReportOutcome> {
    report_with(out, logs, quiet, &StreamOptions::default())
}

/// [`report`] with the streaming analysis' sizes `opts`.
///
/// # Errors
/// As [`report`].
pub fn report_with(
    out: &Path,
    logs: &[PathBuf],
    quiet: bool,
    opts: &StreamOptions,
) -> Result<ReportOutcome> {
    let multi = progress::multi(quiet);
    let run = load_run(logs, &multi)?;
    std::fs::create_dir_all(out).map_err(|e| AnalyzerError::write(out, e))?;
    let analysis = analyze_run(run, Some(out), &multi, opts)?;

    let stage = progress::stage(&multi, "tables");
    let mut written = Vec::new();
    let metrics_path = out.join("metrics.json");
    let text = serde_json::to_string_pretty(&analysis.metrics)
        .map_err(|e| AnalyzerError::write(&metrics_path, e))?;
    std::fs::write(&metrics_path, text).map_err(|e| AnalyzerError::write(&metrics_path, e))?;
    written.push(metrics_path);
    written.extend(analysis.tables.iter().cloned());
    written.extend(write_tables(out, &analysis.controller, &analysis.metrics)?);
    stage.set_message("plots");
    let plots = write_plots(out, &analysis.plot)?;
    for p in &plots {
        written.push(p.png.clone());
        written.push(p.svg.clone());
    }
    stage.set_message("report");
    let blocks = report_blocks(&analysis.metrics, &plots)?;
    let md = out.join("report.md");
    std::fs::write(&md, to_markdown(&blocks)).map_err(|e| AnalyzerError::write(&md, e))?;
    let html = out.join("report.html");
    let title = format!("Towing run report: {}", analysis.metrics.scenario);
    std::fs::write(&html, to_html(&title, &blocks)).map_err(|e| AnalyzerError::write(&html, e))?;
    written.push(md);
    written.push(html);
    stage.finish_and_clear();
    Ok(ReportOutcome {
        metrics: analysis.metrics,
        written,
    })
}

fn write_frame(out: &Path, stem: &str, df: &mut DataFrame) -> Result<Vec<PathBuf>> {
    let csv = out.join(format!("{stem}.csv"));
    let mut f = File::create(&csv).map_err(|e| AnalyzerError::write(&csv, e))?;
    CsvWriter::new(&mut f)
        .finish(df)
        .map_err(|e| AnalyzerError::write(&csv, e))?;
    let pq = out.join(format!("{stem}.parquet"));
    let f = File::create(&pq).map_err(|e| AnalyzerError::write(&pq, e))?;
    ParquetWriter::new(f)
        .finish(df)
        .map_err(|e| AnalyzerError::write(&pq, e))?;
    Ok(vec![csv, pq])
}

fn opt_f64(name: &str, v: impl Iterator<Item = Option<f64>>) -> Column {
    Float64Chunked::from_iter_options(name.into(), v)
        .into_series()
        .into_column()
}

fn opt_str<'a>(name: &str, v: impl Iterator<Item = Option<&'a str>>) -> Column {
    StringChunked::from_iter_options(name.into(), v)
        .into_series()
        .into_column()
}

/// The per-encounter summary as a table.
///
/// # Errors
/// A polars error (unexpected).
pub fn encounter_frame(enc: &[EncounterReport]) -> Result<DataFrame> {
    let f = |name: &str, get: &dyn Fn(&EncounterReport) -> Option<f64>| {
        opt_f64(name, enc.iter().map(get))
    };
    let s = |name: &str, get: &dyn Fn(&EncounterReport) -> Option<&str>| {
        opt_str(name, enc.iter().map(get))
    };
    let cols = vec![
        s("target", &|e| Some(e.target.as_str())),
        f("slot", &|e| Some(f64::from(e.slot))),
        s("situation", &|e| e.situation.as_deref()),
        s("role", &|e| e.role.as_deref()),
        s("situation_geometric", &|e| e.situation_geometric.as_deref()),
        s("situation_assessed", &|e| e.situation_assessed.as_deref()),
        f("t_detect_s", &|e| e.t_detect_s),
        f("t_detect_tow_s", &|e| e.t_detect_tow_s),
        f("t_first_action_s", &|e| e.t_first_action_s),
        s("first_action", &|e| e.first_action.as_deref()),
        f("r_first_action_m", &|e| e.r_first_action_m),
        f("course_change_deg", &|e| e.course_change_deg),
        f("course_change_starboard_deg", &|e| {
            e.course_change_starboard_deg
        }),
        f("course_change_port_deg", &|e| e.course_change_port_deg),
        f("t_cpa_s", &|e| Some(e.t_cpa_s)),
        f("r_cpa_m", &|e| Some(e.r_cpa_m)),
        f("r_cpa_ship_lengths", &|e| Some(e.r_cpa_ship_lengths)),
        f("beta_cpa_deg", &|e| Some(e.beta_cpa_deg)),
        f("alpha_cpa_deg", &|e| Some(e.alpha_cpa_deg)),
        s("side", &|e| Some(e.side.as_str())),
        s("passed", &|e| Some(e.passed.as_str())),
        s("verdict", &|e| Some(e.verdict.as_str())),
        opt_str(
            "reasons",
            enc.iter()
                .map(|e| e.reasons.join("; "))
                .collect::<Vec<_>>()
                .iter()
                .map(|s| Some(s.as_str())),
        ),
        f("rule", &|e| e.rule.map(f64::from)),
        f("score", &|e| e.score),
        f("s_range", &|e| e.scores.map(|s| s.s_range)),
        f("s_pose", &|e| e.scores.map(|s| s.s_pose)),
        f("safety", &|e| e.scores.map(|s| s.safety)),
        f("p_delay", &|e| e.scores.map(|s| s.p_delay)),
        f("p_not_apparent", &|e| e.scores.map(|s| s.p_not_apparent)),
        f("rule13", &|e| e.scores.map(|s| s.rule13)),
        f("rule14", &|e| e.scores.map(|s| s.rule14)),
        f("rule15", &|e| e.scores.map(|s| s.rule15)),
        f("rule16", &|e| e.scores.map(|s| s.rule16)),
        f("rule17", &|e| e.scores.map(|s| s.rule17)),
        f("r_detect_m", &|e| Some(e.params.r_detect_m)),
        f("r_min_m", &|e| Some(e.params.r_min_m)),
        f("r_nm_m", &|e| Some(e.params.r_nm_m)),
        f("r_col_m", &|e| Some(e.params.r_col_m)),
    ];
    DataFrame::new_infer_height(cols).map_err(|e| AnalyzerError::frame("encounters", e))
}

/// The eq. (30) summary as a long table.
fn distance_frame(m: &Metrics) -> Result<DataFrame> {
    let mut obstacle = Vec::new();
    let mut kind = Vec::new();
    let mut encounter = Vec::new();
    let mut vessel = Vec::new();
    let mut min_d = Vec::new();
    let mut length = Vec::new();
    let mut norm = Vec::new();
    let mut t = Vec::new();
    for o in &m.normalized_min_distance {
        for v in VESSELS {
            if let Some(d) = o.vessels.get(v) {
                obstacle.push(o.obstacle.as_str());
                kind.push(o.kind.as_str());
                encounter.push(o.encounter.as_str());
                vessel.push(v);
                min_d.push(Some(d.min_distance_m));
                length.push(Some(d.own_length_m));
                norm.push(Some(d.normalized));
                t.push(Some(d.t_s));
            }
        }
    }
    DataFrame::new_infer_height(vec![
        opt_str("obstacle", obstacle.into_iter().map(Some)),
        opt_str("kind", kind.into_iter().map(Some)),
        opt_str("encounter", encounter.into_iter().map(Some)),
        opt_str("vessel", vessel.into_iter().map(Some)),
        opt_f64("min_distance_m", min_d.into_iter()),
        opt_f64("own_length_m", length.into_iter()),
        opt_f64("normalized", norm.into_iter()),
        opt_f64("t_s", t.into_iter()),
    ])
    .map_err(|e| AnalyzerError::frame("min_distances", e))
}

/// Rows of the controller's tables built and written per chunk.
const CHUNK_ROWS: usize = 100_000;

/// Writes a table of `height` rows chunk by chunk (`rows(offset, len)`), CSV and Parquet.
fn write_chunks(
    out: &Path,
    stem: &str,
    height: usize,
    rows: impl Fn(usize, usize) -> Result<DataFrame>,
) -> Result<Vec<PathBuf>> {
    let mut table = TableOut::new(out, stem);
    let mut offset = 0;
    loop {
        table.write(&mut rows(offset, CHUNK_ROWS)?)?;
        offset += CHUNK_ROWS;
        if offset >= height {
            break;
        }
    }
    table.finish()
}

/// Writes the tables not written while the plant log streamed, as CSV and Parquet:
/// `controller`, `colregs` (in chunks), `encounters`, `min_distances`.
fn write_tables(out: &Path, ctrl: &ControllerFrames, m: &Metrics) -> Result<Vec<PathBuf>> {
    let mut w = write_chunks(out, "controller", ctrl.controller_height(), |o, n| {
        ctrl.controller_rows(o, n)
    })?;
    w.extend(write_chunks(
        out,
        "colregs",
        ctrl.colregs_height(),
        |o, n| ctrl.colregs_rows(o, n),
    )?);
    w.extend(write_frame(
        out,
        "encounters",
        &mut encounter_frame(&m.colregs)?,
    )?);
    w.extend(write_frame(out, "min_distances", &mut distance_frame(m)?)?);
    Ok(w)
}

fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |v| format!("{:.2} %", v * 100.0))
}

fn report_blocks(m: &Metrics, plots: &[PlotFile]) -> Result<Vec<Block>> {
    let mut b = Vec::new();
    b.push(Block::Heading(
        1,
        format!("Towing run: scenario {}", m.scenario),
    ));
    let arch = m.architecture.as_ref().map_or_else(
        || "unknown (no controller log)".to_owned(),
        |a| format!("{} ({})", a.name, a.code),
    );
    let scheme = m.scheme.as_ref().map_or_else(
        || "unknown".to_owned(),
        |s| format!("{} ({})", s.name, s.code),
    );
    if m.truncated {
        for t in &m.truncated_files {
            b.push(Block::Para(format!(
                "WARNING: {} is truncated: {}. The report covers what was read ({:.1} s to {:.1} s).",
                t.file, t.reason, m.start_s, m.end_s
            )));
        }
    }
    b.push(Block::List(vec![
        format!("architecture: {arch}; avoidance scheme: {scheme}"),
        format!("scenario: {} ({})", m.scenario, m.scenario_source),
        format!(
            "simulated {:.1} s to {:.1} s: {} plant steps, {} control samples",
            m.start_s, m.end_s, m.plant_steps, m.control_samples
        ),
        format!(
            "files: {}",
            m.files
                .iter()
                .map(|f| format!("{} ({}, {} bytes)", f.path.display(), f.unit, f.bytes))
                .collect::<Vec<_>>()
                .join("; ")
        ),
    ]));
    if !m.notes.is_empty() {
        b.push(Block::List(
            m.notes.iter().map(|n| format!("note: {n}")).collect(),
        ));
    }

    b.push(Block::Heading(2, "Summary".to_owned()));
    let stats = |s: &Option<crate::metrics::Stats>, prec: usize| {
        s.map_or_else(
            || "-".to_owned(),
            |s| {
                format!(
                    "median {:.prec$}, p99 {:.prec$}, max {:.prec$} (n = {})",
                    s.median, s.p99, s.max, s.count
                )
            },
        )
    };
    let bv = &m.bound_violations.report;
    b.push(Block::Table {
        headers: vec!["metric".into(), "value".into(), "definition".into()],
        rows: vec![
            vec![
                "settling time".into(),
                m.settling_time_s
                    .map_or_else(|| "never settled".to_owned(), |t| format!("{t:.1} s")),
                "first time after which the ship stays within L/2 of the destination, 3 deg of its heading, |u|,|v| < 0.01 m/s, |r| < 0.01 rad/s (paper, section 4.2.3)".into(),
            ],
            vec![
                "max towline elongation error".into(),
                format!(
                    "{} / {}",
                    pct(m.max_towline_elongation_error[0]),
                    pct(m.max_towline_elongation_error[1])
                ),
                "max |l - l_tow| / l_tow, towline 1 / 2".into(),
            ],
            vec![
                "ship travel".into(),
                format!("{:.2} m", m.ship_travel_m),
                "length of the ship's track".into(),
            ],
            vec![
                "collisions".into(),
                m.collisions.to_string(),
                "hull-overlap events: hull rectangles vs hazard circles, target ellipses and each other".into(),
            ],
            vec![
                "bound violations".into(),
                bv.total.to_string(),
                "commands outside the tension, tension rate, towing angle, angle rate and thrust bounds".into(),
            ],
            vec![
                "sample computation time".into(),
                stats(&m.sample_time_ms, 2) + " ms",
                "wall time per control sample (controller log)".into(),
            ],
            vec![
                "ADMM iterations".into(),
                stats(&m.admm_iterations, 0),
                format!(
                    "per control sample; converged in {}",
                    m.admm_converged_fraction
                        .map_or_else(|| "-".to_owned(), |f| format!("{:.1} % of samples", f * 100.0))
                ),
            ],
            vec![
                "fallbacks".into(),
                m.fallbacks.to_string(),
                "samples whose plan was replaced by the shifted previous plan".into(),
            ],
            vec![
                "unit warnings / errors".into(),
                format!("{} / {}", m.unit_warnings, m.unit_errors),
                "/plant/log and /controller/log".into(),
            ],
        ],
    });
    if let Some(f) = &m.final_state {
        b.push(Block::Para(format!(
            "At the end of the log ({:.1} s) the ship is {:.3} m from the destination, heading error {:.2} deg, speed {:.4} m/s.",
            f.t_s, f.distance_to_destination_m, f.heading_error_deg, f.speed_m_s
        )));
    }

    // The paper's tables for this run.
    let value = serde_json::to_value(m).map_err(|e| AnalyzerError::frame("metrics", e))?;
    let summary = RunSummary::from_json("this run", &value);
    b.push(Block::Heading(
        2,
        "Table 6 layout: normalised minimum distance (eq. (30)) and COLREGS compliance".to_owned(),
    ));
    b.push(table6(std::slice::from_ref(&summary)));
    b.push(Block::Heading(
        2,
        "Table 7 layout: avoidance and control performance".to_owned(),
    ));
    b.push(table7(std::slice::from_ref(&summary)));

    b.push(Block::Heading(
        2,
        "Normalised minimum distance to every obstacle (eq. (30))".to_owned(),
    ));
    let mut rows = Vec::new();
    for o in &m.normalized_min_distance {
        let cell = |v: &str| {
            o.vessels.get(v).map_or_else(
                || "-".to_owned(),
                |d| {
                    format!(
                        "{:.2} ({:.3} m at {:.0} s)",
                        d.normalized, d.min_distance_m, d.t_s
                    )
                },
            )
        };
        rows.push(vec![
            o.obstacle.clone(),
            o.kind.clone(),
            o.encounter.clone(),
            cell("ship"),
            cell("tug1"),
            cell("tug2"),
        ]);
    }
    b.push(Block::Table {
        headers: vec![
            "obstacle".into(),
            "kind".into(),
            "encounter".into(),
            "D ship".into(),
            "D tug 1".into(),
            "D tug 2".into(),
        ],
        rows,
    });

    b.push(Block::Heading(2, "COLREGS encounters".to_owned()));
    if let Some(e) = m.colregs.first() {
        let p = &e.params;
        b.push(Block::Para(format!(
            "Scoring after Woerner et al. (2018) at model scale (docs/analyzer.md): r_detect = {:.2} m ({:.2} L), r_min = {:.2} m ({:.2} L), r_nm = {:.2} m ({:.2} L), r_col = {:.2} m ({:.2} L) for the first target, L = {:.3} m the ship length; gamma_nm {}, gamma_col {}, w_r {}, w_theta {}, readily apparent course change {} deg. Side: sign of the target's bearing from the ship's bow at the CPA.",
            p.r_detect_m, p.ranges_in_ship_lengths[0], p.r_min_m, p.ranges_in_ship_lengths[1],
            p.r_nm_m, p.ranges_in_ship_lengths[2], p.r_col_m, p.ranges_in_ship_lengths[3],
            p.ship_length_m, p.gamma_nm, p.gamma_col, p.w_r, p.w_theta, p.dchi_apparent_deg
        )));
    }
    let rows = m
        .colregs
        .iter()
        .map(|e| {
            vec![
                e.target.clone(),
                format!(
                    "{} / {}",
                    e.situation.as_deref().unwrap_or("-"),
                    e.role.as_deref().unwrap_or("-")
                ),
                e.situation_geometric.clone().unwrap_or_else(|| "-".into()),
                num(e.t_detect_s, 1),
                format!(
                    "{} ({})",
                    num(e.t_first_action_s, 1),
                    e.first_action.as_deref().unwrap_or("none")
                ),
                num(e.course_change_deg, 1),
                format!("{:.1}", e.t_cpa_s),
                format!("{:.3} m ({:.2} L)", e.r_cpa_m, e.r_cpa_ship_lengths),
                e.side.clone(),
                e.passed.clone(),
                if e.reasons.is_empty() || e.verdict == "compliant" {
                    e.verdict.clone()
                } else {
                    format!("{}: {}", e.verdict, e.reasons.join("; "))
                },
                e.rule
                    .map_or_else(|| "-".into(), |r| format!("Rule {r}: {}", num(e.score, 2))),
            ]
        })
        .collect();
    b.push(Block::Table {
        headers: vec![
            "target".into(),
            "situation / role (controller)".into(),
            "geometric".into(),
            "detected (s)".into(),
            "first action (s)".into(),
            "course change (deg)".into(),
            "CPA (s)".into(),
            "range at CPA".into(),
            "side".into(),
            "passed".into(),
            "verdict".into(),
            "score".into(),
        ],
        rows,
    });

    b.push(Block::Heading(2, "Bounds".to_owned()));
    let bd = &m.bound_violations.bounds;
    let vrow = |name: &str, bound: String, v: &crate::metrics::Violations, unit: &str| {
        vec![
            name.to_owned(),
            bound,
            format!("{} of {}", v.count, v.checked),
            if v.count > 0 {
                format!("{:.4} {unit}", v.worst_excess)
            } else {
                "-".to_owned()
            },
            num(v.first_t_s, 1),
        ]
    };
    b.push(Block::Table {
        headers: vec![
            "command".into(),
            "bound".into(),
            "violations".into(),
            "worst excess".into(),
            "first (s)".into(),
        ],
        rows: vec![
            vrow(
                "tension",
                format!("{} .. {} N", bd.min_tension_n, bd.max_tension_n),
                &bv.tension,
                "N",
            ),
            vrow(
                "tension rate",
                format!("{} N/s", bd.tension_rate_n_per_s),
                &bv.tension_rate,
                "N/s",
            ),
            vrow(
                "towing angle",
                format!("{:.1} deg", bd.max_towing_angle_rad.to_degrees()),
                &bv.towing_angle,
                "deg",
            ),
            vrow(
                "towing angle rate",
                format!("{:.1} deg/s", bd.angle_rate_rad_per_s.to_degrees()),
                &bv.towing_angle_rate,
                "deg/s",
            ),
            vrow(
                "tug thrust (commands)",
                format!("{:?}", bd.max_thrust),
                &bv.tug_thrust_command,
                "N or N m",
            ),
            vrow(
                "tug thrust (plant inputs)",
                format!("{:?}", bd.max_thrust),
                &bv.tug_thrust_input,
                "N or N m",
            ),
        ],
    });

    if !m.collision_events.is_empty() {
        b.push(Block::Heading(2, "Collisions (hull overlaps)".to_owned()));
        b.push(Block::Table {
            headers: vec![
                "a".into(),
                "b".into(),
                "from (s)".into(),
                "to (s)".into(),
                "samples".into(),
            ],
            rows: m
                .collision_events
                .iter()
                .map(|e| {
                    vec![
                        e.a.clone(),
                        e.b.clone(),
                        format!("{:.1}", e.t_start_s),
                        format!("{:.1}", e.t_end_s),
                        e.samples.to_string(),
                    ]
                })
                .collect(),
        });
    }
    if !m.fallback_reasons.is_empty() {
        b.push(Block::Heading(2, "Fallbacks".to_owned()));
        b.push(Block::Table {
            headers: vec!["reason".into(), "samples".into()],
            rows: m
                .fallback_reasons
                .iter()
                .map(|(r, n)| vec![r.clone(), n.to_string()])
                .collect(),
        });
    }

    b.push(Block::Heading(2, "Plots".to_owned()));
    for p in plots {
        let svg = std::fs::read_to_string(&p.svg).map_err(|e| AnalyzerError::write(&p.svg, e))?;
        b.push(Block::Figure {
            caption: p.title.clone(),
            png: format!("{}.png", p.stem),
            svg,
        });
    }

    b.push(Block::Heading(2, "Files".to_owned()));
    let mut rows = Vec::new();
    for f in &m.files {
        for (topic, n) in &f.messages {
            let errors = f
                .decode_errors
                .get(topic)
                .map_or_else(String::new, |(c, e)| format!("{c} not decoded: {e}"));
            rows.push(vec![
                f.path.display().to_string(),
                topic.clone(),
                n.to_string(),
                errors,
            ]);
        }
    }
    b.push(Block::Table {
        headers: vec![
            "file".into(),
            "topic".into(),
            "messages".into(),
            "problems".into(),
        ],
        rows,
    });
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::SynthRun;

    fn read_csv(path: &Path) -> String {
        std::fs::read_to_string(path).expect("csv")
    }

    /// The regression this guards: the plant log is analysed in batches with rows carried
    /// over for the as-of joins; any batch size must give the tables and metrics of one
    /// batch (the whole log at once, as the analyzer did before streaming).
    #[test]
    fn batches_of_any_size_give_the_tables_and_metrics_of_one_batch() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut run = SynthRun::paper(2345);
        run.scene = false;
        run.speed = 0.2;
        run.obstacles[4].active_from = 405.0 * 0.3;
        run.obstacles[5].active_from = 590.0 * 0.3;
        run.tension_spike_at_sample = Some(40);
        let (plant, controller) = (dir.path().join("p.mcap"), dir.path().join("c.mcap"));
        run.write(&plant, &controller).expect("logs");
        let logs = [plant, controller];
        let whole_dir = dir.path().join("whole");
        let whole = StreamOptions {
            batch_steps: usize::MAX,
            ..StreamOptions::default()
        };
        let w = report_with(&whole_dir, &logs, true, &whole).expect("one batch");
        for batch_steps in [7, 97, 700] {
            let out = dir.path().join(format!("b{batch_steps}"));
            let opts = StreamOptions {
                batch_steps,
                ..StreamOptions::default()
            };
            let b = report_with(&out, &logs, true, &opts).expect("batches");
            assert_eq!(w.metrics, b.metrics, "batch {batch_steps}");
            for stem in ["timeseries", "obstacles", "controller"] {
                let a = read_csv(&whole_dir.join(format!("{stem}.csv")));
                let c = read_csv(&out.join(format!("{stem}.csv")));
                assert_eq!(a, c, "{stem}.csv, batch {batch_steps}");
                let back = ParquetReader::new(
                    File::open(out.join(format!("{stem}.parquet"))).expect("parquet"),
                )
                .finish()
                .expect("read parquet");
                assert_eq!(back.height() + 1, c.lines().count(), "{stem}.parquet");
            }
        }
        let ts = read_csv(&whole_dir.join("timeseries.csv"));
        assert_eq!(ts.lines().count(), 2346 + 1, "one header, every step once");
        let header = ts.lines().next().expect("header");
        for c in [
            "t_ns",
            "ship_x",
            "line2_tension",
            "in_tug2_N",
            "cmd_tension1",
            "wp_psi",
        ] {
            assert!(header.split(',').any(|h| h == c), "{c} in {header}");
        }
    }
}
