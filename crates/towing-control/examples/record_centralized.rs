//! Records the centralized MPC's problems of a closed-loop run and replays them
//! with timing: the Rust half of the side-by-side baseline (CasADi + IPOPT
//! against `towing_mpc::Centralized`, `benches/baseline`, `docs/benchmarks.md`,
//! `cargo xtask bench-baseline`).
//!
//! ```text
//! record_centralized record [--from S] [--to S] [--samples N] [--scheme 1|2|3]
//!                           [--repeats N] --out DIR
//! record_centralized evaluate RECORDED.json PLANS.json --out FILE
//! ```
//!
//! `record` runs the paper scenario's closed loop (the plant's `World`,
//! communication step 0.1 s, `Architecture::Centralized`, scheme I unless told;
//! the loop of `examples/closed_loop.rs` and `benches/sample.rs`) from 0 s to
//! the window's end, and keeps for every control sample in `[from, to)` the exact
//! input the MPC was given ([`Controller::last_mpc_input`]) and the command the
//! loop applied. It writes:
//!
//! - `DIR/recorded.json`: `problem` (every parameter of the problem: weights,
//!   bounds, rates, clearance, penalties, `W_c`, sample time and RK4 substeps,
//!   hull matrices and damping, formation geometry) and `samples` (states,
//!   previous command, reference, obstacles as the MPC sees them, heading floor,
//!   and the loop's command);
//! - `DIR/ours.json`: the recorded inputs replayed in order through a fresh
//!   [`Centralized`] (cold at the window's first sample, then warm-started as in
//!   the loop: `shift()` after a sample, `reset()` where the loop fell back), each
//!   `solve_sample` timed alone (`Instant` around the call), `--repeats` times
//!   over the whole window (a fresh instance each time): per sample the times,
//!   SCP iterations, the merit, its breakdown, the last SCP step and the final plan.
//!
//! `evaluate` rebuilds the same problem (refusing a `problem` section that this
//! build would not write) and evaluates other solvers' plans (`PLANS.json`:
//! `{"samples": [{"plan": {"ship": [[F1, F2, a1, a2] x 3], "tugs": [[[X, Y, N] x
//! 3] x 2]}} | {"plan": null}, ...]}`, one per recorded sample from the first) with
//! [`Centralized::evaluate`], the merit the SCP minimises (`J_S + J_1 + J_2`
//! with the clearance penalties, plus `W_c sum |g_i - f_i|_1`).
//!
//! Floats are written by `serde_json` in their shortest round-trip form.
// A command-line tool: printing is its output.
#![allow(clippy::print_stdout, clippy::print_stderr)]

use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::{json, Value};
use towing_control::{
    Architecture, AvoidanceScheme, Controller, ControllerConfig, Measurement, MpcInput,
};
use towing_model::{HullModel, Scenario, VesselData, World, WorldInputs};
use towing_mpc::{
    AppliedCommand, CostBreakdown, Obstacle, SampleInput, ScpReport, ShipInput, TugInput, HORIZON,
};

/// Communication step of the loop (s), as the FMU masters use.
const STEP: f64 = 0.1;

type Res<T> = Result<T, Box<dyn Error>>;

/// `record`'s options.
#[derive(Debug, Clone)]
struct RecordOptions {
    from: f64,
    to: f64,
    scheme: AvoidanceScheme,
    repeats: usize,
    out: PathBuf,
}

/// One recorded control sample.
#[derive(Debug, Clone, Copy)]
struct Recorded {
    time: f64,
    input: MpcInput,
    /// The loop's applied first moves.
    ship: ShipInput,
    tugs: [TugInput; 2],
    fallback: bool,
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("record") => record(&parse_record(&args[1..])?),
        Some("evaluate") => evaluate(&args[1..]),
        other => Err(format!(
            "unknown mode {other:?}: use `record [--from S] [--to S] [--samples N] \
             [--scheme 1|2|3] [--repeats N] --out DIR` or `evaluate RECORDED.json PLANS.json \
             --out FILE`"
        )
        .into()),
    }
}

