//! The published figures of Du, Negenborn, Reppa (2022), Tables 6 and 7 (as transcribed
//! in `paper/NOTES.md` section 3), for the side-by-side tables.

/// Normalised minimum distances `D` of ship, tug 1, tug 2 for one scenario (eq. (30)).
pub type Distances = [f64; 3];

/// Target ship of each of the paper's three avoidance scenarios: 1 crossing (A),
/// 2 crossing then head-on (B), 3 head-on (C).
pub const SCENARIO_TARGETS: [&str; 3] = ["A", "B", "C"];

/// Scenario captions as in the paper.
pub const SCENARIO_CAPTIONS: [&str; 3] = [
    "Scenario 1 (crossing)",
    "Scenario 2 (crossing & head-on)",
    "Scenario 3 (head-on)",
];

/// One row of Table 6 (distributed control).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table6Row {
    /// Scheme code (1 I, 2 II, 3 III).
    pub scheme: i32,
    /// `D` per scenario.
    pub d: [Distances; 3],
    /// COLREGS compliance per scenario.
    pub colregs: [bool; 3],
}

/// Table 6: normalised minimum distance by avoidance scheme, distributed control.
pub const TABLE6: [Table6Row; 3] = [
    Table6Row {
        scheme: 1,
        d: [[2.45, 4.31, 1.53], [2.65, 3.97, 2.41], [1.43, 1.70, 1.73]],
        colregs: [true, true, true],
    },
    Table6Row {
        scheme: 2,
        d: [[2.30, 4.17, 1.36], [2.62, 3.95, 2.34], [1.23, 1.50, 1.45]],
        colregs: [true, true, true],
    },
    Table6Row {
        scheme: 3,
        d: [[1.93, 4.40, 1.44], [2.19, 3.54, 1.78], [1.13, 1.30, 1.67]],
        colregs: [false, true, true],
    },
];

/// One row of Table 7 (scheme I).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table7Row {
    /// Architecture code (1 distributed, 2 centralized).
    pub architecture: i32,
    /// `D` per scenario.
    pub d: [Distances; 3],
    /// Settling time, s.
    pub settling_time_s: f64,
    /// Maximum towline elongation error of line 1 and 2, fractions.
    pub elongation: [f64; 2],
    /// Ship travel, m (section 4.2.3 text).
    pub ship_travel_m: f64,
}

/// Table 7: distributed vs centralized, scheme I.
pub const TABLE7: [Table7Row; 2] = [
    Table7Row {
        architecture: 1,
        d: [[2.45, 4.31, 1.53], [2.65, 3.97, 2.41], [1.43, 1.70, 1.73]],
        settling_time_s: 968.0,
        elongation: [0.0579, 0.0633],
        ship_travel_m: 62.69,
    },
    Table7Row {
        architecture: 2,
        d: [[2.79, 5.25, 1.74], [2.20, 3.08, 1.92], [1.59, 2.12, 1.73]],
        settling_time_s: 985.0,
        elongation: [0.0515, 0.0532],
        ship_travel_m: 63.57,
    },
];

/// The paper's `D` values and COLREGS compliance for a run, if the paper has them:
/// distributed runs use Table 6's row of their scheme, centralized scheme-I runs Table 7
/// (which gives no compliance column: `None` there).
#[must_use]
pub fn distances_for(
    architecture: Option<i32>,
    scheme: Option<i32>,
) -> Option<([Distances; 3], Option<[bool; 3]>)> {
    match (architecture?, scheme?) {
        (1, s) => TABLE6
            .iter()
            .find(|r| r.scheme == s)
            .map(|r| (r.d, Some(r.colregs))),
        (2, 1) => Some((TABLE7[1].d, None)),
        _ => None,
    }
}

/// Table 7's row for a run (scheme I only).
#[must_use]
pub fn table7_for(architecture: Option<i32>, scheme: Option<i32>) -> Option<Table7Row> {
    if scheme? != 1 {
        return None;
    }
    let a = architecture?;
    TABLE7.iter().copied().find(|r| r.architecture == a)
}
