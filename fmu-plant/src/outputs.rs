//! The plant's own outputs beyond the interface contract ([`OUTPUTS`]: one [`PlantOutput`]
//! per output with its name, value reference, description and value), and the grounding
//! watch behind them ([`Groundings`]).
//!
//! A hull is aground when its footprint (the [`towing_model::HullRect`] of its length and
//! beam) reaches beyond the bank of the scenario's waterway ([`towing_model::Lane`]: within
//! `half_width` of the route), [`towing_model::World::bank_excess`] > 0. The plant has no
//! physics of grounding: the hull keeps moving as in open water (`docs/assumptions.md`);
//! the output and one `/plant/log` event per grounding episode report it, and the
//! analyzer's `waterway` metric judges it with the same geometry.
//!
//! Value references: 400 + vessel (0 ship, 1 tug 1, 2 tug 2), Boolean; free in the
//! contract's numbering ([`towing_interface::vr`]).

use fmi2_slave::description::{Variable, VariableKind};
use towing_interface::codec::Vessel;
use towing_interface::variables::calculated_output;
use towing_interface::vr;
use towing_model::World;

/// One output of the plant's own (module docs).
#[derive(Debug, Clone, Copy)]
pub struct PlantOutput {
    /// FMI name.
    pub name: &'static str,
    /// Value reference.
    pub value_reference: u32,
    /// Description in the model description.
    pub description: &'static str,
    /// Its value from the grounding watch.
    pub get: fn(&Groundings) -> bool,
}

/// The plant's own outputs (module docs).
pub static OUTPUTS: [PlantOutput; 3] = [
    PlantOutput {
        name: "aground.ship",
        value_reference: 400,
        description: "true while a corner of the ship's hull (length x beam) is beyond the waterway's bank (farther than the scenario's half width from the route); false without a waterway",
        get: |g| g.aground[0],
    },
    PlantOutput {
        name: "aground.tug1",
        value_reference: 401,
        description: "true while a corner of tug 1's hull (length x beam) is beyond the waterway's bank (farther than the scenario's half width from the route); false without a waterway",
        get: |g| g.aground[1],
    },
    PlantOutput {
        name: "aground.tug2",
        value_reference: 402,
        description: "true while a corner of tug 2's hull (length x beam) is beyond the waterway's bank (farther than the scenario's half width from the route); false without a waterway",
        get: |g| g.aground[2],
    },
];

/// The model-description variables of [`OUTPUTS`] (calculated outputs, no direct
/// feedthrough; at initialization they depend on the scenario).
#[must_use]
pub fn variables() -> Vec<Variable> {
    OUTPUTS
        .iter()
        .map(|o| {
            calculated_output(
                o.name.to_owned(),
                o.value_reference,
                VariableKind::Boolean { start: None },
                o.description.to_owned(),
                vec![vr::SCENARIO],
            )
        })
        .collect()
}

/// A grounding that began at the end of a step: what the log event says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundingEvent {
    /// The vessel.
    pub vessel: Vessel,
    /// Its position `[x, y]` (m).
    pub position: [f64; 2],
    /// How far its hull reaches beyond the bank (m, > 0).
    pub excess: f64,
}

impl GroundingEvent {
    /// The `/plant/log` message (docs/logging.md).
    #[must_use]
    pub fn message(&self, t: f64) -> String {
        format!(
            "grounding: {} aground at t = {t:.3} s, position ({:.3}, {:.3}) m, its hull {:.3} m beyond the bank",
            self.vessel.name(),
            self.position[0],
            self.position[1],
            self.excess
        )
    }
}

/// Which hulls are aground now (module docs); derived from the world's state alone, so
/// an FMU state restores it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Groundings {
    /// Ship, tug 1, tug 2.
    pub aground: [bool; 3],
}

impl Groundings {
    /// The hulls aground in `world`.
    #[must_use]
    pub fn of(world: &World) -> Groundings {
        Groundings::from_excess(world.bank_excess())
    }

    /// The hulls aground for the excesses beyond the bank of [`World::bank_excess`].
    fn from_excess(excess: Option<[f64; 3]>) -> Groundings {
        let aground = excess.map_or([false; 3], |e| e.map(|x| x > 0.0));
        Groundings { aground }
    }

    /// Moves to `world`'s state: the groundings that began (a hull aground now that was
    /// not before), one event each.
    pub fn update(&mut self, world: &World) -> Vec<GroundingEvent> {
        let excess = world.bank_excess();
        let now = Groundings::from_excess(excess);
        let mut events = Vec::new();
        if let Some(excess) = excess {
            for (k, vessel) in [Vessel::Ship, Vessel::Tug1, Vessel::Tug2]
                .into_iter()
                .enumerate()
            {
                if now.aground[k] && !self.aground[k] {
                    let eta = if k == 0 {
                        world.ship().eta
                    } else {
                        world.tug(k - 1).eta
                    };
                    events.push(GroundingEvent {
                        vessel,
                        position: [eta[0], eta[1]],
                        excess: excess[k],
                    });
                }
            }
        }
        *self = now;
        events
    }
}
