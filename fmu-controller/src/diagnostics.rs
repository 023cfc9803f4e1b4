//! The controller's outputs ([`Outputs`]: the commands and the diagnostics) and the table
//! of its diagnostic outputs ([`DIAGNOSTICS`]): one [`Diagnostic`] per output with its
//! name, value reference, FMI type, unit, description and getter. The model description's
//! diagnostic variables ([`variables`]) and the FMU's getters of them come from the table
//! alone; an output's start value is its getter's value on [`Outputs::default`].
//!
//! Value references of the diagnostics (unique per FMI base type):
//!
//! | range | what |
//! |---|---|
//! | 3000..=3041 | ADMM, timing, reference, guidance, desired angles |
//! | 3100 + 10 (k - 1) + j | COLREGS situation (j = 0) and role (j = 1) of obstacle slot k |
//! | 3200 + 10 (h - 1) + j | predicted positions after sample h = 1..=3 (j: ship x, y, tug1 x, y, tug2 x, y) |

use fmi2_slave::description::{Variable, VariableKind};
use fmi2_slave::LibraryLazy;
use fmi2_slave::ValueType;
use std::fmt;
use towing_control::{Command, SampleReport};
use towing_guidance::{Role, Situation};
use towing_interface::types::real_kind;
use towing_interface::variables::exact_output;
use towing_interface::VESSELS;
use towing_model::MAX_OBSTACLES;
use towing_mpc::HORIZON;

/// `admm.iterations` (Integer output).
pub const ADMM_ITERATIONS: u32 = 3000;
/// `admm.converged` (Boolean output).
pub const ADMM_CONVERGED: u32 = 3001;
/// `admm.primal_residual1/2` (Real outputs), tug 0 or 1.
pub const fn primal_residual(tug: u32) -> u32 {
    3002 + tug
}
/// `admm.dual_residual1/2` (Real outputs), tug 0 or 1.
pub const fn dual_residual(tug: u32) -> u32 {
    3004 + tug
}
/// `controller.compute_time` (Real output, s).
pub const COMPUTE_TIME: u32 = 3010;
/// `controller.fallbacks` (Integer output).
pub const FALLBACKS: u32 = 3011;
/// `controller.samples` (Integer output).
pub const SAMPLES: u32 = 3012;
/// `mpc.budget_hit` (Boolean output).
pub const BUDGET_HIT: u32 = 3013;
/// `reference.x`, `.y`, `.psi` (Real outputs), component 0..3.
pub const fn reference(component: u32) -> u32 {
    3020 + component
}
/// `guidance.active_waypoint` (Integer output).
pub const ACTIVE_WAYPOINT: u32 = 3030;
/// `guidance.altered` (Boolean output).
pub const ALTERED: u32 = 3031;
/// `guidance.d_ob` (Real output, m).
pub const D_OB: u32 = 3032;
/// `guidance.way_off` (Boolean output).
pub const WAY_OFF: u32 = 3033;
/// `towline1/2.angle_desired` (Real outputs, rad), line 0 or 1.
pub const fn angle_desired(line: u32) -> u32 {
    3040 + line
}
/// `colregs[k].situation` (Integer output), `slot` 0-based.
pub const fn colregs_situation(slot: u32) -> u32 {
    3100 + 10 * slot
}
/// `colregs[k].role` (Integer output), `slot` 0-based.
pub const fn colregs_role(slot: u32) -> u32 {
    3101 + 10 * slot
}
/// `prediction.<vessel>[h].x/.y` (Real outputs): `step` 0-based (h - 1), vessel 0 ship,
/// 1 tug1, 2 tug2; axis 0 x, 1 y.
pub const fn prediction(step: u32, vessel: u32, axis: u32) -> u32 {
    3200 + 10 * step + 2 * vessel + axis
}

/// `guidance.d_ob` when no obstacle is active (m): a large finite number, since FMI Real
/// outputs must be finite.
pub const NO_OBSTACLE_DISTANCE: f64 = 1e6;

