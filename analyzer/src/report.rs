//! `analyzer report`: one run's logs to `metrics.json`, tables (CSV and Parquet), plots
//! (PNG and SVG), `report.md` and a self-contained `report.html`.

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::analysis::{analyze_run, Metrics};
use crate::colregs::EncounterReport;
use crate::compare::{table6, table7, RunSummary};
use crate::doc::{to_html, to_markdown, Block};
use crate::error::{AnalyzerError, Result};
use crate::frames::ControllerFrames;
use crate::plots::{write_plots, PlotFile};
use crate::progress;
use crate::rows::VESSELS;
use crate::run::load_run;
use crate::stream::{StreamOptions, TableOut};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// What `report` wrote.
#[derive(Debug, Clone)]
pub struct ReportOutcome {
    /// The metrics (also in `metrics.json`).
    pub metrics: Metrics,
    /// Every file written.
    pub written: Vec<PathBuf>,
}

/// Reads the logs, analyses the run (the verdict under the default thresholds) and writes
/// everything into `out`.
///
/// # Errors
/// See [`crate::error::AnalyzerError`]: unusable inputs name the file and the problem.
pub fn report(out: &Path, logs: &[PathBuf], quiet: bool) -> Result<ReportOutcome> {
    report_with(
        out,
        logs,
        quiet,
        &StreamOptions::default(),
        &Thresholds::default(),
    )
}

/// [`report`] with the streaming analysis' sizes `opts` and the verdict's `thresholds`.
///
/// # Errors
/// As [`report`].
pub fn report_with(
    out: &Path,
    logs: &[PathBuf],
    quiet: bool,
    opts: &StreamOptions,
    thresholds: &Thresholds,
) -> Result<ReportOutcome> {
    let multi = progress::multi(quiet);
    let run = load_run(logs, &multi)?;
    std::fs::create_dir_all(out).map_err(|e| AnalyzerError::write(out, e))?;
    let analysis = analyze_run(run, Some(out), &multi, opts, thresholds)?;

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
    let title = format!("Towing run report: {}", analysis.metrics.run.scenario);
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
    for o in &m.distances.normalized_min_distance {
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
        &mut encounter_frame(&m.colregs.colregs)?,
    )?);
    w.extend(write_frame(out, "min_distances", &mut distance_frame(m)?)?);
    Ok(w)
}

/// The verdict as report blocks: passed, or every reason.
fn verdict_blocks(m: &Metrics) -> Vec<Block> {
    let v = &m.verdict;
    let mut b = vec![Block::Heading(2, "Verdict".to_owned())];
    if v.passed {
        b.push(Block::Para("passed: no metric gave a reason".to_owned()));
    } else {
        b.push(Block::Para(format!("FAILED: {} reasons", v.reasons.len())));
        b.push(Block::List(v.reasons.iter().map(Reason::line).collect()));
    }
    b
}

/// The report: every registered metric's part (head, summary rows, blocks after the
/// summary, details; in registration order) around the verdict, the paper's tables, the
/// plots and the files read.
fn report_blocks(m: &Metrics, plots: &[PlotFile]) -> Result<Vec<Block>> {
    let parts = m.report_parts();
    let mut b: Vec<Block> = parts.iter().flat_map(|p| p.head.iter().cloned()).collect();
    b.extend(verdict_blocks(m));
    b.push(Block::Heading(2, "Summary".to_owned()));
    b.push(Block::Table {
        headers: vec!["metric".into(), "value".into(), "definition".into()],
        rows: parts
            .iter()
            .flat_map(|p| p.summary.iter().map(|r| r.to_vec()))
            .collect(),
    });
    b.extend(parts.iter().flat_map(|p| p.after_summary.iter().cloned()));

    // The paper's tables for this run.
    let summary = RunSummary::from_metrics("this run", m);
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
    b.extend(parts.iter().flat_map(|p| p.details.iter().cloned()));

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
    b.push(files_table(m));
    Ok(b)
}

