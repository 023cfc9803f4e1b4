//! Plot series of bounded size, filled one sample at a time while the plant log streams
//! by: a plot cannot show more points than it has pixels, so a long log must not keep
//! more than a fixed number of points per line.
//!
//! - [`Decimator`]: a line `(a, b)` in sample order. Up to `capacity` samples every
//!   sample is kept; beyond, buckets of consecutive samples (8 at first), each kept as its
//!   first, smallest-`b`, largest-`b` and last point (the extremes stay: a minimum
//!   distance or a spike is drawn). When `capacity / 4` buckets are full, neighbours are
//!   merged pairwise and the bucket width doubles: at most `capacity` points.
//! - [`PathDecimator`]: a track `(East, North)` for the map. Up to `capacity` points every
//!   point is kept; beyond, a point is kept when it is at least a tolerance away from the
//!   last kept one (radial-distance thinning), the tolerance doubling whenever the buffer
//!   fills: every logged position stays within the tolerance of a kept one, however the
//!   motion is spread over the log (a tow that arrives early and then lies still for
//!   days keeps its corners).
//! - [`StrideBuffer`]: whole rows (several values of one instant, e.g. the poses of the
//!   three vessels) at an adaptive stride: every `s`-th row, `s` doubling when the buffer
//!   is full, plus always the last row. Up to `capacity` rows every row is kept.

/// A point kept by a [`Decimator`]: sample number and the two values.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    index: u64,
    a: f64,
    b: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Bucket {
    first: Point,
    min: Point,
    max: Point,
    last: Point,
    count: u64,
}

impl Bucket {
    fn new(p: Point) -> Self {
        Bucket {
            first: p,
            min: p,
            max: p,
            last: p,
            count: 1,
        }
    }

    fn add(&mut self, p: Point) {
        // Strict comparisons: the first of equal extremes stays (as `plots::decimate`).
        if p.b < self.min.b {
            self.min = p;
        }
        if p.b > self.max.b {
            self.max = p;
        }
        self.last = p;
        self.count += 1;
    }

    fn merge(self, next: Bucket) -> Bucket {
        Bucket {
            first: self.first,
            min: if next.min.b < self.min.b {
                next.min
            } else {
                self.min
            },
            max: if next.max.b > self.max.b {
                next.max
            } else {
                self.max
            },
            last: next.last,
            count: self.count + next.count,
        }
    }
}

/// A line of bounded size that keeps each bucket's extremes (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Decimator {
    capacity: usize,
    /// Every sample, until there are more than `capacity`.
    raw: Vec<(f64, f64)>,
    /// Then buckets of `width` samples.
    buckets: Vec<Bucket>,
    width: u64,
    samples: u64,
}

/// Samples per bucket when the raw samples become buckets.
const FIRST_WIDTH: u64 = 8;

impl Decimator {
    /// A decimator of at most `capacity` points (at least 8).
    #[must_use]
    pub fn new(capacity: usize) -> Self {
        Decimator {
            capacity: capacity.max(8),
            raw: Vec::new(),
            buckets: Vec::new(),
            width: FIRST_WIDTH,
            samples: 0,
        }
    }

    /// Adds a sample; pairs with a value that is not finite are left out (they are not
    /// drawn).
    pub fn push(&mut self, a: f64, b: f64) {
        if !(a.is_finite() && b.is_finite()) {
            return;
        }
        let index = self.samples;
        self.samples += 1;
        if self.buckets.is_empty() {
            if self.raw.len() < self.capacity {
                self.raw.push((a, b));
                return;
            }
            self.bucket_raw();
        }
        let p = Point { index, a, b };
        match self.buckets.last_mut() {
            Some(last) if last.count < self.width => last.add(p),
            _ => {
                if self.buckets.len() >= self.capacity / 4 {
                    self.halve();
                }
                self.buckets.push(Bucket::new(p));
            }
        }
    }