fn parse_record(args: &[String]) -> Res<RecordOptions> {
    let mut o = RecordOptions {
        from: 0.0,
        to: 1200.0,
        scheme: AvoidanceScheme::AlterAndCost,
        repeats: 1,
        out: PathBuf::new(),
    };
    let mut samples: Option<usize> = None;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it
            .next()
            .ok_or_else(|| format!("option {flag} needs a value"))?;
        let bad = |e: &dyn std::fmt::Display| format!("option {flag} {value}: {e}");
        match flag.as_str() {
            "--from" => o.from = value.parse().map_err(|e| bad(&e))?,
            "--to" => o.to = value.parse().map_err(|e| bad(&e))?,
            "--samples" => samples = Some(value.parse().map_err(|e| bad(&e))?),
            "--scheme" => {
                o.scheme = AvoidanceScheme::from_code(value.parse().map_err(|e| bad(&e))?)
                    .map_err(|e| bad(&e))?;
            }
            "--repeats" => o.repeats = value.parse().map_err(|e| bad(&e))?,
            "--out" => o.out = PathBuf::from(value),
            _ => return Err(format!("unknown option {flag}").into()),
        }
    }
    if let Some(n) = samples {
        o.to = o.from + n as f64;
    }
    if o.out.as_os_str().is_empty() {
        return Err("option --out DIR is required".into());
    }
    if !(o.from >= 0.0 && o.to > o.from && o.to.is_finite()) {
        return Err(format!("window [{}, {}) s is empty or negative", o.from, o.to).into());
    }
    if o.repeats == 0 {
        return Err("option --repeats must be >= 1".into());
    }
    Ok(o)
}

/// The controller's configuration for the benchmark: the paper scenario,
/// centralized, the given scheme, every other value at its default.
fn config_for(scheme: AvoidanceScheme) -> Res<ControllerConfig> {
    let mut config = ControllerConfig::new(Scenario::paper()?);
    config.tuning.architecture = Architecture::Centralized;
    config.tuning.scheme = scheme;
    Ok(config)
}

/// The closed loop from 0 s to `to`, recording the samples at `from <= t < to`.
fn run_loop(config: &ControllerConfig, from: f64, to: f64) -> Res<Vec<Recorded>> {
    let scenario = &config.scenario;
    let mut world = World::new(scenario, scenario.world_config)?;
    let mut controller = Controller::new(config.clone())?;
    let per_sample = (config.tuning.prediction.sample_time / STEP).round() as usize;
    let mut out = Vec::new();
    let mut n = 0usize;
    while world.time() < to - 1e-9 {
        let m = Measurement::from_world(&world);
        if n.is_multiple_of(per_sample) {
            let time = world.time();
            let r = controller.sample(&m)?;
            if time >= from - 1e-9 {
                let input = *controller
                    .last_mpc_input()
                    .ok_or("the controller kept no MPC input after a sample")?;
                out.push(Recorded {
                    time,
                    input,
                    ship: controller.applied().ship,
                    tugs: controller.applied().tugs,
                    fallback: r.fallback.is_some(),
                });
            }
        }
        let c = controller.command_at((n % per_sample) as f64 * STEP, &m)?;
        world.step(
            &WorldInputs {
                tug_tau: c.tug_thrust,
                tension_cmd: c.tension,
            },
            STEP,
        )?;
        n += 1;
    }
    Ok(out)
}

/// One replayed sample.
#[derive(Debug, Clone)]
struct Replayed {
    times_s: Vec<f64>,
    iterations: usize,
    converged: bool,
    failed: bool,
    merit: f64,
    breakdown: CostBreakdown,
    last_step: ScpReport,
    ship: [ShipInput; HORIZON],
    tugs: [[TugInput; HORIZON]; 2],
}

