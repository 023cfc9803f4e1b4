//! The call-sequence state machine of FMI 2.0 Co-Simulation (section 4.2.4, figure 10 and
//! the table of allowed calls), with the same masks as the Modelica Reference FMUs.
//!
//! `stepInProgress` and `stepCanceled` exist in the table but are never entered: `fmi2DoStep`
//! is synchronous, so `fmi2CancelStep` is always an illegal call. `start`/`end` is the state
//! outside an instance (before `fmi2Instantiate`, after `fmi2FreeInstance`).

/// The state of one instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CallState {
    /// After `fmi2Instantiate` or `fmi2Reset`.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    InitializationMode,
    /// Ready for `fmi2DoStep`.
    StepComplete,
    /// `fmi2DoStep` returned `fmi2Discard`.
    StepFailed,
    /// After `fmi2Terminate`.
    Terminated,
    /// A function returned `fmi2Error`.
    Error,
    /// A function returned `fmi2Fatal` (a panic was caught).
    Fatal,
}

pub(crate) const INSTANTIATED: u16 = 1 << 1;
pub(crate) const INITIALIZATION_MODE: u16 = 1 << 2;
pub(crate) const STEP_COMPLETE: u16 = 1 << 3;
pub(crate) const STEP_IN_PROGRESS: u16 = 1 << 4;
pub(crate) const STEP_FAILED: u16 = 1 << 5;
pub(crate) const STEP_CANCELED: u16 = 1 << 6;
pub(crate) const TERMINATED: u16 = 1 << 7;
pub(crate) const ERROR: u16 = 1 << 8;
pub(crate) const FATAL: u16 = 1 << 9;

impl CallState {
    /// The spec's name of the state, e.g. `"stepComplete"`.
    pub fn name(self) -> &'static str {
        match self {
            CallState::Instantiated => "instantiated",
            CallState::InitializationMode => "initializationMode",
            CallState::StepComplete => "stepComplete",
            CallState::StepFailed => "stepFailed",
            CallState::Terminated => "terminated",
            CallState::Error => "error",
            CallState::Fatal => "fatal",
        }
    }

    pub(crate) fn bit(self) -> u16 {
        match self {
            CallState::Instantiated => INSTANTIATED,
            CallState::InitializationMode => INITIALIZATION_MODE,
            CallState::StepComplete => STEP_COMPLETE,
            CallState::StepFailed => STEP_FAILED,
            CallState::Terminated => TERMINATED,
            CallState::Error => ERROR,
            CallState::Fatal => FATAL,
        }
    }

    /// Stable one-byte code used by the serialized FMU state.
    pub(crate) fn code(self) -> u8 {
        match self {
            CallState::Instantiated => 1,
            CallState::InitializationMode => 2,
            CallState::StepComplete => 3,
            CallState::StepFailed => 4,
            CallState::Terminated => 5,
            CallState::Error => 6,
            CallState::Fatal => 7,
        }
    }

    pub(crate) fn from_code(code: u8) -> Option<CallState> {
        Some(match code {
            1 => CallState::Instantiated,
            2 => CallState::InitializationMode,
            3 => CallState::StepComplete,
            4 => CallState::StepFailed,
            5 => CallState::Terminated,
            6 => CallState::Error,
            7 => CallState::Fatal,
            _ => return None,
        })
    }
}

/// The functions that take an instance, with the states they are allowed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Func {
    SetDebugLogging,
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal,
    GetInteger,
    GetBoolean,
    GetString,
    SetReal,
    SetInteger,
    SetBoolean,
    SetString,
    GetFmuState,
    SetFmuState,
    FreeFmuState,
    SerializedFmuStateSize,
    SerializeFmuState,
    DeSerializeFmuState,
    GetDirectionalDerivative,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    GetStatus,
    GetRealStatus,
    GetIntegerStatus,
    GetBooleanStatus,
    GetStringStatus,
}

const FREE_INSTANCE_MASK: u16 = INSTANTIATED
    | INITIALIZATION_MODE
    | STEP_COMPLETE
    | STEP_FAILED
    | STEP_CANCELED
    | TERMINATED
    | ERROR;
