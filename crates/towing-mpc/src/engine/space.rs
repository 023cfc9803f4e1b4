//! The decision variables of a subproblem: input channels per sample with their
//! bounds, rate bounds and trust-region scales (Du et al. 2022, eq. (17)-(21)),
//! and everything the SCP step derives from them: the projection of a plan onto
//! the constraints, the per-variable boxes of one step, the rate rows.
//!
//! A plan is flat, sample-major: channel `k` of sample `h` is entry
//! `per_step h + k` ([`InputSpace::index`]); so are the QP's increments.

use crate::qp::Qp;

/// One input channel of a sample: a decision variable repeated over the horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channel {
    /// Lower bound (the channel's unit).
    pub lower: f64,
    /// Upper bound (`>= lower`).
    pub upper: f64,
    /// Largest change between consecutive samples, and from the previously
    /// applied command to sample 0 (eq. (20)-(21)); `f64::INFINITY`: none.
    pub rate: f64,
    /// Scale of the trust region (the channel's unit): the step's box is
    /// `radius * trust_scale`.
    pub trust_scale: f64,
    /// The predicted vessels this channel moves, a bit per vessel
    /// ([`ALL_VESSELS`] when a subproblem predicts one vessel). Two increments
    /// whose channels move no common vessel never share a cost term, so `P`
    /// has no entry for them, and a row about some vessels has entries only for
    /// the channels that move one of them: the centralized problem's tug 1 and
    /// tug 2 thrusts are not coupled, which keeps its QP sparse.
    pub moves: u8,
}

/// Every vessel: the `moves` of a channel that may affect any predicted state.
pub const ALL_VESSELS: u8 = u8::MAX;

impl Channel {
    /// A channel without a rate bound.
    #[must_use]
    pub fn bounded(lower: f64, upper: f64, trust_scale: f64) -> Channel {
        Channel {
            lower,
            upper,
            rate: f64::INFINITY,
            trust_scale,
            moves: ALL_VESSELS,
        }
    }

    /// The channel, moving only `vessels`.
    #[must_use]
    pub fn moving(self, vessels: u8) -> Channel {
        Channel {
            moves: vessels,
            ..self
        }
    }

    /// Whether the channel has a rate bound.
    #[must_use]
    pub fn is_rated(&self) -> bool {
        self.rate.is_finite()
    }

    /// What the first sample's rate band is measured from: the previous command,
    /// brought to within one rate bound of the bounds (a previous command outside
    /// them, after a bound moved, [`InputSpace::set_lower`]): the band then always
    /// meets the bounds, and a bound within one rate bound of the previous command
    /// is reached without exceeding the rate.
    #[must_use]
    pub fn start(&self, previous: f64) -> f64 {
        previous.clamp(self.lower - self.rate, self.upper + self.rate)
    }
}

/// The channels of one sample over a horizon (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct InputSpace {
    channels: Vec<Channel>,
    horizon: usize,
    /// The channels with a rate bound, in channel order.
    rated: Vec<usize>,
}

impl InputSpace {
    /// `channels` per sample over `horizon` samples.
    #[must_use]
    pub fn new(channels: Vec<Channel>, horizon: usize) -> InputSpace {
        let rated = (0..channels.len())
            .filter(|&k| channels[k].is_rated())
            .collect();
        InputSpace {
            channels,
            horizon,
            rated,
        }
    }

    /// Channels per sample.
    #[must_use]
    pub fn per_step(&self) -> usize {
        self.channels.len()
    }

    /// Samples.
    #[must_use]
    pub fn horizon(&self) -> usize {
        self.horizon
    }

    /// Decision variables (`per_step * horizon`).
    #[must_use]
    pub fn len(&self) -> usize {
        self.channels.len() * self.horizon
    }

    /// Whether there are no decision variables.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The channels of a sample.
    #[must_use]
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Per increment, the vessels its channel moves.
    #[must_use]
    pub fn moves(&self) -> Vec<u8> {
        (0..self.len())
            .map(|j| self.channels[j % self.per_step()].moves)
            .collect()
    }

    /// Whether increments `i` and `j` can share a cost term (their channels move
    /// a common vessel).
    #[must_use]
    pub fn coupled(&self, i: usize, j: usize) -> bool {
        let ps = self.per_step();
        self.channels[i % ps].moves & self.channels[j % ps].moves != 0
    }

