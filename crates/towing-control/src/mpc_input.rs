//! The data the MPC was given in a control sample, as an owned value: read-only
//! access for tools that replay or compare the MPC outside the loop (the
//! side-by-side baseline `benches/baseline`, `docs/benchmarks.md`).
//!
//! [`Controller::step`](crate::Controller::step) builds a
//! [`towing_mpc::SampleInput`] (ship and tug states as measured, the command
//! applied in the previous sample, the tracked reference, the obstacles selected
//! for the MPC and the heading floor) and hands it to the distributed or the
//! centralized solver. [`Controller::last_mpc_input`](crate::Controller::last_mpc_input)
//! returns a copy of it, so that exactly the same problem can be solved again by
//! another solver or by a fresh instance of the same one. The waterway is not part of the
//! copy (`as_sample_input` gives open water): the side-by-side baseline compares the two
//! solvers on the problem without bank rows (`docs/controller-design.md`, "The waterway").

use towing_model::MAX_OBSTACLES;
use towing_mpc::{AppliedCommand, Obstacle, SampleInput, ShipState, TugState, HORIZON};

/// An owned copy of one sample's [`SampleInput`] (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MpcInput {
    /// The ship's state `[x, y, psi, u, v, r]`, as measured.
    pub ship: ShipState,
    /// The tugs' states (0 = tug 1 aft, 1 = tug 2 forward), as measured.
    pub tugs: [TugState; 2],
    /// The command applied in the previous sample.
    pub previous: AppliedCommand,
    /// The tracked pose per sample of the horizon.
    pub reference: [[f64; 3]; HORIZON],
    /// The obstacles as the MPC sees them; the first `n_obstacles` are used.
    obstacles: [Obstacle; MAX_OBSTACLES],
    /// How many of `obstacles` are in use.
    n_obstacles: usize,
    /// The obstacles left out of the distance cost
    /// ([`SampleInput::distance_cost_off`]).
    pub distance_cost_off: u64,
    /// The heading floor (rad), if any.
    pub heading_floor: Option<f64>,
    /// The surge cap (m/s), if any ([`SampleInput::max_surge`]).
    pub max_surge: Option<f64>,
}

impl MpcInput {
    /// A copy of `input`.
    ///
    /// # Panics
    /// If `input` holds more than [`MAX_OBSTACLES`] obstacles (the controller
    /// never selects more than there are obstacle slots).
    #[must_use]
    pub fn of(input: &SampleInput<'_>) -> MpcInput {
        let n = input.obstacles.len();
        assert!(
            n <= MAX_OBSTACLES,
            "a sample input holds {n} obstacles, more than the {MAX_OBSTACLES} obstacle slots"
        );
        let mut obstacles = [Obstacle::Circle {
            centre: [0.0; 2],
            radius: 1.0,
        }; MAX_OBSTACLES];
        obstacles[..n].copy_from_slice(input.obstacles);
        MpcInput {
            ship: input.ship,
            tugs: input.tugs,
            previous: input.previous,
            reference: input.reference,
            obstacles,
            n_obstacles: n,
            distance_cost_off: input.distance_cost_off,
            heading_floor: input.heading_floor,
            max_surge: input.max_surge,
        }
    }

    /// The obstacles in use, in the MPC's order (nearest to the tow first).
    #[must_use]
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles[..self.n_obstacles]
    }

    /// The input again, to hand to a solver.
    #[must_use]
    pub fn as_sample_input(&self) -> SampleInput<'_> {
        SampleInput {
            ship: self.ship,
            tugs: self.tugs,
            previous: self.previous,
            reference: self.reference,
            obstacles: self.obstacles(),
            distance_cost_off: self.distance_cost_off,
            heading_floor: self.heading_floor,
            max_surge: self.max_surge,
            waterway: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_a_sample_input() {
        let obstacles = [
            Obstacle::Circle {
                centre: [1.0, 2.0],
                radius: 0.5,
            },
            Obstacle::Ellipse {
                centre: [3.0, -1.0],
                semi_major: 1.0,
                semi_minor: 0.4,
                orientation: 0.3,
                drift: [0.1, 0.0],
            },
        ];
        let input = SampleInput {
            ship: [1.0, 2.0, 0.5, 0.1, 0.0, 0.01],
            tugs: [[0.0; 6], [4.0, 5.0, 0.4, 0.0, 0.0, 0.0]],
            previous: AppliedCommand {
                ship: [0.5, 0.6, 0.1, -0.1],
                tugs: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            },
            reference: [[3.0, 4.0, 0.6]; HORIZON],
            obstacles: &obstacles,
            distance_cost_off: 0b10,
            heading_floor: Some(0.2),
            max_surge: Some(0.04),
            waterway: None,
        };
        let owned = MpcInput::of(&input);
        let back = owned.as_sample_input();
        assert_eq!(back.obstacles, &obstacles);
        assert_eq!(
            (back.ship, back.tugs, back.previous, back.reference),
            (input.ship, input.tugs, input.previous, input.reference)
        );
        assert_eq!(back.heading_floor, Some(0.2));
        assert_eq!(back.max_surge, Some(0.04));
        assert_eq!(back.distance_cost_off, 0b10);
    }
}