/// What was read of each file, per topic.
fn files_table(m: &Metrics) -> Block {
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
    Block::Table {
        headers: vec![
            "file".into(),
            "topic".into(),
            "messages".into(),
            "problems".into(),
        ],
        rows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::SynthRun;

    fn read_csv(path: &Path) -> String {
        std::fs::read_to_string(path).expect("csv")
    }

    /// A metric registered in `crate::metric::registry` (here the collisions metric, on
    /// a synthetic run through a hazard) reaches `metrics.json` (its typed section, read
    /// back by `analyzer compare`'s deserialiser), the report (its summary row and
    /// detail table) and the verdict (a reason naming the metric, the target and the
    /// time); the same run without the hazard passes.
    #[test]
    fn a_registered_metric_reaches_metrics_json_the_report_and_the_verdict() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut run = SynthRun::paper(1200);
        run.scene = false;
        run.speed = 0.1;
        run.route = vec![[0.0, 0.0, 0.0], [15.0, 0.0, 0.0], [30.0, 0.0, 0.0]];
        run.obstacles = vec![crate::synth::SynthObstacle {
            name: "rock".to_owned(),
            pos: [6.0, 0.0],
            shape: crate::synth::SynthShape::Circle(1.0),
            active_from: 0.0,
        }];
        let (plant, controller) = (dir.path().join("p.mcap"), dir.path().join("c.mcap"));
        run.write(&plant, &controller).expect("logs");
        let out = dir.path().join("hit");
        let o = report(&out, &[plant, controller], true).expect("report");
        let m = &o.metrics;
        assert!(m.collisions.collisions > 0);

        let text = std::fs::read_to_string(out.join("metrics.json")).expect("metrics.json");
        let json: serde_json::Value = serde_json::from_str(&text).expect("json");
        assert_eq!(json["collisions"], m.collisions.collisions);
        assert_eq!(json["verdict"]["passed"], false);
        assert_eq!(json["thresholds"]["drift_max_deg"], 30.0);
        // Read back as the typed Metrics (serde_json's float parsing is the same either
        // way, so the typed values written out again give the parsed file).
        let back: Metrics = serde_json::from_str(&text).expect("typed metrics");
        assert_eq!(serde_json::to_value(&back).expect("value"), json);
        assert_eq!(back.verdict.reasons.len(), m.verdict.reasons.len());

        assert!(!m.verdict.passed);
        let r = m
            .verdict
            .reasons
            .iter()
            .find(|r| r.metric == "collisions")
            .expect("a collisions reason");
        assert_eq!(r.target.as_deref(), Some("rock"));
        let first = m.collisions.collision_events[0].t_start_s;
        assert_eq!(r.t_s, Some(first));

        let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
        assert!(md.contains("Collisions (hull overlaps)"), "detail table");
        assert!(md.contains("| collisions | "), "summary row");
        assert!(md.contains(&r.line()), "the reason in the verdict section");

        run.obstacles.clear();
        let (plant, controller) = (dir.path().join("p2.mcap"), dir.path().join("c2.mcap"));
        run.write(&plant, &controller).expect("logs");
        let clear = report(&dir.path().join("clear"), &[plant, controller], true).expect("report");
        assert_eq!(clear.metrics.collisions.collisions, 0);
        assert!(
            !clear
                .metrics
                .verdict
                .reasons
                .iter()
                .any(|r| r.metric == "collisions"),
            "{:?}",
            clear.metrics.verdict
        );
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
        let w = report_with(&whole_dir, &logs, true, &whole, &Thresholds::default())
            .expect("one batch");
        for batch_steps in [7, 97, 700] {
            let out = dir.path().join(format!("b{batch_steps}"));
            let opts = StreamOptions {
                batch_steps,
                ..StreamOptions::default()
            };
            let b = report_with(&out, &logs, true, &opts, &Thresholds::default()).expect("batches");
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
