//! Closed loop in Rust, without FMI: the plant's `World` and the controller,
//! communication step 0.1 s. A development tool and a reference for the FMU runs.
//!
//! `cargo run --release -p towing-control --example closed_loop -- [stop_s] [scheme] [csv]`
//! (`SCENARIO=file.toml` runs that scenario instead of the paper's; `DRIFT_LOG=1`
//! prints the controller's state where each drift excursion over 30 deg begins; the
//! other environment knobs are read in `main`).
// A command-line tool: printing is its output.
#![allow(clippy::print_stdout, clippy::print_stderr)]

use std::io::Write;

use towing_control::{AvoidanceScheme, Controller, ControllerConfig, Measurement};
use towing_model::{ObstacleKind, Scenario, World, WorldInputs};

/// Hull outline (rectangle `length x width` at the pose) as boundary samples.
fn rect_points(eta: [f64; 3], length: f64, width: f64) -> Vec<[f64; 2]> {
    let (sn, cs) = eta[2].sin_cos();
    let mut pts = Vec::new();
    let n = 16;
    for k in 0..n {
        let t = k as f64 / n as f64;
        for (a, b) in [
            (-0.5 + t, -0.5),
            (0.5, -0.5 + t),
            (0.5 - t, 0.5),
            (-0.5, 0.5 - t),
        ] {
            let (bx, by) = (a * length, b * width);
            pts.push([eta[0] + cs * bx - sn * by, eta[1] + sn * bx + cs * by]);
        }
    }
    pts
}

fn in_rect(p: [f64; 2], eta: [f64; 3], length: f64, width: f64) -> bool {
    let (sn, cs) = eta[2].sin_cos();
    let (dx, dy) = (p[0] - eta[0], p[1] - eta[1]);
    let (bx, by) = (cs * dx + sn * dy, -sn * dx + cs * dy);
    bx.abs() <= 0.5 * length && by.abs() <= 0.5 * width
}

