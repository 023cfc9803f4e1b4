//! Plots: the files decode, have the sizes asked, and the map is not blank.

mod common;

use analyzer::plots::{
    map_layout, write_plots, ADMM_SIZE, HISTOGRAM_SIZE, RATES_SIZE, STATES_SIZE, TOWING_SIZE,
};
use analyzer::synth::SynthRun;

#[test]
fn plots_decode_with_their_sizes_and_the_map_shows_the_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = SynthRun::paper(3000);
    run.speed = 0.2;
    run.obstacles[4].active_from = 405.0 * 0.3;
    run.obstacles[5].active_from = 590.0 * 0.3;
    common::with_analysis(&run, dir.path(), |a| check_plots(a, dir.path()));
}

fn check_plots(a: &analyzer::analysis::Analysis, dir: &std::path::Path) {
    let out = dir.join("plots");
    std::fs::create_dir_all(&out).expect("dir");
    let plots = write_plots(&out, &a.plot).expect("plots");
    let stems: Vec<&str> = plots.iter().map(|p| p.stem.as_str()).collect();
    assert_eq!(
        stems,
        [
            "map",
            "states",
            "towing",
            "rates",
            "distances",
            "admm",
            "compute_time"
        ]
    );
    let (map_size, _, _) = map_layout(&a.plot);
    for p in &plots {
        let expected = match p.stem.as_str() {
            "map" => map_size,
            "states" => STATES_SIZE,
            "towing" => TOWING_SIZE,
            "rates" => RATES_SIZE,
            "admm" => ADMM_SIZE,
            "compute_time" => HISTOGRAM_SIZE,
            _ => p.size,
        };
        assert_eq!(p.size, expected, "{}", p.stem);
        let img = image::open(&p.png).expect("png decodes").to_rgb8();
        assert_eq!(img.dimensions(), expected, "{}", p.stem);
        let svg = std::fs::read_to_string(&p.svg).expect("svg");
        assert!(
            svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
            "{}",
            p.stem
        );
        assert!(
            svg.contains(&format!("width=\"{}\"", expected.0)),
            "{}",
            p.stem
        );
        // Text was drawn with the embedded font (axis descriptions).
        assert!(
            svg.contains("t (s)") || svg.contains("East y (m)") || svg.contains("compute time")
        );
    }
    // Six obstacles in rows of two.
    let dist = plots
        .iter()
        .find(|p| p.stem == "distances")
        .expect("distances");
    assert_eq!(dist.size, (1400, 3 * 320 + 40));

    // The map: equal aspect (metres per pixel alike on both axes) and not blank.
    let map = plots.iter().find(|p| p.stem == "map").expect("map");
    let img = image::open(&map.png).expect("png").to_rgb8();
    let total = img.pixels().len();
    let white = img.pixels().filter(|p| p.0 == [255, 255, 255]).count();
    let coloured = img
        .pixels()
        .filter(|p| {
            let [r, g, b] = p.0;
            let (hi, lo) = (r.max(g).max(b), r.min(g).min(b));
            hi - lo > 60
        })
        .count();
    assert!(
        total - white > total / 20,
        "map nearly blank: {white} of {total} white"
    );
    assert!(
        coloured > 2000,
        "too few coloured pixels (tracks, hulls): {coloured}"
    );
    let ((w, h), er, nr) = map_layout(&a.plot);
    let plot_w = f64::from(w - 110);
    let plot_h = f64::from(h) - 130.0;
    let mpp_e = (er.end - er.start) / plot_w;
    let mpp_n = (nr.end - nr.start) / plot_h;
    assert!((mpp_e / mpp_n - 1.0).abs() < 0.01, "{mpp_e} vs {mpp_n}");
}

#[test]
fn a_run_without_controller_log_still_plots() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(10.0, 0.1, 200);
    let (plant, _) = common::write_logs(&run, dir.path());
    let out = dir.path().join("r");
    let outcome = analyzer::report(&out, &[plant], true).expect("report");
    assert!(outcome.metrics.run.architecture.is_none());
    assert!(outcome
        .metrics
        .run
        .notes
        .iter()
        .any(|n| n.contains("no controller log")));
    for f in ["map.png", "states.svg", "towing.png", "report.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(!out.join("admm.png").exists());
}
