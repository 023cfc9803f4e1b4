//! The closed loop of the packaged FMUs through a Rust importer (fmi-rs 0.3), in either
//! coupling, for the integration tests (`tests/tests/fmi_rs.rs`) and the cross-check of the
//! masters (`examples/closed_loop_csv.rs`, read by `tests/python/test_systems.py`).
//!
//! Connections by identical names, as `masters/closed_loop.py` makes them: every controller
//! input takes the plant output of the same name, every plant input the controller output of
//! the same name; an input without such an output, or of another type, is an error.
//! Initialization as in that master: the plant is initialized first, its outputs are set on
//! the controller in the controller's initialization mode, and the controller's outputs after
//! its initialization are set on the plant.

use fmi_rs::fmi2::builder::FMU2Builder;
use fmi_rs::fmi2::types::{fmi2FMUstate, fmi2Status};
use fmi_rs::fmi2::{CS, FMU2};
use fmi_rs::model_description::fmi2::{Causality, ModelDescription, VariableType};
use std::path::Path;
use std::sync::Arc;

/// Order of the two FMUs within a communication step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// The controller steps on the plant's outputs at t, then the plant steps with the
    /// controller's new outputs (`masters/closed_loop.py`'s default).
    GaussSeidel,
    /// Both step on the other's outputs at t; outputs are exchanged after both steps
    /// (libcosim's fixed-step algorithm, fmpy's SSP runner).
    Jacobi,
}

impl std::str::FromStr for Coupling {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "gauss-seidel" => Ok(Self::GaussSeidel),
            "jacobi" => Ok(Self::Jacobi),
            other => Err(format!(
                "unknown coupling {other:?} (gauss-seidel or jacobi)"
            )),
        }
    }
}

/// Initial values of the connected inputs before the first step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitialInputs {
    /// The other FMU's outputs after initialization (every master of this workspace and
    /// libcosim).
    Exchanged,
    /// Every connected input 0 at the first step and nothing exchanged during
    /// initialization: what fmpy's SSP runner (`fmpy.ssp.simulate_ssp`) does, to reproduce
    /// its trajectory.
    Zero,
}

/// A closed-loop run: `columns` = `time`, every plant output, every controller output (in
/// modelDescription order, Integer and Boolean outputs as numbers); `rows[k]` at t = k h:
/// row 0 after initialization, row k after the k-th communication step.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    /// Names of the controller inputs fed by the plant, and of the plant inputs fed by the
    /// controller.
    pub to_controller: Vec<String>,
    pub to_plant: Vec<String>,
    /// fmi2Warning statuses returned (an MPC fallback only with the controller's
    /// `fmi.warning_on_fallback`; `controller.fallbacks` counts them all).
    pub warnings: usize,
}

impl Trajectory {
    /// The values of one column over time.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[i]).collect())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Real,
    Integer,
    Boolean,
}

fn kind(v: &VariableType) -> Option<Kind> {
    match v {
        VariableType::Real { .. } => Some(Kind::Real),
        VariableType::Integer { .. } | VariableType::Enumeration { .. } => Some(Kind::Integer),
        VariableType::Boolean { .. } => Some(Kind::Boolean),
        _ => None,
    }
}

const KINDS: [Kind; 3] = [Kind::Real, Kind::Integer, Kind::Boolean];

/// The connected inputs per kind (Real, Integer, Boolean): the index of each one's source
/// among the sender's outputs of that kind, and its value reference (set in one call).
#[derive(Default)]
struct Inputs {
    source: [Vec<usize>; 3],
    vr: [Vec<u32>; 3],
}

/// One instance with its outputs (read once per step, by type) and its connected inputs.
struct Unit {
    name: &'static str,
    fmu: Arc<FMU2<CS>>,
    /// Per kind: names and value references of the outputs.
    out_names: [Vec<String>; 3],
    out_vr: [Vec<u32>; 3],
    reals: Vec<f64>,
    ints: Vec<i32>,
    bools: Vec<i32>,
    /// The connected inputs, fed from the other unit's outputs.
    inputs: Inputs,
    /// Scratch values of the connected inputs (Real; Integer and Boolean), reused each step.
    in_reals: Vec<f64>,
    in_ints: Vec<i32>,
    /// Value references by variable name (for parameters).
    parameters: std::collections::HashMap<String, u32>,
}