/// Replays `samples` in order `repeats` times through a fresh [`Centralized`]
/// each time, timing `solve_sample` alone; the plans of every repeat must agree
/// bit for bit (the solver is deterministic).
fn replay(config: &ControllerConfig, samples: &[Recorded], repeats: usize) -> Res<Vec<Replayed>> {
    let mut out: Vec<Replayed> = Vec::with_capacity(samples.len());
    for repeat in 0..repeats {
        let mut mpc = towing_control::centralized_mpc(config)?;
        for (k, s) in samples.iter().enumerate() {
            let input = s.input.as_sample_input();
            let start = Instant::now();
            let r = mpc.solve_sample(&input);
            let spent = start.elapsed().as_secs_f64();
            let ship = mpc.ship_plan();
            let tugs = [mpc.tug_plan(0), mpc.tug_plan(1)];
            if s.fallback || r.failed {
                mpc.reset();
            } else {
                mpc.shift();
            }
            if repeat == 0 {
                out.push(Replayed {
                    times_s: vec![spent],
                    iterations: r.iterations,
                    converged: r.converged,
                    failed: r.failed,
                    merit: r.cost,
                    breakdown: r.breakdown,
                    last_step: r.last_step,
                    ship,
                    tugs,
                });
            } else {
                let first = &mut out[k];
                if first.ship != ship || first.tugs != tugs {
                    return Err(format!(
                        "repeat {repeat} of sample {k} (t = {} s) gave another plan",
                        s.time
                    )
                    .into());
                }
                first.times_s.push(spent);
            }
        }
    }
    Ok(out)
}

fn record(o: &RecordOptions) -> Res<()> {
    let config = config_for(o.scheme)?;
    eprintln!(
        "record_centralized: closed loop 0-{} s (paper scenario, centralized, scheme {}), \
         recording [{}, {}) s",
        o.to,
        o.scheme.code(),
        o.from,
        o.to
    );
    let samples = run_loop(&config, o.from, o.to)?;
    eprintln!(
        "record_centralized: {} samples recorded; replaying {} time(s)",
        samples.len(),
        o.repeats
    );
    let replayed = replay(&config, &samples, o.repeats)?;
    let mpc = towing_control::centralized_mpc(&config)?;
    let mut same_as_loop = 0usize;
    let mut ours = Vec::with_capacity(samples.len());
    for (s, r) in samples.iter().zip(&replayed) {
        let evaluated = mpc.evaluate(&s.input.as_sample_input(), &r.ship, &r.tugs);
        let same = !s.fallback && r.ship[0] == s.ship && [r.tugs[0][0], r.tugs[1][0]] == s.tugs;
        same_as_loop += usize::from(same);
        ours.push(json!({
            "time": s.time,
            "times_s": r.times_s,
            "iterations": r.iterations,
            "converged": r.converged,
            "failed": r.failed,
            "merit": r.merit,
            "merit_evaluated": merit(&evaluated, &config),
            "breakdown": breakdown_json(&r.breakdown),
            "last_step": step_json(&r.last_step),
            "plan": plan_json(&r.ship, &r.tugs),
            "first_move_as_in_loop": same,
        }));
    }
    std::fs::create_dir_all(&o.out)
        .map_err(|e| format!("cannot create {}: {e}", o.out.display()))?;
    let recorded = json!({
        "config": config_json(&config),
        "problem": problem_json(&config)?,
        "samples": samples.iter().map(sample_json).collect::<Vec<_>>(),
    });
    write_json(&o.out.join("recorded.json"), &recorded)?;
    let summary = json!({
        "samples": ours,
        "first_moves_as_in_loop": same_as_loop,
        "repeats": o.repeats,
    });
    write_json(&o.out.join("ours.json"), &summary)?;
    eprintln!(
        "record_centralized: wrote {} and ours.json; replay's first move equals the loop's \
         in {same_as_loop} of {} samples",
        o.out.join("recorded.json").display(),
        samples.len()
    );
    Ok(())
}