    /// The raw samples as buckets of [`FIRST_WIDTH`].
    fn bucket_raw(&mut self) {
        let raw = std::mem::take(&mut self.raw);
        let width = usize::try_from(FIRST_WIDTH).unwrap_or(8);
        self.buckets = raw
            .chunks(width)
            .enumerate()
            .map(|(c, chunk)| {
                let point = |j: usize| Point {
                    index: (c * width + j) as u64,
                    a: chunk[j].0,
                    b: chunk[j].1,
                };
                let mut bucket = Bucket::new(point(0));
                for j in 1..chunk.len() {
                    bucket.add(point(j));
                }
                bucket
            })
            .collect();
        self.width = FIRST_WIDTH;
    }

    /// Merges neighbouring buckets pairwise: half the buckets, twice the width.
    fn halve(&mut self) {
        let merged: Vec<Bucket> = self
            .buckets
            .chunks(2)
            .map(|pair| match pair {
                [a, b] => a.merge(*b),
                [a] => *a,
                _ => unreachable!("chunks(2) yields one or two"),
            })
            .collect();
        self.buckets = merged;
        self.width *= 2;
    }

    /// Finite samples pushed.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Points kept now (at most `capacity`).
    #[must_use]
    pub fn len(&self) -> usize {
        if self.buckets.is_empty() {
            self.raw.len()
        } else {
            self.buckets.iter().map(|b| distinct(b).len()).sum()
        }
    }

    /// True when nothing was pushed.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.samples == 0
    }

    /// The kept points `(a, b)` in sample order.
    #[must_use]
    pub fn points(&self) -> Vec<(f64, f64)> {
        if self.buckets.is_empty() {
            return self.raw.clone();
        }
        let mut out = Vec::with_capacity(4 * self.buckets.len());
        for bucket in &self.buckets {
            out.extend(distinct(bucket).into_iter().map(|p| (p.a, p.b)));
        }
        out
    }
}

/// The bucket's distinct points in sample order.
fn distinct(b: &Bucket) -> Vec<Point> {
    let mut pts = vec![b.first, b.min, b.max, b.last];
    pts.sort_by_key(|p| p.index);
    pts.dedup_by_key(|p| p.index);
    pts
}

/// A path of bounded size (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PathDecimator {
    capacity: usize,
    points: Vec<(f64, f64)>,
    /// `None` while every point is kept.
    tolerance: Option<f64>,
    last: Option<(f64, f64)>,
}

/// Distance between two positions, at most `f64::MAX`: an infinite gap (two positions
/// near `f64::MAX` of opposite signs) would pass every tolerance and keep
/// [`PathDecimator::thin`] doubling it for ever.
fn gap(p: (f64, f64), q: (f64, f64)) -> f64 {
    (p.0 - q.0).hypot(p.1 - q.1).min(f64::MAX)
}

impl PathDecimator {
    /// A path of at most `capacity` points (at least 8) plus the last one.
    #[must_use]
    pub fn new(capacity: usize) -> Self {
        PathDecimator {
            capacity: capacity.max(8),
            points: Vec::new(),
            tolerance: None,
            last: None,
        }
    }

    /// Adds a position; pairs with a value that is not finite are left out.
    pub fn push(&mut self, a: f64, b: f64) {
        if !(a.is_finite() && b.is_finite()) {
            return;
        }
        let p = (a, b);
        self.last = Some(p);
        let tol = match self.tolerance {
            None if self.points.len() < self.capacity => {
                self.points.push(p);
                return;
            }
            None => {
                // Full: from here on thin by distance, starting from the mean spacing
                // the path would have at a quarter of the capacity.
                let length: f64 = self.points.windows(2).map(|w| gap(w[0], w[1])).sum();
                let tol = (length / (self.capacity / 4) as f64).max(f64::MIN_POSITIVE);
                self.thin(tol);
                self.tolerance.unwrap_or(tol)
            }
            Some(tol) => tol,
        };
        if self.points.last().is_none_or(|&q| gap(p, q) >= tol) {
            self.points.push(p);
            if self.points.len() >= self.capacity {
                self.thin(2.0 * tol);
            }
        }
    }