/// `what` is formatted only for an error (the per-step calls pass `format_args!`).
fn check(
    status: fmi2Status,
    what: impl std::fmt::Display,
    warnings: &mut usize,
) -> Result<(), String> {
    match status {
        fmi2Status::Ok => Ok(()),
        fmi2Status::Warning => {
            *warnings += 1;
            Ok(())
        }
        other => Err(format!("{what}: {other:?}")),
    }
}

impl Unit {
    fn new(name: &'static str, fmu: Arc<FMU2<CS>>, md: &ModelDescription) -> Self {
        let mut out_names: [Vec<String>; 3] = Default::default();
        let mut out_vr: [Vec<u32>; 3] = Default::default();
        for v in md
            .modelVariables
            .iter()
            .filter(|v| matches!(v.causality, Causality::Output))
        {
            if let Some(k) = kind(&v.variableType) {
                out_names[k as usize].push(v.name.clone());
                out_vr[k as usize].push(v.valueReference);
            }
        }
        Self {
            name,
            fmu,
            reals: vec![0.0; out_vr[0].len()],
            ints: vec![0; out_vr[1].len()],
            bools: vec![0; out_vr[2].len()],
            out_names,
            out_vr,
            inputs: Inputs::default(),
            in_reals: Vec::new(),
            in_ints: Vec::new(),
            parameters: md
                .modelVariables
                .iter()
                .map(|v| (v.name.clone(), v.valueReference))
                .collect(),
        }
    }

    fn parameter(&self, name: &str) -> Result<u32, String> {
        self.parameters
            .get(name)
            .copied()
            .ok_or_else(|| format!("{}: no variable {name}", self.name))
    }

    /// The instance's state, serialized.
    fn serialize(&self, w: &mut usize) -> Result<Vec<u8>, String> {
        let name = self.name;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        check(
            self.fmu.getFMUstate(&mut state),
            format_args!("{name}: getFMUstate"),
            w,
        )?;
        let mut size = 0;
        let sized = self.fmu.serializedFMUstateSize(state, &mut size);
        let mut bytes = vec![0; size];
        let serialized = self.fmu.serializeFMUstate(state, &mut bytes);
        let freed = self.fmu.freeFMUstate(&mut state);
        check(sized, format_args!("{name}: serializedFMUstateSize"), w)?;
        check(serialized, format_args!("{name}: serializeFMUstate"), w)?;
        check(freed, format_args!("{name}: freeFMUstate"), w)?;
        Ok(bytes)
    }

    /// Restores the instance from serialized bytes.
    fn deserialize(&self, bytes: &[u8], w: &mut usize) -> Result<(), String> {
        let name = self.name;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        check(
            self.fmu.deSerializeFMUstate(bytes, &mut state),
            format_args!("{name}: deSerializeFMUstate"),
            w,
        )?;
        let set = self.fmu.setFMUstate(state);
        let freed = self.fmu.freeFMUstate(&mut state);
        check(set, format_args!("{name}: setFMUstate"), w)?;
        check(freed, format_args!("{name}: freeFMUstate"), w)
    }

    /// Reads the outputs by type; stops at the first call that fails.
    fn read_outputs(&mut self, warnings: &mut usize) -> Result<(), String> {
        let name = self.name;
        let status = self.fmu.getReal(&self.out_vr[0], &mut self.reals);
        check(status, format_args!("{name}: reading outputs"), warnings)?;
        let status = self.fmu.getInteger(&self.out_vr[1], &mut self.ints);
        check(status, format_args!("{name}: reading outputs"), warnings)?;
        let status = self.fmu.getBoolean(&self.out_vr[2], &mut self.bools);
        check(status, format_args!("{name}: reading outputs"), warnings)
    }