/// The outputs: commands and diagnostics, holding their start values until the first step.
/// Part of the FMU state (serde).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Outputs {
    pub(crate) command: Command,
    pub(crate) iterations: i32,
    pub(crate) converged: bool,
    pub(crate) budget_hit: bool,
    pub(crate) r_pri: [f64; 2],
    pub(crate) r_dual: [f64; 2],
    pub(crate) compute_time: f64,
    pub(crate) fallbacks: i32,
    pub(crate) samples: i32,
    pub(crate) reference: [f64; 3],
    pub(crate) active_waypoint: i32,
    pub(crate) altered: bool,
    pub(crate) way_off: bool,
    pub(crate) d_ob: f64,
    pub(crate) angle_desired: [f64; 2],
    pub(crate) situation: [i32; MAX_OBSTACLES],
    pub(crate) role: [i32; MAX_OBSTACLES],
    /// `[h][vessel][axis]`.
    pub(crate) prediction: [[[f64; 2]; 3]; HORIZON],
}

impl Default for Outputs {
    fn default() -> Self {
        Self {
            command: Command::default(),
            iterations: 0,
            converged: false,
            budget_hit: false,
            r_pri: [0.0; 2],
            r_dual: [0.0; 2],
            compute_time: 0.0,
            fallbacks: 0,
            samples: 0,
            reference: [0.0; 3],
            active_waypoint: 0,
            altered: false,
            way_off: false,
            d_ob: NO_OBSTACLE_DISTANCE,
            angle_desired: [0.0; 2],
            situation: [-1; MAX_OBSTACLES],
            role: [0; MAX_OBSTACLES],
            prediction: [[[0.0; 2]; 3]; HORIZON],
        }
    }
}

fn saturating_i32<T: TryInto<i32>>(x: T) -> i32 {
    x.try_into().unwrap_or(i32::MAX)
}

impl Outputs {
    /// The diagnostics of the sample `r` (the commands are set by the step).
    pub(crate) fn record(&mut self, r: &SampleReport) {
        self.iterations = saturating_i32(r.iterations);
        self.converged = r.converged;
        self.budget_hit = r.budget_hit;
        self.r_pri = r.r_pri;
        self.r_dual = r.r_dual;
        self.compute_time = r.compute_time;
        self.fallbacks = saturating_i32(r.fallbacks);
        self.samples = self.samples.saturating_add(1);
        self.reference = r.reference;
        self.active_waypoint = saturating_i32(r.guidance.active_waypoint);
        self.altered = r.guidance.altered;
        self.way_off = r.guidance.way_off;
        self.d_ob = if r.guidance.d_ob.is_finite() {
            r.guidance.d_ob.min(NO_OBSTACLE_DISTANCE)
        } else {
            NO_OBSTACLE_DISTANCE
        };
        self.angle_desired = r.desired_angle;
        self.situation = r.situation.map(situation_code);
        self.role = r.role.map(role_code);
        for h in 0..HORIZON {
            let states = [
                &r.prediction.ship[h],
                &r.prediction.tugs[0][h],
                &r.prediction.tugs[1][h],
            ];
            for (vessel, s) in states.iter().enumerate() {
                self.prediction[h][vessel] = [s[0], s[1]];
            }
        }
    }
}

/// The FMI code of a COLREGS situation (`-1`: none, static hazard or empty slot).
#[must_use]
pub fn situation_code(s: Option<Situation>) -> i32 {
    s.map_or(-1, Situation::code)
}

/// The FMI code of the tow's role: 0 none, 1 give-way, 2 stand-on.
#[must_use]
pub fn role_code(r: Option<Role>) -> i32 {
    match r {
        None => 0,
        Some(Role::GiveWay) => 1,
        Some(Role::StandOn) => 2,
    }
}

/// How a diagnostic reads [`Outputs`]; the variant is its FMI type.
pub enum Getter {
    /// A Real output.
    Real(Box<dyn Fn(&Outputs) -> f64 + Send + Sync>),
    /// An Integer output, declared within `[min, max]`.
    Integer {
        /// The value.
        get: Box<dyn Fn(&Outputs) -> i32 + Send + Sync>,
        /// Declared minimum.
        min: i32,
        /// Declared maximum.
        max: i32,
    },
    /// A Boolean output.
    Boolean(Box<dyn Fn(&Outputs) -> bool + Send + Sync>),
}

