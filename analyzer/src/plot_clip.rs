//! Bounded drawing: chart axes that plotters can always lay out, and geometry clipped to a
//! window around the chart before plotters sees it.
//!
//! plotters rasterises a primitive over its whole extent in pixels (a horizontal line from
//! -1e9 px to 1e9 px is 2e9 pixel writes; a dashed line is cut into dashes along its whole
//! length) and its tick search loops forever on an axis that is infinite or narrower than
//! the float resolution at its magnitude. A corrupted or absurd log (a towline of
//! 1.8e308 m puts the tugs there) must give a clipped plot, not a hang, so:
//!
//! - values beyond [`PLOT_LIMIT`] (or not finite) are off scale: they widen no axis
//!   ([`range_of`]);
//! - every axis is finite, within twice the limit, and at least [`MIN_RELATIVE_WIDTH`] of
//!   its magnitude wide ([`axis`]);
//! - lines and polygons are clipped, in data coordinates, to a [`Window`] of
//!   [`MARGIN`] axis widths around the chart, points outside it are not drawn: the
//!   pixels of a primitive are bounded by the window's size (about 9 times the chart's).
//!
//! Geometry inside the window is passed through unchanged, so a plot of sane data is the
//! plot it always was.

use std::ops::Range;

/// Values of a larger magnitude are off scale (m, s, N, deg, ms: nothing the analyzer plots
/// reaches it in a sane run).
pub const PLOT_LIMIT: f64 = 1e12;

/// Smallest axis width relative to the magnitude of its ends (about 4 500 times the float
/// resolution).
pub const MIN_RELATIVE_WIDTH: f64 = 1e-12;

/// Axis widths the clipping window extends beyond the chart on each side.
pub const MARGIN: f64 = 4.0;

/// The range of the finite values within [`PLOT_LIMIT`], padded by 5 % (a constant by 10 %
/// of its magnitude, or 1 at 0) and made a safe [`axis`]; `None` without such values.
pub fn range_of<'a>(values: impl Iterator<Item = &'a f64>) -> Option<Range<f64>> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && v.abs() <= PLOT_LIMIT)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return None;
    }
    if (hi - lo) < 1e-12 {
        let pad = if lo.abs() > 1e-12 {
            lo.abs() * 0.1
        } else {
            1.0
        };
        return Some(axis(lo - pad, hi + pad));
    }
    let pad = 0.05 * (hi - lo);
    Some(axis(lo - pad, hi + pad))
}

/// An axis from `lo` to `hi` that plotters can lay out: ends clamped to twice
/// [`PLOT_LIMIT`] (not finite: -1..1), in order, and widened about its centre to at least
/// [`MIN_RELATIVE_WIDTH`] of its magnitude. A sane axis is returned unchanged.
#[must_use]
pub fn axis(lo: f64, hi: f64) -> Range<f64> {
    if !(lo.is_finite() && hi.is_finite()) {
        return -1.0..1.0;
    }
    let limit = 2.0 * PLOT_LIMIT;
    let (lo, hi) = (lo.clamp(-limit, limit), hi.clamp(-limit, limit));
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let min_width = MIN_RELATIVE_WIDTH * lo.abs().max(hi.abs());
    if hi - lo >= min_width && hi > lo {
        return lo..hi;
    }
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * min_width.max(1e-12);
    centre - half..centre + half
}

/// The area geometry may occupy: the chart's ranges extended by [`MARGIN`] widths on every
/// side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    x: (f64, f64),
    y: (f64, f64),
}

impl Window {
    /// The window around a chart of ranges `x` and `y` (finite, as [`axis`] gives).
    #[must_use]
    pub fn around(x: &Range<f64>, y: &Range<f64>) -> Self {
        let widen = |r: &Range<f64>| {
            let w = (r.end - r.start).abs() * MARGIN;
            (r.start.min(r.end) - w, r.start.max(r.end) + w)
        };
        Window {
            x: widen(x),
            y: widen(y),
        }
    }

    /// Whether `p` lies in the window (not when a coordinate is not finite).
    #[must_use]
    pub fn contains(&self, p: (f64, f64)) -> bool {
        (self.x.0..=self.x.1).contains(&p.0) && (self.y.0..=self.y.1).contains(&p.1)
    }

    /// The parts of the polyline `pts` inside the window, in order: a segment crossing
    /// the border is cut at it, a non-finite point breaks the line. A polyline inside the
    /// window comes back whole and unchanged.
    #[must_use]
    pub fn polyline(&self, pts: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
        if pts.iter().all(|&p| self.contains(p)) {
            return if pts.is_empty() {
                Vec::new()
            } else {
                vec![pts.to_vec()]
            };
        }
        let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut open = false;
        for w in pts.windows(2) {
            let Some((a, b)) = self.segment(w[0], w[1]) else {
                open = false;
                continue;
            };
            match pieces.last_mut() {
                Some(piece) if open && piece.last() == Some(&a) => piece.push(b),
                _ => pieces.push(vec![a, b]),
            }
            // The piece goes on only where the segment ended inside, uncut.
            open = b == w[1];
        }
        pieces
    }