/// Overlap of the tow's hulls with the obstacles and with each other.
fn overlaps(world: &World, scenario: &Scenario) -> Vec<String> {
    let hulls = [
        (
            "ship",
            world.ship().eta,
            scenario.ship_data.length,
            scenario.ship_data.width,
        ),
        (
            "tug1",
            world.tug(0).eta,
            scenario.tug_data[0].length,
            scenario.tug_data[0].width,
        ),
        (
            "tug2",
            world.tug(1).eta,
            scenario.tug_data[1].length,
            scenario.tug_data[1].width,
        ),
    ];
    let mut out = Vec::new();
    for (name, eta, l, w) in hulls {
        let pts = rect_points(eta, l, w);
        for k in 0..towing_model::MAX_OBSTACLES {
            let o = world.obstacle(k);
            let hit = match o.kind {
                ObstacleKind::StaticCircle => {
                    let r = 0.5 * o.length.max(o.width);
                    pts.iter().any(|p| (p[0] - o.x).hypot(p[1] - o.y) < r)
                        || in_rect([o.x, o.y], eta, l, w)
                }
                ObstacleKind::VesselEllipse => {
                    let (a, b) = (0.5 * o.length, 0.5 * o.width);
                    let (sn, cs) = o.psi.sin_cos();
                    let inside = |p: &[f64; 2]| {
                        let (dx, dy) = (p[0] - o.x, p[1] - o.y);
                        let (ex, ey) = (cs * dx + sn * dy, -sn * dx + cs * dy);
                        (ex / a).powi(2) + (ey / b).powi(2) < 1.0
                    };
                    let ell: Vec<[f64; 2]> = (0..64)
                        .map(|k| {
                            let t = k as f64 / 64.0 * std::f64::consts::TAU;
                            let (ex, ey) = (a * t.cos(), b * t.sin());
                            [o.x + cs * ex - sn * ey, o.y + sn * ex + cs * ey]
                        })
                        .collect();
                    pts.iter().any(inside) || ell.iter().any(|p| in_rect(*p, eta, l, w))
                }
                _ => false,
            };
            if hit {
                out.push(format!("{name} x obstacle[{}]", k + 1));
            }
        }
    }
    for i in 0..3 {
        for j in i + 1..3 {
            let (ni, ei, li, wi) = hulls[i];
            let (nj, ej, lj, wj) = hulls[j];
            if rect_points(ei, li, wi)
                .iter()
                .any(|p| in_rect(*p, ej, lj, wj))
                || rect_points(ej, lj, wj)
                    .iter()
                    .any(|p| in_rect(*p, ei, li, wi))
            {
                out.push(format!("{ni} x {nj}"));
            }
        }
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let stop: f64 = args.get(1).map_or(Ok(1200.0), |s| s.parse())?;
    let scheme = AvoidanceScheme::from_code(args.get(2).map_or(Ok(1), |s| s.parse())?)?;
    let mut scenario = match std::env::var("SCENARIO") {
        Ok(path) => Scenario::from_file(path)?,
        Err(_) => Scenario::paper()?,
    };
    if std::env::var("NO_OBST").is_ok() {
        scenario.obstacles.clear();
    }
    let mut world = World::new(&scenario, scenario.world_config)?;
    let mut config = ControllerConfig::new(scenario.clone());
    config.tuning.scheme = scheme;
    if let Ok(g) = std::env::var("INNER_GAIN") {
        let g: f64 = g.parse()?;
        config.tuning.inner.gain = [g, g, g];
    }
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(v) = env("W_F") {
        config.tuning.ship.weight_tension = v;
    }
    if let Some(v) = env("W_A") {
        config.tuning.ship.weight_towing_angle = v;
    }
    if let Some(v) = env("F_MIN") {
        config.tuning.ship.min_tension = v;
    }
    if let Some(v) = env("ACCEPT") {
        config.tuning.guidance.acceptance_radius = v;
    }
    if let Some(v) = env("PARALLEL") {
        config.tuning.admm.parallel_tugs = v != 0.0;
    }
    if let Some(v) = env("MOTION_PENALTY") {
        config.tuning.ship.motion.penalty = v;
    }
    if let Some(v) = env("MAX_DRIFT") {
        config.tuning.ship.motion.max_drift = v.to_radians();
    }
    if let Some(v) = env("RHO") {
        config.tuning.admm.rho = v;
    }
    if let Some(v) = env("LOS") {
        config.tuning.tracking.los_distance = v;
    }
    if let Some(v) = env("LOOKAHEAD") {
        config.tuning.tracking.lookahead = v;
    }
    if let Some(v) = env("W_S1") {
        config.tuning.ship.weight_position = v;
        config.tuning.ship.weight_heading = v;
    }
    if let Some(v) = env("W_S2") {
        config.tuning.ship.weight_surge = v;
        config.tuning.ship.weight_sway = v;
    }
    if let Some(v) = env("W_T2") {
        config.tuning.tug.weight_surge = v;
        config.tuning.tug.weight_sway = v;
        config.tuning.tug.weight_yaw_rate = v;
    }
    if let Some(v) = env("W_PSI") {
        config.tuning.ship.weight_heading = v;
    }
    if let Some(v) = env("COURSE_RATE") {
        config.tuning.tracking.course_rate = v.to_radians();
    }
    if let Some(v) = env("COURSE_LEAD") {
        config.tuning.tracking.course_lead = v.to_radians();
    }
    if let Some(v) = env("W_R") {
        config.tuning.ship.weight_yaw_rate = v;
    }
    if let Some(v) = env("R17_TCPA") {
        config.tuning.guidance.colregs.rule17.tcpa = v;
    }
    if let Some(v) = env("R17_WO") {
        config.tuning.guidance.colregs.rule17.way_off_speed = v;
    }
    if let Some(v) = env("R17_DEC") {
        config.tuning.guidance.colregs.rule17.way_off_deceleration = v;
    }
    if let Some(v) = env("R17_DCPA") {
        config.tuning.guidance.colregs.rule17.dcpa = v;
    }
    if let Some(v) = env("ARCH") {
        config.tuning.architecture = towing_control::Architecture::from_code(v as i32)?;
    }
    if let Some(v) = env("EPS") {
        config.tuning.ship.distance.epsilon = v;
        config.tuning.tug.distance.epsilon = v;
    }
    if let Some(v) = env("CENT_TOL") {
        config.tuning.centralized.tolerance = v;
    }
    if let Some(v) = env("CENT_GOOD") {
        config.tuning.centralized.scp.good = v;
    }
    if let Some(v) = env("CENT_POOR") {
        config.tuning.centralized.scp.poor = v;
    }
    if let Some(v) = env("GW_LA") {
        config.tuning.tracking.give_way_lookahead = v;
    }
    if let Some(v) = env("GW_SURGE") {
        config.tuning.tracking.give_way_surge = v;
    }
    if let Some(v) = env("TUG_NMAX") {
        config.tuning.tug.thrust_limit[2] = v;
    }
    if let Some(v) = env("TUG_TR_N") {
        config.tuning.tug.trust_scale[2] = v;
    }
    if let Some(v) = env("TUG_RMAX") {
        config.tuning.tug.max_yaw_rate = v;
    }
    if let Some(v) = env("TOW_ROWS") {
        config.tuning.tug.tow_rows = v > 0.0;
    }
    if let Some(v) = env("OTHER_TUG_ROW") {
        config.tuning.tug.other_tug_row = v > 0.0;
    }
    if let Some(v) = env("PT_W") {
        config.tuning.ship.weight_port_turn = v;
    }
    if let Some(v) = env("PT_M") {
        config.tuning.tracking.port_turn_margin = v.to_radians();
    }
    if let Some(v) = env("TUG_RW") {
        config.tuning.centralized.weight_force_rate = v;
        config.tuning.centralized.weight_moment_rate = v;
    }
    if let Some(v) = env("SHIP_DRIFT") {
        config.tuning.ship.motion.max_drift = v.to_radians();
    }
    if let Some(v) = env("SHIP_VMAX") {
        config.tuning.ship.motion.max_speed = v;
    }
    if let Some(v) = env("RULE17_TCPA") {
        config.tuning.guidance.colregs.rule17.tcpa = v;
    }
    if let Some(v) = env("THETA") {
        config.tuning.guidance.altering_angle = v.to_radians();
    }
    if let Some(v) = env("CENT_IT") {
        config.tuning.centralized.max_iterations = v as usize;
    }
    if let (Some(w), Some(t)) = (env("TERM_W"), env("TERM_T")) {
        config.tuning.ship.terminal = Some(towing_mpc::TerminalCost {
            weight: w,
            horizon: t,
        });
    }
    let mut controller = Controller::new(config)?;
    let mut csv = match args.get(3) {
        Some(path) => Some(std::io::BufWriter::new(std::fs::File::create(path)?)),
        None => None,
    };
    let h = 0.1;
    let steps = (stop / h).round() as usize;
    let per_sample = 10;
    let mut times = Vec::new();
    let mut iters = Vec::new();
    let mut not_converged = 0;
    let mut min_clear = f64::INFINITY;
    let dest = scenario.route.destination;
    let mut settled_since: Option<f64> = None;
    let mut collisions = 0usize;
    // Per obstacle slot: (CPA distance, time, relative bearing in deg) of target ships.
    let mut cpa: [(f64, f64, f64); towing_model::MAX_OBSTACLES] =
        [(f64::INFINITY, 0.0, 0.0); towing_model::MAX_OBSTACLES];
    let mut max_tug_r = 0.0f64;
    // DRIFT_LOG: the context of each drift excursion (drift > 30 deg at >= 0.05 m/s).
    let drift_log = std::env::var("DRIFT_LOG").is_ok();
    let mut in_drift = false;
    let mut last_report: Option<towing_control::SampleReport> = None;
    let wall = std::time::Instant::now();
    for n in 0..steps {
        let m = Measurement::from_world(&world);
        let step = controller.step(world.time(), &m)?;
        if let Some(r) = step.sample {
            last_report = Some(r);
            times.push(r.compute_time * 1e3);
            iters.push(r.iterations);
            not_converged += usize::from(!r.converged);
            if let (Ok(a), Ok(b)) = (
                std::env::var("TRACE_FROM").map(|v| v.parse::<f64>().unwrap_or(0.0)),
                std::env::var("TRACE_TO").map(|v| v.parse::<f64>().unwrap_or(0.0)),
            ) {
                let t = world.time();
                if t >= a && t <= b {
                    let (sp, cp) = m.ship[2].sin_cos();
                    let rel = |p: &[f64; 6]| {
                        let (dx, dy) = (p[0] - m.ship[0], p[1] - m.ship[1]);
                        (cp * dx + sp * dy, -sp * dx + cp * dy)
                    };
                    let (f2, l2) = rel(&m.tugs[1]);
                    let (f1, l1) = rel(&m.tugs[0]);
                    eprintln!("t {t:6.1} psi {:6.1} r {:6.3} drift {:6.1} sog {:.3} | T {:.2} {:.2} at {:5.1} {:5.1} | F {:.2} {:.2} a {:6.1} {:6.1} | tug2 rel ({f2:5.2},{l2:5.2}) psi {:6.1} nu ({:.3},{:.3},{:.3}) tau {:?} | tug1 rel ({f1:5.2},{l1:5.2}) tau {:?} | it {} rp {:.1e} rd {:.1e} | pred ship ({:.2},{:.2},{:.1}) pdrift {:.1} {:.1} {:.1}",
                        m.ship[2].to_degrees(), m.ship[5], m.ship[4].atan2(m.ship[3]).to_degrees(), m.ship[3].hypot(m.ship[4]), world.towline(0).tension, world.towline(1).tension, world.towline(0).angle.to_degrees(), world.towline(1).angle.to_degrees(), r.command.tension[0], r.command.tension[1], r.desired_angle[0].to_degrees(), r.desired_angle[1].to_degrees(),
                        m.tugs[1][2].to_degrees(), m.tugs[1][3], m.tugs[1][4], m.tugs[1][5], r.command.tug_thrust[1].map(|v| (v * 100.0).round() / 100.0), r.command.tug_thrust[0].map(|v| (v * 100.0).round() / 100.0),
                        r.iterations, r.r_pri[1], r.r_dual[1], r.prediction.ship[2][0], r.prediction.ship[2][1], r.prediction.ship[2][2].to_degrees(), r.prediction.ship[0][4].atan2(r.prediction.ship[0][3]).to_degrees(), r.prediction.ship[1][4].atan2(r.prediction.ship[1][3]).to_degrees(), r.prediction.ship[2][4].atan2(r.prediction.ship[2][3]).to_degrees());
                }
            }
            if std::env::var("DEBUG").is_ok() && n % (per_sample * 5) == 0 {
                eprintln!(
                    "t {:6.1} ref ({:6.2},{:6.2},{:6.1}) wp {} alt {} F ({:.2},{:.2}) a ({:5.1},{:5.1}) act ({:5.1},{:5.1}) tau1 {:?} tau2 {:?} it {} ship ({:6.2},{:6.2},{:6.1}) u {:.3} v {:.3} r {:.3}",
                    world.time(), r.reference[0], r.reference[1], r.reference[2].to_degrees(),
                    r.guidance.active_waypoint, r.guidance.altered, r.command.tension[0], r.command.tension[1],
                    r.desired_angle[0].to_degrees(), r.desired_angle[1].to_degrees(),
                    world.towline(0).angle.to_degrees(), world.towline(1).angle.to_degrees(),
                    r.command.tug_thrust[0].map(|v| (v * 100.0).round() / 100.0), r.command.tug_thrust[1].map(|v| (v * 100.0).round() / 100.0), r.iterations,
                    m.ship[0], m.ship[1], m.ship[2].to_degrees(), m.ship[3], m.ship[4], m.ship[5]
                );
            }
            if std::env::var("GOV").is_ok() {
                if let Some(g) = r.guidance.governing {
                    eprintln!("GOV t {:.1} alt {} wo {} u {:.3} idx {} range {:.2} d9 {:.2} sit {:?} act {:?} det {} pc {} crossed {} man {:?} beta {:?}",
                        world.time(), r.guidance.altered, r.guidance.way_off, m.ship[3], g.index, g.range, g.distance_eq9, g.situation, g.action, g.detected, g.past_and_clear, g.crossed, g.manoeuvre,
                        g.encounter.map(|e| (e.bearing.to_degrees() * 10.0).round() / 10.0));
                }
            }
            if std::env::var("MASK").is_ok() {
                if let Some(i) = controller.last_mpc_input() {
                    let obs: Vec<String> = i
                        .obstacles()
                        .iter()
                        .enumerate()
                        .map(|(j, o)| {
                            let (d, _) = o.distance([m.ship[0], m.ship[1]]);
                            format!(
                                "{}{:.1}",
                                if i.distance_cost_off & (1 << j) != 0 {
                                    "-"
                                } else {
                                    "+"
                                },
                                d
                            )
                        })
                        .collect();
                    let tg: Vec<String> = (0..towing_model::MAX_OBSTACLES)
                        .filter_map(|k| {
                            let o = world.obstacle(k);
                            (o.kind == ObstacleKind::VesselEllipse).then(|| {
                                let (dx, dy) = (o.x - m.ship[0], o.y - m.ship[1]);
                                format!(
                                    "[{k}: r {:.2} b {:.0}]",
                                    dx.hypot(dy),
                                    towing_model::wrap_angle(dy.atan2(dx) - m.ship[2]).to_degrees()
                                )
                            })
                        })
                        .collect();
                    eprintln!("MASK t {:.1} psi {:.1} u {:.3} ref {:.1} floor {:?} alt {} wo {} obs {} {}", world.time(), m.ship[2].to_degrees(), m.ship[3], r.reference[2].to_degrees(), r.heading_floor.map(|f| (f.to_degrees() * 10.0).round() / 10.0), r.guidance.altered, r.guidance.way_off, obs.join(" "), tg.join(" "));
                }
            }
            if let Some(why) = r.fallback {
                eprintln!("t = {:.1}: fallback: {why}", world.time());
            }
        }
        let c = step.command;
        world.step(
            &WorldInputs {
                tug_tau: c.tug_thrust,
                tension_cmd: c.tension,
            },
            h,
        )?;
        max_tug_r = max_tug_r.max(world.tug(0).nu[2].abs().max(world.tug(1).nu[2].abs()));
        if drift_log {
            let s = world.ship();
            let drifting =
                s.nu[0].hypot(s.nu[1]) >= 0.05 && s.nu[1].atan2(s.nu[0]).abs() > 30f64.to_radians();
            if drifting && !in_drift {
                if let Some(r) = &last_report {
                    eprintln!(
                        "DRIFT t {:.1} psi {:.1} ref {:.1} floor {:?} alt {} sit {:?} u {:.3} v {:.3} r {:.3} F ({:.2},{:.2}) a ({:.1},{:.1}) wp {}",
                        world.time(), s.eta[2].to_degrees(), r.reference[2].to_degrees(),
                        r.heading_floor.map(|f| (f.to_degrees() * 10.0).round() / 10.0),
                        r.guidance.altered, r.guidance.governing.and_then(|g| g.situation),
                        s.nu[0], s.nu[1], s.nu[2], r.command.tension[0], r.command.tension[1],
                        r.desired_angle[0].to_degrees(), r.desired_angle[1].to_degrees(), r.guidance.active_waypoint
                    );
                }
            }
            in_drift = drifting;
        }
        if let Some(f) = csv.as_mut() {
            let s = world.ship();
            let (t1, t2) = (world.tug(0), world.tug(1));
            writeln!(
                f,
                "{:.1},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                world.time(),
                s.eta[0],
                s.eta[1],
                s.eta[2],
                s.nu[0],
                s.nu[1],
                s.nu[2],
                t1.eta[0],
                t1.eta[1],
                t1.eta[2],
                t2.eta[0],
                t2.eta[1],
                t2.eta[2],
                c.tension[0],
                c.tension[1]
            )?;
        }
        {
            let s = world.ship();
            let ok = (s.eta[0] - dest.x).hypot(s.eta[1] - dest.y)
                <= 0.5 * scenario.ship_data.length
                && towing_model::wrap_angle(s.eta[2] - dest.psi).abs() <= 3f64.to_radians()
                && s.nu[0].abs() < 0.01
                && s.nu[1].abs() < 0.01
                && s.nu[2].abs() < 0.01;
            if !ok {
                settled_since = None;
            } else if settled_since.is_none() {
                settled_since = Some(world.time());
            }
        }
        for (k, c) in cpa.iter_mut().enumerate() {
            let o = world.obstacle(k);
            if o.kind != ObstacleKind::VesselEllipse {
                continue;
            }
            let s = world.ship().eta;
            let (dx, dy) = (o.x - s[0], o.y - s[1]);
            let d = dx.hypot(dy);
            if d < c.0 {
                *c = (
                    d,
                    world.time(),
                    towing_model::wrap_angle(dy.atan2(dx) - s[2]).to_degrees(),
                );
            }
        }
        if n % 5 == 0 {
            for o in overlaps(&world, &scenario) {
                collisions += 1;
                if collisions <= 5 {
                    eprintln!("t = {:.1}: overlap {o}", world.time());
                }
            }
        }
        // Clearance to every active obstacle (centre distance minus radius, crude).
        for k in 0..towing_model::MAX_OBSTACLES {
            let o = world.obstacle(k);
            if o.kind == ObstacleKind::None {
                continue;
            }
            for p in [world.ship().eta, world.tug(0).eta, world.tug(1).eta] {
                let d = (p[0] - o.x).hypot(p[1] - o.y) - 0.5 * o.length.max(o.width);
                min_clear = min_clear.min(d);
            }
        }
    }
    let sides: Vec<String> = cpa
        .iter()
        .enumerate()
        .filter(|(_, c)| c.0.is_finite())
        .map(|(k, c)| {
            format!(
                "obstacle[{}] CPA {:.2} m at {:.0} s bearing {:.0} ({})",
                k + 1,
                c.0,
                c.1,
                c.2,
                if c.2 < 0.0 { "port" } else { "STARBOARD" }
            )
        })
        .collect();
    println!("{}", sides.join("; "));
    times.sort_by(f64::total_cmp);
    iters.sort_unstable();
    let s = world.ship();
    println!(
        "end t={:.0}: ship at ({:.2}, {:.2}) psi {:.1} deg, u {:.3}; wall {:.2} s; sample ms median {:.2} p99 {:.2} max {:.2}; iterations median {} p99 {} max {}; not converged {}; fallbacks {}; min crude clearance {:.2} m; settled at {:?}; overlaps {}; max tug yaw rate {:.2} rad/s",
        world.time(), s.eta[0], s.eta[1], s.eta[2].to_degrees(), s.nu[0], wall.elapsed().as_secs_f64(),
        times[times.len() / 2], times[times.len() * 99 / 100], times[times.len() - 1],
        iters[iters.len() / 2], iters[iters.len() * 99 / 100], iters[iters.len() - 1], not_converged,
        controller.fallbacks(), min_clear, settled_since, collisions, max_tug_r
    );
    Ok(())
}