    /// Sets this unit's connected inputs from `sender`'s last outputs (or to 0).
    fn take_inputs(&mut self, sender: Option<&Unit>, warnings: &mut usize) -> Result<(), String> {
        for k in KINDS {
            let (source, vrs) = (&self.inputs.source[k as usize], &self.inputs.vr[k as usize]);
            if vrs.is_empty() {
                continue;
            }
            let status = if k == Kind::Real {
                self.in_reals.clear();
                self.in_reals
                    .extend(source.iter().map(|&i| sender.map_or(0.0, |s| s.reals[i])));
                self.fmu.setReal(vrs, &self.in_reals)
            } else {
                fn int_outputs(s: &Unit, k: Kind) -> &[i32] {
                    if k == Kind::Integer {
                        &s.ints
                    } else {
                        &s.bools
                    }
                }
                self.in_ints.clear();
                self.in_ints.extend(
                    source
                        .iter()
                        .map(|&i| sender.map_or(0, |s| int_outputs(s, k)[i])),
                );
                if k == Kind::Integer {
                    self.fmu.setInteger(vrs, &self.in_ints)
                } else {
                    self.fmu.setBoolean(vrs, &self.in_ints)
                }
            };
            check(
                status,
                format_args!("{}: setting inputs", self.name),
                warnings,
            )?;
        }
        Ok(())
    }

    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.reals
            .iter()
            .copied()
            .chain(self.ints.iter().map(|&i| f64::from(i)))
            .chain(self.bools.iter().map(|&b| f64::from(b)))
    }

    fn column_names(&self) -> impl Iterator<Item = &String> + '_ {
        self.out_names.iter().flatten()
    }
}

/// For every input of `receiver`: (index of the same-name output among `sender`'s outputs
/// of its kind, input value reference), per kind. Errors name every input that cannot be fed.
fn connect(
    sender: &Unit,
    sender_md: &ModelDescription,
    receiver_md: &ModelDescription,
    receiver_name: &str,
) -> Result<(Inputs, Vec<String>), String> {
    let mut inputs = Inputs::default();
    let mut names = Vec::new();
    let mut problems = Vec::new();
    for input in receiver_md
        .modelVariables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Input))
    {
        let output = sender_md
            .modelVariables
            .iter()
            .find(|v| v.name == input.name && matches!(v.causality, Causality::Output));
        match (output, kind(&input.variableType)) {
            (None, _) => problems.push(format!(
                "{receiver_name} input '{}' has no {} output of the same name",
                input.name, sender.name
            )),
            (Some(_), None) => problems.push(format!(
                "{receiver_name} input '{}' has a type the masters do not connect",
                input.name
            )),
            (Some(o), Some(k)) if kind(&o.variableType) != Some(k) => problems.push(format!(
                "{receiver_name} input '{}' and the {} output of that name differ in type",
                input.name, sender.name
            )),
            (Some(_), Some(k)) => {
                let index = sender.out_names[k as usize]
                    .iter()
                    .position(|n| *n == input.name)
                    .ok_or_else(|| format!("{}: output '{}' not found", sender.name, input.name))?;
                inputs.source[k as usize].push(index);
                inputs.vr[k as usize].push(input.valueReference);
                names.push(input.name.clone());
            }
        }
    }
    if problems.is_empty() {
        Ok((inputs, names))
    } else {
        Err(format!(
            "cannot connect the FMUs by name:\n  {}",
            problems.join("\n  ")
        ))
    }
}

/// Runs `steps` communication steps of `step` seconds from t = 0 (the plant's default
/// scenario, every parameter at its start value).
///
/// # Errors
/// When an FMU cannot be loaded or connected, or returns fmi2Discard, fmi2Error or
/// fmi2Fatal (the message names the call and the time).
pub fn run_closed_loop(
    plant_fmu: &Path,
    controller_fmu: &Path,
    coupling: Coupling,
    initial_inputs: InitialInputs,
    step: f64,
    steps: u32,
) -> Result<Trajectory, String> {
    let mut lp = ClosedLoop::load(plant_fmu, controller_fmu)?;
    let stop = f64::from(steps) * step;
    lp.initialize(initial_inputs, stop, &[])?;
    let mut rows = vec![lp.record(0.0)];
    rows.extend(lp.run(coupling, initial_inputs, step, 0..steps)?);
    lp.finish(rows)
}

/// Both FMUs loaded, instantiated and connected by name (module docs), stepped a range of
/// steps at a time; their FMU states saved to and restored from files.
pub struct ClosedLoop {
    /// The unpacked FMUs (their folders live as long as these).
    _builders: [FMU2Builder; 2],
    plant: Unit,
    ctrl: Unit,
    to_controller: Vec<String>,
    to_plant: Vec<String>,
    warnings: usize,
}