impl fmt::Debug for Getter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Getter::Real(_) => f.write_str("Real"),
            Getter::Integer { min, max, .. } => write!(f, "Integer [{min}, {max}]"),
            Getter::Boolean(_) => f.write_str("Boolean"),
        }
    }
}

/// One diagnostic output of the controller (`causality="output"`, `initial="exact"`, no
/// dependency on the inputs).
#[derive(Debug)]
pub struct Diagnostic {
    /// FMI name.
    pub name: String,
    /// Value reference.
    pub value_reference: u32,
    /// Unit of a Real output (empty: dimensionless).
    pub unit: &'static str,
    /// Description for the model description.
    pub description: String,
    /// The getter; its variant is the FMI type.
    pub getter: Getter,
}

impl Diagnostic {
    fn real(
        name: String,
        value_reference: u32,
        unit: &'static str,
        description: String,
        get: impl Fn(&Outputs) -> f64 + Send + Sync + 'static,
    ) -> Self {
        Diagnostic {
            name,
            value_reference,
            unit,
            description,
            getter: Getter::Real(Box::new(get)),
        }
    }

    fn integer(
        name: String,
        value_reference: u32,
        (min, max): (i32, i32),
        description: String,
        get: impl Fn(&Outputs) -> i32 + Send + Sync + 'static,
    ) -> Self {
        Diagnostic {
            name,
            value_reference,
            unit: "",
            description,
            getter: Getter::Integer {
                get: Box::new(get),
                min,
                max,
            },
        }
    }

    fn boolean(
        name: String,
        value_reference: u32,
        description: String,
        get: impl Fn(&Outputs) -> bool + Send + Sync + 'static,
    ) -> Self {
        Diagnostic {
            name,
            value_reference,
            unit: "",
            description,
            getter: Getter::Boolean(Box::new(get)),
        }
    }

    /// The FMI base type.
    #[must_use]
    pub fn value_type(&self) -> ValueType {
        match self.getter {
            Getter::Real(_) => ValueType::Real,
            Getter::Integer { .. } => ValueType::Integer,
            Getter::Boolean(_) => ValueType::Boolean,
        }
    }

    /// The value in `outputs` of a Real diagnostic; `None` for another type.
    #[must_use]
    pub fn real_in(&self, outputs: &Outputs) -> Option<f64> {
        match &self.getter {
            Getter::Real(get) => Some(get(outputs)),
            _ => None,
        }
    }

    /// The value in `outputs` of an Integer diagnostic; `None` for another type.
    #[must_use]
    pub fn integer_in(&self, outputs: &Outputs) -> Option<i32> {
        match &self.getter {
            Getter::Integer { get, .. } => Some(get(outputs)),
            _ => None,
        }
    }

    /// The value in `outputs` of a Boolean diagnostic; `None` for another type.
    #[must_use]
    pub fn boolean_in(&self, outputs: &Outputs) -> Option<bool> {
        match &self.getter {
            Getter::Boolean(get) => Some(get(outputs)),
            _ => None,
        }
    }

    /// The model-description variable: start value the getter's on [`Outputs::default`].
    #[must_use]
    pub fn variable(&self) -> Variable {
        let start = Outputs::default();
        let kind = match &self.getter {
            Getter::Real(get) => real_kind(self.unit, Some(get(&start))),
            Getter::Integer { get, min, max } => VariableKind::Integer {
                declared_type: None,
                start: Some(get(&start)),
                min: Some(*min),
                max: Some(*max),
            },
            Getter::Boolean(get) => VariableKind::Boolean {
                start: Some(get(&start)),
            },
        };
        exact_output(
            self.name.clone(),
            self.value_reference,
            kind,
            self.description.clone(),
        )
    }
}

/// Counts from 0 (iterations, samples, a waypoint index).
const COUNT: (i32, i32) = (0, i32::MAX);