    /// The segment `a`-`b` cut to the window (Liang-Barsky), `None` when no part of it is
    /// inside or a coordinate is not finite. Computed with half the difference, so two
    /// ends near `f64::MAX` of opposite signs do not overflow; a cut end lies on the
    /// border it was cut at (that coordinate exact, the other clamped into the window,
    /// which the float resolution of far ends needs).
    fn segment(&self, a: (f64, f64), b: (f64, f64)) -> Option<((f64, f64), (f64, f64))> {
        if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) {
            return None;
        }
        if self.contains(a) && self.contains(b) {
            return Some((a, b));
        }
        // p(s) = a + s h, s in [0, 2], h = (b - a) / 2.
        let h = (b.0 / 2.0 - a.0 / 2.0, b.1 / 2.0 - a.1 / 2.0);
        let (mut s0, mut s1) = (0.0f64, 2.0f64);
        // The border (axis, value) each end was cut at.
        let (mut enter, mut leave) = (None, None);
        for (axis, start, step, (lo, hi)) in [(0, a.0, h.0, self.x), (1, a.1, h.1, self.y)] {
            if step == 0.0 {
                if !(lo..=hi).contains(&start) {
                    return None;
                }
                continue;
            }
            let (e_lo, e_hi) = ((lo - start) / step, (hi - start) / step);
            let ((e_in, b_in), (e_out, b_out)) = if e_lo <= e_hi {
                ((e_lo, lo), (e_hi, hi))
            } else {
                ((e_hi, hi), (e_lo, lo))
            };
            if e_in > s0 {
                (s0, enter) = (e_in, Some((axis, b_in)));
            }
            if e_out < s1 {
                (s1, leave) = (e_out, Some((axis, b_out)));
            }
        }
        if s0.is_nan() || s1.is_nan() || s0 > s1 {
            return None;
        }
        let cut = |s: f64, border: Option<(usize, f64)>, end: (f64, f64)| {
            let Some((axis, value)) = border else {
                return Some(end);
            };
            let mut p = (a.0 + s * h.0, a.1 + s * h.1);
            if axis == 0 {
                p.0 = value;
            } else {
                p.1 = value;
            }
            (p.0.is_finite() && p.1.is_finite())
                .then(|| (p.0.clamp(self.x.0, self.x.1), p.1.clamp(self.y.0, self.y.1)))
        };
        Some((cut(s0, enter, a)?, cut(s1, leave, b)?))
    }

    /// The polygon `pts` cut to the window (Sutherland-Hodgman); empty when nothing of it
    /// is inside or a vertex is not finite. A polygon inside the window comes back
    /// unchanged.
    #[must_use]
    pub fn polygon(&self, pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
        if pts.iter().any(|p| !(p.0.is_finite() && p.1.is_finite())) {
            return Vec::new();
        }
        if pts.iter().all(|&p| self.contains(p)) {
            return pts.to_vec();
        }
        let mut poly = pts.to_vec();
        // Each edge of the window: axis (0 x, 1 y), bound, keep the side above it?
        for (axis, bound, above) in [
            (0, self.x.0, true),
            (0, self.x.1, false),
            (1, self.y.0, true),
            (1, self.y.1, false),
        ] {
            poly = clip_half_plane(&poly, axis, bound, above);
            if poly.is_empty() {
                break;
            }
        }
        if poly.iter().all(|p| p.0.is_finite() && p.1.is_finite()) {
            // Rounding may leave a cut vertex a hair outside.
            poly.iter()
                .map(|p| (p.0.clamp(self.x.0, self.x.1), p.1.clamp(self.y.0, self.y.1)))
                .collect()
        } else {
            Vec::new()
        }
    }
}

/// Coordinate `axis` (0 x, 1 y) of `p`.
fn coord(p: (f64, f64), axis: usize) -> f64 {
    if axis == 0 {
        p.0
    } else {
        p.1
    }
}