impl std::fmt::Debug for ClosedLoop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClosedLoop")
            .field("warnings", &self.warnings)
            .finish_non_exhaustive()
    }
}

/// The files [`ClosedLoop::save`] writes into a folder.
const STATE_FILES: [&str; 2] = ["plant.state", "controller.state"];

impl ClosedLoop {
    /// Loads and instantiates both FMUs and connects them.
    ///
    /// # Errors
    /// An FMU that cannot be loaded or instantiated, inputs that cannot be connected.
    pub fn load(plant_fmu: &Path, controller_fmu: &Path) -> Result<Self, String> {
        let load = |p: &Path| FMU2Builder::new(&p).map_err(|e| format!("{}: {e}", p.display()));
        let plant_b = load(plant_fmu)?;
        let ctrl_b = load(controller_fmu)?;
        let (p_md, c_md) = (&plant_b.model_description, &ctrl_b.model_description);
        let instantiate = |b: &FMU2Builder, name: &str| {
            b.instantiate_cs(name)
                .map_err(|e| format!("instantiating {name}: {e}"))
        };
        let mut plant = Unit::new("plant", instantiate(&plant_b, "plant")?, p_md);
        let mut ctrl = Unit::new("controller", instantiate(&ctrl_b, "controller")?, c_md);
        let (to_ctrl, to_controller) = connect(&plant, p_md, c_md, "controller")?;
        let (to_plant_inputs, to_plant) = connect(&ctrl, c_md, p_md, "plant")?;
        ctrl.inputs = to_ctrl;
        plant.inputs = to_plant_inputs;
        Ok(Self {
            _builders: [plant_b, ctrl_b],
            plant,
            ctrl,
            to_controller,
            to_plant,
            warnings: 0,
        })
    }

    /// Initializes both (module docs) with a stop time, the controller's Integer (or
    /// Enumeration) parameters `controller_params` set first.
    ///
    /// # Errors
    /// A call that fails, an unknown parameter.
    pub fn initialize(
        &mut self,
        initial_inputs: InitialInputs,
        stop: f64,
        controller_params: &[(&str, i32)],
    ) -> Result<(), String> {
        let (plant, ctrl, w) = (&mut self.plant, &mut self.ctrl, &mut self.warnings);
        for &(name, value) in controller_params {
            let vr = ctrl.parameter(name)?;
            check(
                ctrl.fmu.setInteger(&[vr], &[value]),
                format_args!("controller: {name}"),
                w,
            )?;
        }
        let exchanged = initial_inputs == InitialInputs::Exchanged;
        check(
            plant.fmu.setupExperiment(None, 0.0, Some(stop)),
            "plant: setupExperiment",
            w,
        )?;
        check(
            plant.fmu.enterInitializationMode(),
            "plant: enterInitializationMode",
            w,
        )?;
        check(
            plant.fmu.exitInitializationMode(),
            "plant: exitInitializationMode",
            w,
        )?;
        check(
            ctrl.fmu.setupExperiment(None, 0.0, Some(stop)),
            "controller: setupExperiment",
            w,
        )?;
        check(
            ctrl.fmu.enterInitializationMode(),
            "controller: enterInitializationMode",
            w,
        )?;
        plant.read_outputs(w)?;
        if exchanged {
            ctrl.take_inputs(Some(plant), w)?;
        }
        check(
            ctrl.fmu.exitInitializationMode(),
            "controller: exitInitializationMode",
            w,
        )?;
        ctrl.read_outputs(w)?;
        if exchanged {
            plant.take_inputs(Some(ctrl), w)?;
        }
        Ok(())
    }

    /// `time`, every plant output, every controller output (as [`Trajectory`]).
    #[must_use]
    pub fn record(&self, t: f64) -> Vec<f64> {
        std::iter::once(t)
            .chain(self.plant.values())
            .chain(self.ctrl.values())
            .collect()
    }