    /// Keeps the points at least `tol` from the previous kept one, doubling `tol` until
    /// at most half the capacity remain.
    fn thin(&mut self, mut tol: f64) {
        loop {
            let mut kept: Vec<(f64, f64)> = Vec::with_capacity(self.points.len());
            for &p in &self.points {
                if kept.last().is_none_or(|&q| gap(p, q) >= tol) {
                    kept.push(p);
                }
            }
            self.points = kept;
            if self.points.len() < self.capacity / 2 {
                break;
            }
            tol *= 2.0;
        }
        self.tolerance = Some(tol);
    }

    /// The distance within which every position pushed has a kept point (0 while every
    /// point is kept).
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        self.tolerance.unwrap_or(0.0)
    }

    /// The kept points in order, the last position included.
    #[must_use]
    pub fn points(&self) -> Vec<(f64, f64)> {
        let mut out = self.points.clone();
        if let Some(l) = self.last {
            if out.last() != Some(&l) {
                out.push(l);
            }
        }
        out
    }
}

/// Rows of `N` values at an adaptive stride (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StrideBuffer<const N: usize> {
    capacity: usize,
    stride: u64,
    rows: Vec<(u64, [f64; N])>,
    last: Option<(u64, [f64; N])>,
    pushed: u64,
}

impl<const N: usize> StrideBuffer<N> {
    /// A buffer of at most `capacity` strided rows (at least 2) plus the last row.
    #[must_use]
    pub fn new(capacity: usize) -> Self {
        StrideBuffer {
            capacity: capacity.max(2),
            stride: 1,
            rows: Vec::new(),
            last: None,
            pushed: 0,
        }
    }

    /// Adds a row.
    pub fn push(&mut self, row: [f64; N]) {
        let index = self.pushed;
        self.pushed += 1;
        self.last = Some((index, row));
        if !index.is_multiple_of(self.stride) {
            return;
        }
        if self.rows.len() == self.capacity {
            self.stride *= 2;
            let stride = self.stride;
            self.rows.retain(|(i, _)| i.is_multiple_of(stride));
            if !index.is_multiple_of(stride) {
                return;
            }
        }
        self.rows.push((index, row));
    }

    /// Rows pushed.
    #[must_use]
    pub fn pushed(&self) -> u64 {
        self.pushed
    }

    /// The kept rows in order, the last row included.
    #[must_use]
    pub fn rows(&self) -> Vec<[f64; N]> {
        let mut out: Vec<[f64; N]> = self.rows.iter().map(|(_, r)| *r).collect();
        if let Some((i, r)) = self.last {
            if self.rows.last().is_none_or(|(j, _)| *j != i) {
                out.push(r);
            }
        }
        out
    }

