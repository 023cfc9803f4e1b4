//! Issue 15, item 5: a host that loads an FMU's shared library, runs an instance, frees it
//! and unloads the library, over and over, must see flat memory. Both cdylibs
//! (`libtowing_plant.so`, `libtowing_controller.so`, built by cargo next to this test as
//! the dev-dependencies `fmu-plant` and `fmu-controller`) go through `dlopen`,
//! `fmi2Instantiate`, `fmi2SetupExperiment`, `fmi2EnterInitializationMode`,
//! `fmi2ExitInitializationMode`, three `fmi2DoStep`, `fmi2Terminate`, `fmi2FreeInstance`
//! and `dlclose` in every cycle, and the resident set size may not grow after a warm-up.
//!
//! Before the fix each cycle lost the model description and variable tables the library
//! had built in its statics (about 60 KB for the plant under valgrind): RSS grew by about
//! 70 KiB per cycle of both libraries (10.5 MB from cycle 50 to cycle 200). Since
//! (`fmi2_slave::LibraryLazy`) it stays within a few pages over 1,000 cycles (about 6 s).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::{Exports, Fmu};
use libloading::Library;

/// Cycles (of both libraries) measured; [`WARM_UP`] of them before the first reading.
/// `UNLOAD_CYCLES=<n>` changes the count for a manual run (under valgrind, say).
const CYCLES: usize = 1_000;
const WARM_UP: usize = 50;
/// Allowed growth of the resident set between the end of the warm-up and the end (KiB):
/// allocator noise, a few pages (16 KiB measured). The leak made it about 65,000 KiB.
const MAX_GROWTH_KIB: u64 = 1_024;

/// The cdylib `lib<name>.so` cargo built for this profile: next to `deps/`, where this test
/// executable lives, or in `deps/` itself.
fn cdylib(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable's path");
    let deps = exe.parent().expect("the test executable's directory");
    let file = format!("lib{name}.so");
    let candidates = [deps.parent().map(|p| p.join(&file)), Some(deps.join(&file))];
    candidates
        .into_iter()
        .flatten()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("{file} not found next to {}", exe.display()))
}

/// The GUID of the committed `modelDescription/<model>.xml` (kept equal to the built
/// FMU's by the FMU crates' tests). Not from the FMU crates themselves: linking both would
/// define every `fmi2*` symbol twice.
fn committed_guid(model: &str) -> String {
    let xml =
        towing_interface::testing::read_repository_file(&format!("modelDescription/{model}.xml"));
    let start = xml.find("guid=\"").expect("a guid attribute") + "guid=\"".len();
    let len = xml[start..].find('"').expect("the guid's closing quote");
    xml[start..start + len].to_string()
}

/// Resident set size of this process (KiB), from `/proc/self/status`.
fn rss_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect("VmRSS in /proc/self/status")
}

/// The FMI functions of the loaded `lib`.
///
/// # Safety
/// `lib` is an FMU built with `export_fmi2!`; the table is used only while `lib` is loaded.
unsafe fn exports(lib: &Library) -> Exports {
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the symbol has the FMI 2.0 signature of the field it fills.
            *unsafe { lib.get(concat!($name, "\0").as_bytes()) }
                .unwrap_or_else(|e| panic!("{}: {e}", $name))
        };
    }
    Exports {
        set_debug_logging: sym!("fmi2SetDebugLogging"),
        instantiate: sym!("fmi2Instantiate"),
        free_instance: sym!("fmi2FreeInstance"),
        setup_experiment: sym!("fmi2SetupExperiment"),
        enter_initialization_mode: sym!("fmi2EnterInitializationMode"),
        exit_initialization_mode: sym!("fmi2ExitInitializationMode"),
        terminate: sym!("fmi2Terminate"),
        reset: sym!("fmi2Reset"),
        get_real: sym!("fmi2GetReal"),
        get_integer: sym!("fmi2GetInteger"),
        get_boolean: sym!("fmi2GetBoolean"),
        get_string: sym!("fmi2GetString"),
        set_real: sym!("fmi2SetReal"),
        set_integer: sym!("fmi2SetInteger"),
        set_boolean: sym!("fmi2SetBoolean"),
        set_string: sym!("fmi2SetString"),
        get_fmu_state: sym!("fmi2GetFMUstate"),
        set_fmu_state: sym!("fmi2SetFMUstate"),
        free_fmu_state: sym!("fmi2FreeFMUstate"),
        serialized_fmu_state_size: sym!("fmi2SerializedFMUstateSize"),
        serialize_fmu_state: sym!("fmi2SerializeFMUstate"),
        deserialize_fmu_state: sym!("fmi2DeSerializeFMUstate"),
        do_step: sym!("fmi2DoStep"),
        get_real_status: sym!("fmi2GetRealStatus"),
    }
}

/// One FMU library: its path and GUID.
struct Unit {
    path: PathBuf,
    guid: String,
}

impl Unit {
    /// Load, instantiate (resources: the repository's `scenarios/`), initialize, three steps
    /// of 0.1 s, terminate, free, unload.
    fn cycle(&self, resources: &str) {
        // SAFETY: our own FMU library; its initializers only set up Rust statics.
        let lib = unsafe { Library::new(&self.path) }
            .unwrap_or_else(|e| panic!("dlopen {}: {e}", self.path.display()));
        {
            // SAFETY: the table is dropped with `fmu`, before `lib` is closed.
            let exports = unsafe { exports(&lib) };
            let fmu = Fmu::try_new_with_guid(exports, &self.guid, "unload", Some(resources), false)
                .unwrap_or_else(|log| panic!("{}: instantiate: {log:?}", self.path.display()));
            fmu.init(0.0, None);
            for k in 0..3 {
                let t = f64::from(k) * 0.1;
                assert_eq!(fmu.step(t, 0.1), Fmi2Status::Ok, "{}", fmu.log_text());
            }
            assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());
        }
        lib.close()
            .unwrap_or_else(|e| panic!("dlclose {}: {e}", self.path.display()));
    }
}

#[test]
fn loading_and_unloading_both_fmus_a_thousand_times_keeps_memory_flat() {
    let units = [
        Unit {
            path: cdylib("towing_plant"),
            guid: committed_guid("TowingPlant"),
        },
        Unit {
            path: cdylib("towing_controller"),
            guid: committed_guid("TowingController"),
        },
    ];
    let resources = towing_interface::testing::resources_uri();
    let cycles: usize = std::env::var("UNLOAD_CYCLES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(CYCLES);
    let mut after_warm_up = None;
    let started = std::time::Instant::now();
    for cycle in 1..=cycles {
        for unit in &units {
            unit.cycle(&resources);
        }
        if cycle == WARM_UP.min(cycles) {
            after_warm_up = Some(rss_kib());
        }
    }
    let start = after_warm_up.expect("a reading after the warm-up");
    let end = rss_kib();
    let growth = end.saturating_sub(start);
    eprintln!(
        "{cycles} cycles in {:.1} s; RSS after cycle {WARM_UP}: {start} KiB, after cycle {cycles}: {end} KiB, growth {growth} KiB ({:.2} KiB per cycle)",
        started.elapsed().as_secs_f64(),
        growth as f64 / (cycles.saturating_sub(WARM_UP).max(1)) as f64
    );
    assert!(
        growth < MAX_GROWTH_KIB,
        "RSS grew by {growth} KiB from cycle {WARM_UP} ({start} KiB) to cycle {cycles} ({end} KiB)"
    );
}