/// ADMM and timing: `admm.*`, `controller.*`.
fn solver() -> Vec<Diagnostic> {
    let mut v = vec![
        Diagnostic::integer(
            "admm.iterations".into(),
            ADMM_ITERATIONS,
            COUNT,
            "ADMM iterations of the last sample (the centralized architecture reports its SCP loop count)".into(),
            |o| o.iterations,
        ),
        Diagnostic::boolean(
            "admm.converged".into(),
            ADMM_CONVERGED,
            "true when the stopping rule eq. (29) ended the last sample's ADMM; false when it stopped at max_iterations (the last iterate, within every bound, is applied)".into(),
            |o| o.converged,
        ),
    ];
    for tug in 0..2u32 {
        let n = tug + 1;
        let i = tug as usize;
        v.push(Diagnostic::real(
            format!("admm.primal_residual{n}"),
            primal_residual(tug),
            "",
            format!("last primal residual |g_{n} - f_{n}|_2 of tug {n}'s consensus (Algorithm 1, eq. (29)), in the units of the pose [m, m, rad] stacked over the horizon; 0 in a sample at rest, 1.7976931348623157e308 (the largest finite value) when the iterate overflowed"),
            move |o| o.r_pri[i],
        ));
        v.push(Diagnostic::real(
            format!("admm.dual_residual{n}"),
            dual_residual(tug),
            "",
            format!("last dual residual |f_{n}^s - f_{n}^(s-1)|_2 of tug {n} (eq. (28) as printed, without rho); 0 in a sample at rest, 1.7976931348623157e308 (the largest finite value) when the iterate overflowed"),
            move |o| o.r_dual[i],
        ));
    }
    v.push(Diagnostic::boolean(
        "mpc.budget_hit".into(),
        BUDGET_HIT,
        "true when the last sample's optimisation was stopped by its time budget (mpc.sample_time_budget): the best iterate within every bound so far was applied".into(),
        |o| o.budget_hit,
    ));
    v.push(Diagnostic::real(
        "controller.compute_time".into(),
        COMPUTE_TIME,
        "s",
        "wall-clock time of the last sample (guidance and MPC); varies from run to run".into(),
        |o| o.compute_time,
    ));
    v.push(Diagnostic::integer(
        "controller.fallbacks".into(),
        FALLBACKS,
        COUNT,
        "samples since instantiation whose plan was replaced by the previous plan, shifted (each one is logged as a warning \"fallback: <reason>\", category logStatusWarning; fmi2DoStep returns fmi2Warning for it only with fmi.warning_on_fallback)".into(),
        |o| o.fallbacks,
    ));
    v.push(Diagnostic::integer(
        "controller.samples".into(),
        SAMPLES,
        COUNT,
        "control samples computed since initialization (one per sample_time, not per communication step)".into(),
        |o| o.samples,
    ));
    v
}

/// The reference and the guidance: `reference.*`, `guidance.*`, `towlineN.angle_desired`.
fn guidance() -> Vec<Diagnostic> {
    let mut v = Vec::new();
    for (c, (field, unit)) in [("x", "m"), ("y", "m"), ("psi", "rad")]
        .into_iter()
        .enumerate()
    {
        v.push(Diagnostic::real(
            format!("reference.{field}"),
            reference(c as u32),
            unit,
            format!("reference pose {field} the ship MPC tracked in the last sample (eta_Sd of eq. (8), or the route waypoint in avoidance_scheme 3)"),
            move |o| o.reference[c],
        ));
    }
    v.push(Diagnostic::integer(
        "guidance.active_waypoint".into(),
        ACTIVE_WAYPOINT,
        COUNT,
        "index of the active waypoint in the route (1 = W_P1; the last is the destination; 0 before the first sample)".into(),
        |o| o.active_waypoint,
    ));
    v.push(Diagnostic::boolean(
        "guidance.altered".into(),
        ALTERED,
        "true when the reference is the altered waypoint eta_Sn (eq. (10)-(11))".into(),
        |o| o.altered,
    ));
    v.push(Diagnostic::boolean(
        "guidance.way_off".into(),
        WAY_OFF,
        "true while the stand-on tow keeps the way off for a target under Rule 17 (docs/colregs.md, \"Rule 17: which action\"); the route is then kept".into(),
        |o| o.way_off,
    ));
    v.push(Diagnostic::real(
        "guidance.d_ob".into(),
        D_OB,
        "m",
        format!("smallest range-equivalent distance between the tow and any active obstacle (eq. (8)); {NO_OBSTACLE_DISTANCE:e} m when there is none"),
        |o| o.d_ob,
    ));
    for line in 0..2u32 {
        let i = line as usize;
        v.push(Diagnostic::real(
            format!("towline{}.angle_desired", line + 1),
            angle_desired(line),
            "rad",
            format!(
                "towing angle alpha_{} of the applied plan (the tug's formation reference)",
                line + 1
            ),
            move |o| o.angle_desired[i],
        ));
    }
    v
}