/// The merit the SCP minimises, from a breakdown.
fn merit(b: &CostBreakdown, config: &ControllerConfig) -> f64 {
    b.total() + config.tuning.centralized.consensus_penalty * b.consensus_l1
}

fn write_json(path: &Path, value: &Value) -> Res<()> {
    let text = serde_json::to_string(value)?;
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()).into())
}

fn config_json(config: &ControllerConfig) -> Value {
    json!({
        "scenario": "paper",
        "architecture": config.tuning.architecture.code(),
        "scheme": config.tuning.scheme.code(),
        "hull_model": format!("{:?}", config.hull()),
    })
}

/// Hull matrices and the damping derivatives the prediction uses (the linear
/// hull uses only the five linear ones: the others are written as 0).
fn hull_json(hull: HullModel, data: &VesselData) -> Res<Value> {
    let built = hull.build(data)?;
    let m = built.mass_matrix();
    let mi = built.mass_matrix_inv();
    let rows = |a: &dyn Fn(usize, usize) -> f64| -> Vec<Vec<f64>> {
        (0..3).map(|r| (0..3).map(|c| a(r, c)).collect()).collect()
    };
    let linear = ["x_u", "y_v", "y_r", "n_v", "n_r"];
    let mut damping = serde_json::Map::new();
    for (name, value) in data.damping.fields() {
        let used = hull == HullModel::NonlinearDamping || linear.contains(&name);
        damping.insert(name.to_owned(), json!(if used { value } else { 0.0 }));
    }
    Ok(json!({
        "mass_matrix": rows(&|r, c| m[(r, c)]),
        "mass_matrix_inv": rows(&|r, c| mi[(r, c)]),
        "damping": damping,
        "bow_tow_point_x": data.bow_tow_point_x,
        "stern_tow_point_x": data.stern_tow_point_x,
        "length": data.length,
        "width": data.width,
    }))
}

/// Every parameter of the centralized problem (module docs).
fn problem_json(config: &ControllerConfig) -> Res<Value> {
    let s = &config.scenario;
    let (ship, tug) = towing_control::mpc_params(config);
    let p = &config.tuning.prediction;
    let distance = |d: &towing_mpc::DistanceCost| json!({"d_safe": d.d_safe, "epsilon": d.epsilon});
    let clearance = |c: &towing_mpc::ClearanceParams| {
        json!({"max_obstacles": c.max_obstacles, "min_distance": c.min_distance,
               "penalty": c.penalty, "max_slack": c.max_slack})
    };
    let c = &config.tuning.centralized;
    Ok(json!({
        "horizon": HORIZON,
        "sample_time": p.sample_time,
        "integration_step": p.integration_step,
        "substeps": p.substeps(),
        "substep": p.sample_time / p.substeps() as f64,
        "ship_hull": hull_json(config.hull(), &s.ship_data)?,
        "tug_hulls": [hull_json(config.hull(), &s.tug_data[0])?, hull_json(config.hull(), &s.tug_data[1])?],
        "towline_desired_length": s.towline_desired_length,
        "ship": {
            "pose_weights": ship.state_weights().0,
            "velocity_weights": ship.state_weights().1,
            "weight_distance": ship.weight_distance,
            "min_tension": ship.min_tension,
            "max_tension": ship.max_tension,
            "max_angle": ship.max_angle,
            "tension_rate": ship.tension_rate,
            "angle_rate": ship.angle_rate,
            "weight_towing_angle": ship.weight_towing_angle,
            "weight_tension": ship.weight_tension,
            "terminal": ship.terminal.map(|t| json!({"weight": t.weight, "horizon": t.horizon})),
            "distance": distance(&ship.distance),
            "clearance": clearance(&ship.clearance),
            "weight_port_turn": ship.weight_port_turn,
            "motion": {"max_drift": ship.motion.max_drift, "sway_allowance": ship.motion.sway_allowance,
                       "max_sternway": ship.motion.max_sternway, "max_speed": ship.motion.max_speed,
                       "penalty": ship.motion.penalty},
        },
        "tug": {
            "pose_weights": tug.state_weights().0,
            "velocity_weights": tug.state_weights().1,
            "weight_distance": tug.weight_distance,
            "thrust_limit": tug.thrust_limit,
            "distance": distance(&tug.distance),
            "clearance": clearance(&tug.clearance),
        },
        "centralized": {
            "consensus_penalty": c.consensus_penalty,
            "thrust_rate_weights": [c.weight_force_rate, c.weight_force_rate, c.weight_moment_rate],
            "max_iterations": c.max_iterations,
            "tolerance": c.tolerance,
        },
    }))
}