    /// Column `k` of [`StrideBuffer::rows`].
    #[must_use]
    pub fn column(&self, k: usize) -> Vec<f64> {
        self.rows().iter().map(|r| r[k]).collect()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// splitmix64: seeded, reproducible inputs without a dependency.
    pub(crate) fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn below_capacity_every_sample_is_kept() {
        let mut r = rng(1);
        let mut d = Decimator::new(1000);
        let pts: Vec<(f64, f64)> = (0..1000).map(|i| (f64::from(i), r())).collect();
        for &(a, b) in &pts {
            d.push(a, b);
        }
        d.push(f64::NAN, 1.0);
        assert_eq!(d.points(), pts);
    }

    #[test]
    fn bounded_extremes_kept_order_kept() {
        for seed in 0..20 {
            let mut r = rng(seed);
            let cap = 64;
            let mut d = Decimator::new(cap);
            let n = 10_000 + (r() * 50_000.0) as usize;
            let mut lo = (0.0, f64::INFINITY);
            let mut hi = (0.0, f64::NEG_INFINITY);
            for i in 0..n {
                let t = i as f64 * 0.1;
                let v = (t * 0.01).sin() + 0.2 * r() + if r() < 1e-4 { 5.0 } else { 0.0 };
                if v < lo.1 {
                    lo = (t, v);
                }
                if v > hi.1 {
                    hi = (t, v);
                }
                d.push(t, v);
                assert!(d.len() <= cap, "seed {seed}: {} points", d.len());
            }
            let p = d.points();
            assert!(p.len() <= cap && p.len() >= cap / 8, "{}", p.len());
            assert!(p.contains(&lo) && p.contains(&hi), "seed {seed}");
            assert!(p.windows(2).all(|w| w[0].0 < w[1].0));
            assert_eq!(p.first().map(|p| p.0), Some(0.0));
            assert_eq!(p.last().map(|p| p.0), Some((n - 1) as f64 * 0.1));
        }
    }

    #[test]
    fn stride_buffer_is_bounded_and_keeps_ends() {
        let mut b = StrideBuffer::<2>::new(100);
        for i in 0..100 {
            b.push([f64::from(i), 0.0]);
        }
        assert_eq!(b.rows().len(), 100, "every row up to the capacity");
        for n in [101usize, 1000, 12_345, 100_000] {
            let mut b = StrideBuffer::<2>::new(100);
            for i in 0..n {
                b.push([i as f64, 1.0]);
            }
            let t = b.column(0);
            assert!(t.len() <= 101, "{n}: {}", t.len());
            assert!(t.len() > 50, "{n}: {}", t.len());
            assert_eq!(t[0], 0.0);
            assert_eq!(*t.last().expect("last"), (n - 1) as f64);
            // Evenly strided before the last row.
            let s = t[1] - t[0];
            assert!(t[..t.len() - 1].windows(2).all(|w| w[1] - w[0] == s));
        }
    }

    #[test]
    fn a_path_keeps_its_corners_however_long_it_lies_still() {
        // An L (10 m North, then 10 m East) in 2 000 samples, then 200 000 samples still
        // with millimetre jitter.
        let mut r = rng(7);
        let cap = 256;
        let mut d = PathDecimator::new(cap);
        let mut truth = Vec::new();
        for i in 0..202_000 {
            let s = (f64::from(i) * 0.01).min(20.0);
            let (mut x, mut y) = if s <= 10.0 {
                (s, 0.0)
            } else {
                (10.0, s - 10.0)
            };
            if i >= 2000 {
                x += 1e-3 * (r() - 0.5);
                y += 1e-3 * (r() - 0.5);
            }
            d.push(y, x);
            truth.push((y, x));
            assert!(d.points().len() <= cap + 1);
        }
        let tol = d.tolerance();
        assert!(tol > 0.0 && tol < 0.5, "tolerance {tol}");
        let kept = d.points();
        // Every logged position is within the tolerance of a kept point: the corner too.
        for &p in truth.iter().step_by(97).chain([(0.0, 10.0)].iter()) {
            let near = kept
                .iter()
                .map(|&q| gap(p, q))
                .fold(f64::INFINITY, f64::min);
            assert!(near <= tol + 1e-12, "{p:?}: {near} > {tol}");
        }
        assert_eq!(kept.first(), Some(&(0.0, 0.0)));
        // Up to the capacity, every point.
        let mut e = PathDecimator::new(cap);
        for i in 0..cap {
            e.push(i as f64, 0.0);
        }
        assert_eq!(e.points().len(), cap);
        assert_eq!(e.tolerance(), 0.0);
    }

    #[test]
    fn a_path_of_positions_near_f64_max_thins_in_bounded_time() {
        // Positions of opposite signs near f64::MAX are an infinite distance apart; the
        // thinning used to double its tolerance for ever (a hang of the analyzer on a log
        // with absurd coordinates).
        let cap = 8;
        let mut d = PathDecimator::new(cap);
        for i in 0..1000 {
            let s = if i % 2 == 0 { 1.0 } else { -1.0 };
            d.push(s * f64::MAX, -s * 1.7e308);
            assert!(d.points().len() <= cap + 1, "{} points", d.points().len());
        }
        assert_eq!(d.points().first(), Some(&(f64::MAX, -1.7e308)));
        assert_eq!(d.points().last(), Some(&(-f64::MAX, 1.7e308)));
    }
}
