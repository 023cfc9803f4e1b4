//! The plant log is analysed in bounded memory: whatever the log's length, the plot series
//! stay within their bounds, while every metric is computed on every plant step: equal to
//! its batch formula on the whole columns, and independent of the batch and plot sizes.

mod common;

use std::borrow::Cow;

use analyzer::analysis::PlotData;
use analyzer::metrics::{
    check_bounds, max_elongation_error, min_with_time, settling_time, travel, VesselTrack,
};
use analyzer::read::read_log;
use analyzer::stream::StreamOptions;
use analyzer::synth::SynthRun;
use indicatif::ProgressBar;

const SMALL: StreamOptions = StreamOptions {
    batch_steps: 500,
    plot_points: 64,
    track_rows: 64,
};

/// The longest plot line (points) and the most rows of a kept track.
fn plot_sizes(p: &PlotData) -> (usize, usize) {
    let lines = p
        .states
        .iter()
        .flatten()
        .chain(&p.tracks)
        .chain(&p.actual.angle_deg)
        .chain(&p.actual.tension)
        .chain(p.obstacles.iter().flat_map(|o| &o.distance))
        .map(Vec::len)
        .max()
        .unwrap_or(0);
    let rows = p
        .obstacles
        .iter()
        .map(|o| o.t.len())
        .chain([p.poses.t.len()])
        .max()
        .unwrap_or(0);
    (lines, rows)
}

#[test]
fn plot_series_stay_bounded_and_metrics_equal_the_whole_column_formulas() {
    for steps in [3_000usize, 24_000] {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut run = SynthRun::paper(steps);
        run.scene = false;
        let (m, (lines, rows)) = common::with_options(&run, dir.path(), &SMALL, |a| {
            (a.metrics.clone(), plot_sizes(&a.plot))
        });
        assert_eq!(m.run.plant_steps, steps + 1);
        // Bounded: at most `plot_points` per line, the strided rows plus the last one.
        assert!(lines <= SMALL.plot_points, "{steps} steps: {lines} points");
        assert!(rows <= SMALL.track_rows + 1, "{steps} steps: {rows} rows");
        assert!(lines >= SMALL.plot_points / 8 && rows > SMALL.track_rows / 2);

        // The batch and plot sizes change nothing in the metrics.
        let whole = StreamOptions {
            batch_steps: usize::MAX,
            ..StreamOptions::default()
        };
        let m2 = common::with_options(&run, dir.path(), &whole, |a| a.metrics.clone());
        assert_eq!(m, m2, "{steps} steps");

        // Every metric of the plant log equals its batch formula on the whole columns
        // (all topics of the synthetic log share their times: as-of joins are by index).
        let log = read_log(&dir.path().join("plant.mcap"), &ProgressBar::hidden()).expect("log");
        let p = &log.plant;
        let secs = |t: &[i64]| t.iter().map(|&t| t as f64 * 1e-9).collect::<Vec<f64>>();
        let t = secs(&p.ship.t_ns);
        let ship = VesselTrack {
            x: Cow::Borrowed(&p.ship.x),
            y: Cow::Borrowed(&p.ship.y),
            psi: Cow::Borrowed(&p.ship.psi),
            u: Cow::Borrowed(&p.ship.u),
            v: Cow::Borrowed(&p.ship.v),
            r: Cow::Borrowed(&p.ship.r),
        };
        let settle = settling_time(
            &t,
            &ship,
            m.config.destination,
            m.settling.settling_criteria,
        );
        assert_eq!(m.settling.settling_time_s, settle);
        // Arrives at 1057.5 s.
        assert_eq!(settle.is_some(), steps > 10_575);
        assert_eq!(
            m.travel.ship_travel_m.to_bits(),
            travel(&p.ship.x, &p.ship.y).to_bits()
        );
        for k in 0..2 {
            let line = &p.towlines[k];
            let e = max_elongation_error(
                &secs(&line.t_ns),
                &line.length,
                m.config.towline_desired_length[k],
            )
            .expect("elongation");
            assert_eq!(m.elongation.max_towline_elongation_error[k], Some(e.0));
            assert_eq!(m.elongation.max_towline_elongation_error_t_s[k], Some(e.1));
        }
        let ob = &p.obstacles;
        for o in &m.distances.normalized_min_distance {
            let rows: Vec<usize> = (0..ob.t_ns.len())
                .filter(|&i| ob.slot[i] == o.slot)
                .collect();
            let tt: Vec<f64> = rows.iter().map(|&i| ob.t_ns[i] as f64 * 1e-9).collect();
            for (v, cols) in [("ship", &p.ship), ("tug1", &p.tug1), ("tug2", &p.tug2)] {
                let d: Vec<f64> = rows
                    .iter()
                    .map(|&i| {
                        let j = cols.t_ns.partition_point(|&t| t <= ob.t_ns[i]) - 1;
                        (ob.x[i] - cols.x[j]).hypot(ob.y[i] - cols.y[j])
                    })
                    .collect();
                let (min, at) = min_with_time(&tt, &d).expect("distance");
                let got = &o.vessels[v];
                assert_eq!(
                    (got.min_distance_m, got.t_s),
                    (min, at),
                    "{} {v}",
                    o.obstacle
                );
            }
        }
        let inp = &p.inputs;
        let ti = secs(&inp.t_ns);
        let thrust = [
            [inp.tug1[0].as_slice(), &inp.tug1[1], &inp.tug1[2]],
            [inp.tug2[0].as_slice(), &inp.tug2[1], &inp.tug2[2]],
        ];
        let b = check_bounds(None, Some((&ti, thrust)), &m.config.bounds);
        assert_eq!(
            m.bounds.bound_violations.report.tug_thrust_input,
            b.tug_thrust_input
        );
        assert_eq!(b.tug_thrust_input.checked, 6 * (steps + 1));
    }
}