fn sample_json(s: &Recorded) -> Value {
    let i = &s.input;
    json!({
        "time": s.time,
        "ship": i.ship,
        "tugs": i.tugs,
        "previous": {"ship": i.previous.ship, "tugs": i.previous.tugs},
        "reference": i.reference,
        "heading_floor": i.heading_floor,
        "max_surge": i.max_surge,
        "obstacles": i.obstacles(),
        "distance_cost_off": i.distance_cost_off,
        "loop": {"ship": s.ship, "tugs": s.tugs, "fallback": s.fallback},
    })
}

fn plan_json(ship: &[ShipInput; HORIZON], tugs: &[[TugInput; HORIZON]; 2]) -> Value {
    json!({"ship": ship, "tugs": tugs})
}

/// The last SCP step of a sample (why it stopped).
fn step_json(s: &ScpReport) -> Value {
    json!({"qp": format!("{:?}", s.qp), "accepted": s.accepted, "cost_before": s.cost_before,
           "cost_after": s.cost_after, "predicted_decrease": s.predicted_decrease,
           "ratio": s.ratio, "radius": s.radius, "qp_iterations": s.qp_iterations})
}

fn breakdown_json(b: &CostBreakdown) -> Value {
    json!({"ship": b.ship, "tugs": b.tugs, "consensus_l1": b.consensus_l1,
           "consensus_max": b.consensus_max})
}

// ---- evaluate -------------------------------------------------------------

fn read_json(path: &str) -> Res<Value> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))?;
    serde_json::from_str(&text).map_err(|e| format!("{path} is not JSON: {e}").into())
}

/// `N` numbers at `v` (`what` names it in errors).
fn floats<const N: usize>(v: &Value, what: &str) -> Res<[f64; N]> {
    let a = v
        .as_array()
        .filter(|a| a.len() == N)
        .ok_or_else(|| format!("{what}: expected {N} numbers, got {v}"))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x
            .as_f64()
            .ok_or_else(|| format!("{what}: {x} is not a number"))?;
    }
    Ok(out)
}

/// A number or `null` (`None`) at `v`.
fn optional_float(v: &Value, what: &str) -> Res<Option<f64>> {
    match v {
        Value::Null => Ok(None),
        x => Ok(Some(
            x.as_f64()
                .ok_or_else(|| format!("{what}: {x} is not a number"))?,
        )),
    }
}

/// `[[f64; N]; M]` at `v`.
fn nested<const M: usize, const N: usize>(v: &Value, what: &str) -> Res<[[f64; N]; M]> {
    let a = v
        .as_array()
        .filter(|a| a.len() == M)
        .ok_or_else(|| format!("{what}: expected {M} rows, got {v}"))?;
    let mut out = [[0.0; N]; M];
    for (k, (o, row)) in out.iter_mut().zip(a).enumerate() {
        *o = floats(row, &format!("{what}[{k}]"))?;
    }
    Ok(out)
}