/// The part of polygon `poly` on one side of the line `coord(axis) = bound` (`above`: the
/// side with larger values).
fn clip_half_plane(poly: &[(f64, f64)], axis: usize, bound: f64, above: bool) -> Vec<(f64, f64)> {
    let inside = |p: (f64, f64)| {
        let c = coord(p, axis);
        if above {
            c >= bound
        } else {
            c <= bound
        }
    };
    let cross = |a: (f64, f64), b: (f64, f64)| {
        let (ca, cb) = (coord(a, axis), coord(b, axis));
        // Half differences: no overflow between ends near f64::MAX.
        let s = (bound / 2.0 - ca / 2.0) / (cb / 2.0 - ca / 2.0);
        let other = |u: f64, v: f64| u + (2.0 * s) * (v / 2.0 - u / 2.0);
        if axis == 0 {
            (bound, other(a.1, b.1))
        } else {
            (other(a.0, b.0), bound)
        }
    };
    let mut out = Vec::with_capacity(poly.len() + 4);
    for (k, &b) in poly.iter().enumerate() {
        let a = poly[(k + poly.len() - 1) % poly.len()];
        match (inside(a), inside(b)) {
            (true, true) => out.push(b),
            (true, false) => out.push(cross(a, b)),
            (false, true) => {
                out.push(cross(a, b));
                out.push(b);
            }
            (false, false) => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window() -> Window {
        // Chart 0..10 x 0..10: window -40..50 on both axes.
        Window::around(&(0.0..10.0), &(0.0..10.0))
    }

    #[test]
    fn sane_axes_and_geometry_pass_unchanged() {
        assert_eq!(axis(-3.5, 61.25), -3.5..61.25);
        let r = range_of([1.0, 3.0, 2.0].iter()).expect("range");
        assert_eq!(r, 0.9..3.1);
        let line = vec![(0.0, 0.0), (5.0, 9.0), (10.0, -20.0)];
        assert_eq!(window().polyline(&line), vec![line.clone()]);
        assert_eq!(window().polygon(&line), line);
    }

    #[test]
    fn absurd_axes_are_finite_and_wide_enough() {
        for (lo, hi) in [
            (f64::NEG_INFINITY, f64::INFINITY),
            (f64::NAN, 1.0),
            (-1.7e308, 1.7e308),
            (1e12, 1e12),
            (9.2e9, 9.2e9 + 1e-9),
            (5.0, -5.0),
        ] {
            let r = axis(lo, hi);
            assert!(
                r.start.is_finite() && r.end.is_finite(),
                "{lo}..{hi}: {r:?}"
            );
            assert!(r.end > r.start, "{lo}..{hi}: {r:?}");
            let magnitude = r.start.abs().max(r.end.abs());
            assert!(
                r.end - r.start >= 0.99 * MIN_RELATIVE_WIDTH * magnitude,
                "{r:?}"
            );
            assert!(magnitude <= 2.0 * PLOT_LIMIT + 1.0, "{r:?}");
        }
        // Values off scale widen no range.
        let r = range_of([0.0, 10.0, 1.7e308, f64::NAN, -1e300].iter()).expect("range");
        assert_eq!(r, -0.5..10.5);
        assert_eq!(range_of([f64::INFINITY, 1e13].iter()), None);
    }

    #[test]
    fn lines_are_cut_at_the_window_and_broken_at_bad_points() {
        let w = window();
        // From inside to far outside: cut at x = 50.
        let cut = w.polyline(&[(0.0, 0.0), (1.7e308, 0.0)]);
        assert_eq!(cut, vec![vec![(0.0, 0.0), (50.0, 0.0)]]);
        // Across the window between two far points of opposite signs.
        let across = w.polyline(&[(-1.7e308, 5.0), (1.7e308, 5.0)]);
        assert_eq!(across, vec![vec![(-40.0, 5.0), (50.0, 5.0)]]);
        // Entirely outside: nothing.
        assert!(w.polyline(&[(100.0, 100.0), (200.0, 300.0)]).is_empty());
        // A NaN splits the line in two.
        let split = w.polyline(&[
            (0.0, 0.0),
            (1.0, 1.0),
            (f64::NAN, 0.0),
            (2.0, 2.0),
            (3.0, 3.0),
        ]);
        assert_eq!(
            split,
            vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
        // Out and back in: two pieces, each cut at the border.
        let out_in = w.polyline(&[(0.0, 0.0), (100.0, 0.0), (0.0, 1.0)]);
        assert_eq!(out_in.len(), 2);
        assert_eq!(out_in[0], vec![(0.0, 0.0), (50.0, 0.0)]);
        assert_eq!(out_in[1][1], (0.0, 1.0));
        for p in out_in.iter().flatten() {
            assert!(w.contains(*p), "{p:?}");
        }
    }

    #[test]
    fn polygons_are_cut_to_the_window() {
        let w = window();
        let big = [
            (-1e300, -1e300),
            (1e300, -1e300),
            (1e300, 1e300),
            (-1e300, 1e300),
        ];
        let cut = w.polygon(&big);
        assert_eq!(cut.len(), 4);
        for p in &cut {
            assert!(w.contains(*p), "{p:?}");
        }
        assert!(w
            .polygon(&[(100.0, 100.0), (101.0, 100.0), (100.0, 101.0)])
            .is_empty());
        assert!(w
            .polygon(&[(0.0, 0.0), (f64::NAN, 1.0), (1.0, 0.0)])
            .is_empty());
    }
}