/// `colregs[k].situation` and `.role` of every obstacle slot.
fn colregs() -> Vec<Diagnostic> {
    let mut v = Vec::new();
    for slot in 0..MAX_OBSTACLES {
        let k = slot + 1;
        let vr_slot = slot as u32;
        v.push(Diagnostic::integer(
            format!("colregs[{k}].situation"),
            colregs_situation(vr_slot),
            (-1, 6),
            format!("COLREGS situation held for the encounter with obstacle slot {k} (0 safe before the tow detects the target or acts for it): -1 none (empty slot or static hazard), 0 safe, 1 head-on, 2 crossing give-way, 3 crossing stand-on, 4 overtaking, 5 being overtaken, 6 unclassified (docs/colregs.md)"),
            move |o| o.situation[slot],
        ));
        v.push(Diagnostic::integer(
            format!("colregs[{k}].role"),
            colregs_role(vr_slot),
            (0, 2),
            format!(
                "the tow's COLREGS role towards obstacle slot {k}: 0 none, 1 give-way, 2 stand-on"
            ),
            move |o| o.role[slot],
        ));
    }
    v
}

/// `prediction.<vessel>[h].x/.y` of every vessel over the horizon.
fn predictions() -> Vec<Diagnostic> {
    let mut v = Vec::new();
    for h in 0..HORIZON {
        for (vessel, (name, what)) in VESSELS.iter().enumerate() {
            for (axis, (field, position)) in [("x", "North position"), ("y", "East position")]
                .into_iter()
                .enumerate()
            {
                v.push(Diagnostic::real(
                    format!("prediction.{name}[{}].{field}", h + 1),
                    prediction(h as u32, vessel as u32, axis as u32),
                    "m",
                    format!(
                        "{what}: {position} predicted by the last sample's plan {} sample(s) ahead",
                        h + 1
                    ),
                    move |o| o.prediction[h][vessel][axis],
                ));
            }
        }
    }
    v
}

/// Every diagnostic output, in model-description order, built once.
pub static DIAGNOSTICS: LibraryLazy<Vec<Diagnostic>> = LibraryLazy::new(|| {
    let mut v = solver();
    v.extend(guidance());
    v.extend(colregs());
    v.extend(predictions());
    v
});

/// The model-description variables of [`DIAGNOSTICS`].
#[must_use]
pub fn variables() -> Vec<Variable> {
    DIAGNOSTICS.iter().map(Diagnostic::variable).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The start values of the model description are those of `Outputs::default`, which
    /// the FMU holds until its first step.
    #[test]
    fn start_values_are_the_default_outputs() {
        let start = Outputs::default();
        for d in DIAGNOSTICS.iter() {
            let v = d.variable();
            match (&v.kind, &d.getter) {
                (VariableKind::Real { start: s, .. }, Getter::Real(get)) => {
                    assert_eq!(*s, Some(get(&start)), "{}", d.name);
                }
                (VariableKind::Integer { start: s, .. }, Getter::Integer { get, .. }) => {
                    assert_eq!(*s, Some(get(&start)), "{}", d.name);
                }
                (VariableKind::Boolean { start: s }, Getter::Boolean(get)) => {
                    assert_eq!(*s, Some(get(&start)), "{}", d.name);
                }
                _ => panic!("{}: kind and getter differ", d.name),
            }
        }
        assert_eq!(
            DIAGNOSTICS.len(),
            2 + 4 + 4 + 3 + 4 + 2 + 2 * MAX_OBSTACLES + 6 * HORIZON
        );
    }
}