    /// Sets the lower bound of channel `k` to `lower` (at most its upper bound).
    pub fn set_lower(&mut self, k: usize, lower: f64) {
        let c = &mut self.channels[k];
        c.lower = lower.min(c.upper);
    }

    /// Flat index of channel `k` of sample `h`.
    #[must_use]
    pub fn index(&self, h: usize, k: usize) -> usize {
        self.channels.len() * h + k
    }

    /// Projects `plan` onto the bounds and rate bounds, sample by sample, the
    /// first sample measured from `previous` ([`Channel::start`]):
    /// afterwards `du = 0` is feasible for the step's QP. Channels without a rate
    /// bound are clamped into their bounds.
    pub fn project(&self, plan: &mut [f64], previous: &[f64]) {
        for (k, c) in self.channels.iter().enumerate() {
            let mut before = c.start(previous[k]);
            for h in 0..self.horizon {
                let u = &mut plan[self.index(h, k)];
                *u = u.clamp(c.lower.max(before - c.rate), c.upper.min(before + c.rate));
                before = *u;
            }
        }
    }

    /// The boxes `[lo_j, hi_j]` of the increments of one step from the projected
    /// `plan`: the bounds, the trust region `radius * trust_scale` and, for
    /// sample 0, the rate band around `previous`; each widened to contain 0 (the
    /// projected plan is feasible; this keeps it so under rounding).
    pub fn boxes(
        &self,
        plan: &[f64],
        previous: &[f64],
        radius: f64,
        lo: &mut [f64],
        hi: &mut [f64],
    ) {
        for (k, c) in self.channels.iter().enumerate() {
            let tr = radius * c.trust_scale;
            let prev = c.start(previous[k]);
            for h in 0..self.horizon {
                let j = self.index(h, k);
                let u = plan[j];
                let (mut l, mut r) = ((c.lower - u).max(-tr), (c.upper - u).min(tr));
                if h == 0 {
                    l = l.max(prev - c.rate - u);
                    r = r.min(prev + c.rate - u);
                }
                lo[j] = l.min(0.0);
                hi[j] = r.max(0.0);
            }
        }
    }

    /// Rate rows: two per rated channel and sample `h >= 1`.
    #[must_use]
    pub fn rate_rows(&self) -> usize {
        2 * self.rated.len() * self.horizon.saturating_sub(1)
    }

    /// The `(row, column)` entries of the rate rows (rows counted from
    /// `first_row`) and their values: row `2 (n_r (h - 1) + q)` is
    /// `du_{h,k} - du_{h-1,k} <= b`, the next one its negative, `k` the `q`-th
    /// rated channel.
    #[must_use]
    pub fn rate_entries(&self, first_row: usize) -> Vec<((usize, usize), f64)> {
        let mut out = Vec::with_capacity(4 * self.rate_rows());
        for h in 1..self.horizon {
            for (q, &k) in self.rated.iter().enumerate() {
                let row = first_row + 2 * (self.rated.len() * (h - 1) + q);
                let (cur, prev) = (self.index(h, k), self.index(h - 1, k));
                out.extend([
                    ((row, cur), 1.0),
                    ((row, prev), -1.0),
                    ((row + 1, cur), -1.0),
                    ((row + 1, prev), 1.0),
                ]);
            }
        }
        out
    }

    /// The right-hand sides of the rate rows (from QP row `first_row`) for a
    /// step from `plan`: `rate -+ (u_h - u_{h-1})`, at least 0.
    pub fn load_rate_rows(&self, qp: &mut Qp, first_row: usize, plan: &[f64]) {
        for (q, &k) in self.rated.iter().enumerate() {
            let rate = self.channels[k].rate;
            for h in 1..self.horizon {
                let diff = plan[self.index(h, k)] - plan[self.index(h - 1, k)];
                let row = first_row + 2 * (self.rated.len() * (h - 1) + q);
                qp.b_mut()[row] = (rate - diff).max(0.0);
                qp.b_mut()[row + 1] = (rate + diff).max(0.0);
            }
        }
    }