/// The MPC input of a recorded sample (the form `sample_json` writes).
fn input_from(v: &Value, k: usize) -> Res<MpcInput> {
    let what = format!("samples[{k}]");
    let obstacles = v["obstacles"]
        .as_array()
        .ok_or_else(|| format!("{what}.obstacles: not a list"))?
        .iter()
        .enumerate()
        .map(|(j, o)| {
            serde_json::from_value::<Obstacle>(o.clone())
                .map_err(|e| format!("{what}.obstacles[{j}]: {e}").into())
        })
        .collect::<Res<Vec<_>>>()?;
    let input = SampleInput {
        ship: floats(&v["ship"], &format!("{what}.ship"))?,
        tugs: nested(&v["tugs"], &format!("{what}.tugs"))?,
        previous: AppliedCommand {
            ship: floats(&v["previous"]["ship"], &format!("{what}.previous.ship"))?,
            tugs: nested(&v["previous"]["tugs"], &format!("{what}.previous.tugs"))?,
        },
        reference: nested(&v["reference"], &format!("{what}.reference"))?,
        obstacles: &obstacles,
        distance_cost_off: v["distance_cost_off"]
            .as_u64()
            .ok_or_else(|| format!("{what}.distance_cost_off: not an unsigned integer"))?,
        heading_floor: optional_float(&v["heading_floor"], &format!("{what}.heading_floor"))?,
        max_surge: optional_float(&v["max_surge"], &format!("{what}.max_surge"))?,
        waterway: None,
    };
    Ok(MpcInput::of(&input))
}

fn plan_from(v: &Value, what: &str) -> Res<([ShipInput; HORIZON], [[TugInput; HORIZON]; 2])> {
    let ship = nested(&v["ship"], &format!("{what}.ship"))?;
    let tugs = v["tugs"]
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or_else(|| format!("{what}.tugs: expected 2 plans"))?;
    Ok((
        ship,
        [
            nested(&tugs[0], &format!("{what}.tugs[0]"))?,
            nested(&tugs[1], &format!("{what}.tugs[1]"))?,
        ],
    ))
}

fn evaluate(args: &[String]) -> Res<()> {
    let [recorded_path, plans_path, flag, out] = args else {
        return Err("usage: evaluate RECORDED.json PLANS.json --out FILE".into());
    };
    if flag != "--out" {
        return Err(format!("expected --out FILE, got {flag}").into());
    }
    let recorded = read_json(recorded_path)?;
    let plans = read_json(plans_path)?;
    let scheme = recorded["config"]["scheme"]
        .as_i64()
        .ok_or_else(|| format!("{recorded_path}: config.scheme missing"))?;
    let config = config_for(AvoidanceScheme::from_code(scheme as i32)?)?;
    if recorded["problem"] != problem_json(&config)? {
        return Err(format!(
            "{recorded_path}: its problem section differs from the problem this build \
             solves (recorded with other parameters or another version): record it again"
        )
        .into());
    }
    let samples = recorded["samples"]
        .as_array()
        .ok_or_else(|| format!("{recorded_path}: samples missing"))?;
    // The plans of the first samples (a solver run on a prefix of the window).
    let given = plans["samples"]
        .as_array()
        .filter(|p| p.len() <= samples.len())
        .ok_or_else(|| {
            format!(
                "{plans_path}: expected a list `samples` of at most {} entries",
                samples.len()
            )
        })?;
    let mpc = towing_control::centralized_mpc(&config)?;
    let mut out_samples = Vec::with_capacity(given.len());
    for (k, (s, p)) in samples.iter().zip(given).enumerate() {
        if p["plan"].is_null() {
            out_samples.push(json!({"merit": null, "breakdown": null}));
            continue;
        }
        let input = input_from(s, k)?;
        let (ship, tugs) = plan_from(&p["plan"], &format!("{plans_path}: samples[{k}].plan"))?;
        let b = mpc.evaluate(&input.as_sample_input(), &ship, &tugs);
        out_samples.push(json!({"merit": merit(&b, &config), "breakdown": breakdown_json(&b)}));
    }
    write_json(Path::new(out), &json!({"samples": out_samples}))?;
    eprintln!(
        "record_centralized: evaluated {} plans into {out}",
        given.len()
    );
    Ok(())
}