const GET_MASK: u16 =
    INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR;
const SET_MASK: u16 = INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE;
const STATUS_MASK: u16 = STEP_COMPLETE | STEP_IN_PROGRESS | STEP_FAILED | TERMINATED;

impl Func {
    /// The exported C name.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Func::SetDebugLogging => "fmi2SetDebugLogging",
            Func::FreeInstance => "fmi2FreeInstance",
            Func::SetupExperiment => "fmi2SetupExperiment",
            Func::EnterInitializationMode => "fmi2EnterInitializationMode",
            Func::ExitInitializationMode => "fmi2ExitInitializationMode",
            Func::Terminate => "fmi2Terminate",
            Func::Reset => "fmi2Reset",
            Func::GetReal => "fmi2GetReal",
            Func::GetInteger => "fmi2GetInteger",
            Func::GetBoolean => "fmi2GetBoolean",
            Func::GetString => "fmi2GetString",
            Func::SetReal => "fmi2SetReal",
            Func::SetInteger => "fmi2SetInteger",
            Func::SetBoolean => "fmi2SetBoolean",
            Func::SetString => "fmi2SetString",
            Func::GetFmuState => "fmi2GetFMUstate",
            Func::SetFmuState => "fmi2SetFMUstate",
            Func::FreeFmuState => "fmi2FreeFMUstate",
            Func::SerializedFmuStateSize => "fmi2SerializedFMUstateSize",
            Func::SerializeFmuState => "fmi2SerializeFMUstate",
            Func::DeSerializeFmuState => "fmi2DeSerializeFMUstate",
            Func::GetDirectionalDerivative => "fmi2GetDirectionalDerivative",
            Func::SetRealInputDerivatives => "fmi2SetRealInputDerivatives",
            Func::GetRealOutputDerivatives => "fmi2GetRealOutputDerivatives",
            Func::DoStep => "fmi2DoStep",
            Func::CancelStep => "fmi2CancelStep",
            Func::GetStatus => "fmi2GetStatus",
            Func::GetRealStatus => "fmi2GetRealStatus",
            Func::GetIntegerStatus => "fmi2GetIntegerStatus",
            Func::GetBooleanStatus => "fmi2GetBooleanStatus",
            Func::GetStringStatus => "fmi2GetStringStatus",
        }
    }

    /// Bit set of the states in which the function may be called (FMI 2.0 section 4.2.4).
    pub(crate) fn mask(self) -> u16 {
        match self {
            Func::SetDebugLogging => FREE_INSTANCE_MASK | STEP_IN_PROGRESS,
            // The brief and the spec's text on fmi2Fatal: only fmi2FreeInstance remains.
            Func::FreeInstance => FREE_INSTANCE_MASK | FATAL,
            Func::SetupExperiment | Func::EnterInitializationMode => INSTANTIATED,
            Func::ExitInitializationMode => INITIALIZATION_MODE,
            Func::Terminate => STEP_COMPLETE | STEP_FAILED,
            Func::Reset
            | Func::GetFmuState
            | Func::SetFmuState
            | Func::FreeFmuState
            | Func::SerializedFmuStateSize
            | Func::SerializeFmuState
            | Func::DeSerializeFmuState => FREE_INSTANCE_MASK,
            Func::GetReal
            | Func::GetInteger
            | Func::GetBoolean
            | Func::GetString
            | Func::GetDirectionalDerivative => GET_MASK,
            Func::SetReal | Func::SetInteger | Func::SetBoolean | Func::SetString => SET_MASK,
            Func::SetRealInputDerivatives => SET_MASK,
            Func::GetRealOutputDerivatives => {
                STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR
            }
            Func::DoStep => STEP_COMPLETE,
            Func::CancelStep => STEP_IN_PROGRESS,
            Func::GetStatus
            | Func::GetRealStatus
            | Func::GetIntegerStatus
            | Func::GetBooleanStatus
            | Func::GetStringStatus => STATUS_MASK,
        }
    }

    /// Whether an `fmi2Error` of this function leaves the call state as it was: the
    /// functions that only serialize an FMU state or make one from bytes. They do not touch
    /// the instance's model or clock, so refusing corrupt bytes (or a state that cannot be
    /// serialized) leaves the instance as usable as before, which is what a master that
    /// tries a stored file needs; FMI 2.0 section 2.1.3 asks for a restart from a stored
    /// state after an error of the instance's own computation, which this is not.
    pub(crate) fn refusal_keeps_state(self) -> bool {
        matches!(
            self,
            Func::SerializedFmuStateSize | Func::SerializeFmuState | Func::DeSerializeFmuState
        )
    }

    pub(crate) fn allowed_in(self, state: CallState) -> bool {
        self.mask() & state.bit() != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [CallState; 7] = [
        CallState::Instantiated,
        CallState::InitializationMode,
        CallState::StepComplete,
        CallState::StepFailed,
        CallState::Terminated,
        CallState::Error,
        CallState::Fatal,
    ];

    #[test]
    fn fatal_allows_only_free_instance() {
        for f in [
            Func::Reset,
            Func::GetReal,
            Func::GetFmuState,
            Func::SetFmuState,
            Func::SetDebugLogging,
            Func::DoStep,
        ] {
            assert!(!f.allowed_in(CallState::Fatal), "{}", f.name());
        }
        assert!(Func::FreeInstance.allowed_in(CallState::Fatal));
    }

    #[test]
    fn error_allows_gets_state_functions_reset_free_only() {
        let allowed = [
            Func::SetDebugLogging,
            Func::FreeInstance,
            Func::Reset,
            Func::GetReal,
            Func::GetInteger,
            Func::GetBoolean,
            Func::GetString,
            Func::GetFmuState,
            Func::SetFmuState,
            Func::FreeFmuState,
            Func::SerializedFmuStateSize,
            Func::SerializeFmuState,
            Func::DeSerializeFmuState,
            Func::GetDirectionalDerivative,
            Func::GetRealOutputDerivatives,
        ];
        let denied = [
            Func::SetupExperiment,
            Func::EnterInitializationMode,
            Func::ExitInitializationMode,
            Func::Terminate,
            Func::SetReal,
            Func::SetInteger,
            Func::SetBoolean,
            Func::SetString,
            Func::SetRealInputDerivatives,
            Func::DoStep,
            Func::CancelStep,
            Func::GetStatus,
            Func::GetRealStatus,
            Func::GetIntegerStatus,
            Func::GetBooleanStatus,
            Func::GetStringStatus,
        ];
        for f in allowed {
            assert!(f.allowed_in(CallState::Error), "{}", f.name());
        }
        for f in denied {
            assert!(!f.allowed_in(CallState::Error), "{}", f.name());
        }
    }

    #[test]
    fn co_simulation_main_path() {
        use CallState as S;
        assert!(Func::SetupExperiment.allowed_in(S::Instantiated));
        assert!(!Func::SetupExperiment.allowed_in(S::InitializationMode));
        assert!(Func::SetReal.allowed_in(S::Instantiated));
        assert!(!Func::GetReal.allowed_in(S::Instantiated));
        assert!(Func::GetReal.allowed_in(S::InitializationMode));
        assert!(Func::DoStep.allowed_in(S::StepComplete));
        assert!(!Func::DoStep.allowed_in(S::StepFailed));
        assert!(Func::Terminate.allowed_in(S::StepFailed));
        assert!(!Func::SetReal.allowed_in(S::Terminated));
        assert!(Func::GetRealStatus.allowed_in(S::StepFailed));
        assert!(!Func::GetRealStatus.allowed_in(S::InitializationMode));
        for s in ALL {
            assert!(!Func::CancelStep.allowed_in(s), "{}", s.name());
            assert_eq!(CallState::from_code(s.code()), Some(s));
        }
        assert_eq!(CallState::from_code(0), None);
    }
}