    /// The largest change of a sample-0 channel between two plans.
    #[must_use]
    pub fn first_move_change(&self, a: &[f64], b: &[f64]) -> f64 {
        let mut change: f64 = 0.0;
        for k in 0..self.per_step() {
            change = change.max((a[k] - b[k]).abs());
        }
        change
    }

    /// Whether `plan` satisfies every bound and rate bound (the first sample
    /// from `previous`, [`Channel::start`]) within `tol`.
    #[must_use]
    pub fn contains(&self, plan: &[f64], previous: &[f64], tol: f64) -> bool {
        self.channels.iter().enumerate().all(|(k, c)| {
            let mut before = c.start(previous[k]);
            (0..self.horizon).all(|h| {
                let u = plan[self.index(h, k)];
                let ok =
                    u >= c.lower - tol && u <= c.upper + tol && (u - before).abs() <= c.rate + tol;
                before = u;
                ok
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn space() -> InputSpace {
        InputSpace::new(
            vec![
                Channel {
                    lower: 0.1,
                    upper: 3.0,
                    rate: 0.3,
                    trust_scale: 1.0,
                    moves: ALL_VESSELS,
                },
                Channel::bounded(-10.0, 10.0, 10.0),
            ],
            3,
        )
    }

    proptest! {
        /// A projected plan satisfies every bound and rate bound, and a plan that
        /// does already is left as it is.
        #[test]
        fn projection_is_feasible_and_idempotent(
            plan in proptest::collection::vec(-20.0f64..20.0, 6),
            previous in proptest::collection::vec(-5.0f64..5.0, 2),
        ) {
            let s = space();
            let mut p = plan.clone();
            s.project(&mut p, &previous);
            prop_assert!(s.contains(&p, &previous, 1e-12));
            let again = p.clone();
            s.project(&mut p, &previous);
            prop_assert_eq!(p, again);
        }

        /// Every box contains 0, and a step inside the boxes and the rate rows
        /// keeps the plan feasible.
        #[test]
        fn boxes_contain_zero(
            plan in proptest::collection::vec(-20.0f64..20.0, 6),
            previous in proptest::collection::vec(-5.0f64..5.0, 2),
            radius in 1e-4f64..2.0,
        ) {
            let s = space();
            let mut p = plan.clone();
            s.project(&mut p, &previous);
            let (mut lo, mut hi) = (vec![0.0; 6], vec![0.0; 6]);
            s.boxes(&p, &previous, radius, &mut lo, &mut hi);
            for j in 0..6 {
                prop_assert!(lo[j] <= 0.0 && hi[j] >= 0.0);
                let mut q = p.clone();
                q[j] += hi[j];
                prop_assert!(q[j] <= s.channels()[j % 2].upper + 1e-12);
            }
        }
    }

    /// A lower bound raised above the previous command (the ship's holding tension,
    /// `ShipMpcParams::tension_floor`) is met by the first sample without a change
    /// beyond the rate bound when it lies within one rate bound; beyond that reach the
    /// plan is still feasible, measured from the previous command brought within reach.
    #[test]
    fn a_raised_lower_bound_is_reached_within_the_rate() {
        let mut s = space();
        s.set_lower(0, 0.3);
        let previous = [0.1, 0.0];
        let mut plan = vec![0.0; 6];
        s.project(&mut plan, &previous);
        assert!(
            plan[0] >= 0.3 && plan[0] - previous[0] <= 0.3 + 1e-12,
            "{plan:?}"
        );
        assert!(s.contains(&plan, &previous, 1e-12));
        s.set_lower(0, 1.0);
        let mut plan = vec![0.0; 6];
        s.project(&mut plan, &previous);
        assert!((plan[0] - 1.0).abs() < 1e-12, "{plan:?}");
        assert!(s.contains(&plan, &previous, 1e-12));
    }

    #[test]
    fn rate_rows_pair_consecutive_samples() {
        let s = space();
        assert_eq!(s.rate_rows(), 4);
        let e = s.rate_entries(10);
        assert_eq!(e.len(), 8);
        assert_eq!(e[0], ((10, 2), 1.0));
        assert_eq!(e[1], ((10, 0), -1.0));
        assert_eq!(e[4], ((12, 4), 1.0));
    }
}