    /// Communication steps `range` (step `k` from t = k h): the rows after each.
    ///
    /// # Errors
    /// A step or an exchange that fails.
    pub fn run(
        &mut self,
        coupling: Coupling,
        initial_inputs: InitialInputs,
        step: f64,
        range: std::ops::Range<u32>,
    ) -> Result<Vec<Vec<f64>>, String> {
        let exchanged = initial_inputs == InitialInputs::Exchanged;
        let mut rows = Vec::with_capacity(range.len());
        for k in range {
            let (plant, ctrl, w) = (&mut self.plant, &mut self.ctrl, &mut self.warnings);
            let t = f64::from(k) * step;
            let zero = k == 0 && !exchanged;
            let plant_out = (!zero).then_some(&*plant);
            ctrl.take_inputs(plant_out, w)?;
            match coupling {
                Coupling::GaussSeidel => {
                    check(
                        ctrl.fmu.doStep(t, step, 1),
                        format_args!("controller: doStep at t = {t} s"),
                        w,
                    )?;
                    ctrl.read_outputs(w)?;
                    plant.take_inputs(Some(ctrl), w)?;
                    check(
                        plant.fmu.doStep(t, step, 1),
                        format_args!("plant: doStep at t = {t} s"),
                        w,
                    )?;
                }
                Coupling::Jacobi => {
                    let ctrl_out = (!zero).then_some(&*ctrl);
                    plant.take_inputs(ctrl_out, w)?;
                    check(
                        ctrl.fmu.doStep(t, step, 1),
                        format_args!("controller: doStep at t = {t} s"),
                        w,
                    )?;
                    check(
                        plant.fmu.doStep(t, step, 1),
                        format_args!("plant: doStep at t = {t} s"),
                        w,
                    )?;
                    ctrl.read_outputs(w)?;
                }
            }
            plant.read_outputs(w)?;
            rows.push(self.record(f64::from(k + 1) * step));
        }
        Ok(rows)
    }

    /// Serializes both FMUs' states (`fmi2SerializeFMUstate`) into `plant.state` and
    /// `controller.state` in `dir`.
    ///
    /// # Errors
    /// A call that fails, a file that cannot be written.
    pub fn save(&mut self, dir: &Path) -> Result<(), String> {
        for (unit, file) in [&self.plant, &self.ctrl].into_iter().zip(STATE_FILES) {
            let bytes = unit.serialize(&mut self.warnings)?;
            std::fs::write(dir.join(file), bytes)
                .map_err(|e| format!("writing {}: {e}", dir.join(file).display()))?;
        }
        Ok(())
    }

    /// Restores both FMUs from the files [`save`](Self::save) wrote
    /// (`fmi2DeSerializeFMUstate`, `fmi2SetFMUstate`), into instances that were only set
    /// up (`fmi2SetupExperiment` with `stop`), and reads their outputs.
    ///
    /// # Errors
    /// A call that fails, a file that cannot be read.
    pub fn restore(&mut self, dir: &Path, stop: f64) -> Result<(), String> {
        for (unit, file) in [&mut self.plant, &mut self.ctrl]
            .into_iter()
            .zip(STATE_FILES)
        {
            let w = &mut self.warnings;
            let path = dir.join(file);
            let bytes =
                std::fs::read(&path).map_err(|e| format!("reading {}: {e}", path.display()))?;
            let name = unit.name;
            check(
                unit.fmu.setupExperiment(None, 0.0, Some(stop)),
                format_args!("{name}: setupExperiment"),
                w,
            )?;
            unit.deserialize(&bytes, w)?;
            unit.read_outputs(w)?;
        }
        Ok(())
    }

    /// Terminates both and returns the trajectory of `rows`.
    ///
    /// # Errors
    /// A terminate that fails.
    pub fn finish(mut self, rows: Vec<Vec<f64>>) -> Result<Trajectory, String> {
        let w = &mut self.warnings;
        check(self.ctrl.fmu.terminate(), "controller: terminate", w)?;
        check(self.plant.fmu.terminate(), "plant: terminate", w)?;
        let columns: Vec<String> = std::iter::once("time".to_owned())
            .chain(self.plant.column_names().cloned())
            .chain(self.ctrl.column_names().cloned())
            .collect();
        Ok(Trajectory {
            columns,
            rows,
            to_controller: self.to_controller,
            to_plant: self.to_plant,
            warnings: self.warnings,
        })
    }
}
