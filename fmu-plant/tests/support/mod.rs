//! The benchmark set-up shared by `benches/do_step.rs` and `examples/do_step_latency.rs`:
//! a plant instance on a scenario whose 8 obstacles are all active (optionally writing an
//! MCAP log), seeded inputs, and one master-style communication step.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::Fmu;
use fmi2_slave::{Causality, ValueType};
use towing_plant::variables::{self as vars, DESCRIPTION};

/// A scenario with all 8 obstacle slots active from t = 0 (the towing-model bench's).
pub const EIGHT_OBSTACLES: &str = "crates/towing-model/benches/eight_obstacles.toml";

/// A ready-to-step plant plus seeded inputs.
pub struct Bench {
    pub fmu: Fmu,
    inputs: Vec<[f64; 8]>,
    input_vrs: [u32; 8],
    output_vrs: Vec<u32>,
    outputs: std::cell::RefCell<Vec<f64>>,
    time: std::cell::Cell<f64>,
}

impl Bench {
    pub fn new() -> Bench {
        Self::with_log(None)
    }

    /// As [`Bench::new`], with `log_file` set to `log` when given.
    pub fn with_log(log: Option<&std::path::Path>) -> Bench {
        let scenario = towing_interface::testing::workspace_root().join(EIGHT_OBSTACLES);
        let fmu = Fmu::try_new(
            fmi2_slave::exports_of!(towing_plant),
            &DESCRIPTION,
            "bench",
            None,
            false,
        )
        .unwrap();
        assert_eq!(
            fmu.set_string(vars::SCENARIO, scenario.to_str().unwrap()),
            Fmi2Status::Ok
        );
        let vr = |name| vars::parameter_vr_of(name).unwrap();
        assert_eq!(
            fmu.set_boolean(vr("model.hull_from_scenario"), false),
            Fmi2Status::Ok
        );
        assert_eq!(fmu.set_integer(vr("model.hull"), 2), Fmi2Status::Ok);
        if let Some(log) = log {
            assert_eq!(
                fmu.set_string(vars::LOG_FILE, log.to_str().unwrap()),
                Fmi2Status::Ok
            );
        }
        fmu.init(0.0, None);
        for slot in 0..8 {
            assert_ne!(
                fmu.get_integer(vars::obstacle(slot, vars::OBSTACLE_KIND)),
                0
            );
        }
        let output_vrs: Vec<u32> = DESCRIPTION
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output && v.value_type() == ValueType::Real)
            .map(|v| v.value_reference)
            .collect();
        // Seeded pseudo-random inputs within the paper's limits (64-bit LCG).
        let mut state = 2022u64;
        let mut unit = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let inputs = (0..1024)
            .map(|_| {
                [
                    3.0 + 2.0 * unit(),
                    unit(),
                    0.2 * unit(),
                    3.0 + 2.0 * unit(),
                    unit(),
                    0.2 * unit(),
                    1.5 + 1.5 * unit(),
                    1.5 + 1.5 * unit(),
                ]
            })
            .collect();
        let n = output_vrs.len();
        Bench {
            fmu,
            inputs,
            input_vrs: towing_interface::COMMANDS,
            output_vrs,
            outputs: std::cell::RefCell::new(vec![0.0; n]),
            time: std::cell::Cell::new(0.0),
        }
    }

    /// Set inputs, step 0.1 s, read every Real output.
    pub fn communication_step(&self, k: usize) -> Fmi2Status {
        let u = &self.inputs[k % self.inputs.len()];
        let s = self.fmu.set_reals(&self.input_vrs, u);
        if s != Fmi2Status::Ok {
            return s;
        }
        let t = self.time.get();
        let s = self.fmu.step(t, 0.1);
        if s != Fmi2Status::Ok {
            return s;
        }
        self.time.set(t + 0.1);
        let (s, v) = self.fmu.try_get_reals(&self.output_vrs);
        self.outputs.borrow_mut().copy_from_slice(&v);
        s
    }
}
