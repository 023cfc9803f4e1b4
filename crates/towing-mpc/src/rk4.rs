//! Fixed-step RK4 over one sample with the inputs held (zero-order hold), and its
//! forward-mode derivative.
//!
//! The value recursion is the plant's `World::step` arithmetic, operation for
//! operation (`x_t = x + 0.5 h k_1`, ..., `x += h / 6 (k_1 + 2 k_2 + 2 k_3 + k_4)`),
//! so a model with the plant's forces and substep reproduces the plant to rounding.
//!
//! The derivative differentiates that recursion exactly (not the ODE): with
//! `S_x = dx / dx_0` (6x6) and `S_p = dx / dp` (6xNP), at each stage
//! `dk = A(x_t) S_t (+ B(x_t))` with `A = df/dx`, `B = df/dp` of the continuous
//! dynamics and `S_t` the stage point's sensitivity (`S + c h dk_prev`), and
//! `S += h / 6 (dk_1 + 2 dk_2 + 2 dk_3 + dk_4)`. The result is the Jacobian of the
//! discrete map the model evaluates, to rounding.
//!
//! `A` and `B` of a vessel model are sparse ([`StageJacobian`]): nothing depends on
//! the position (translation invariance), the kinematics `R(psi) nu` do not
//! depend on the inputs, and the inputs enter `nu_dot` only. The products use that
//! structure (18 instead of 36 multiplications per column). Everything lives on
//! the stack (fixed-size arrays): no allocation.

use nalgebra::{Matrix3, SMatrix};

/// A 6-state vector.
pub(crate) type State = [f64; 6];

/// `n` RK4 substeps of `h` from `x`, `f` the continuous dynamics with the inputs
/// already bound.
#[inline(always)]
pub(crate) fn integrate<F: FnMut(&State) -> State>(
    mut f: F,
    x0: &State,
    n: usize,
    h: f64,
) -> State {
    let mut x = *x0;
    let mut xt = [0.0; 6];
    for _ in 0..n {
        let k1 = f(&x);
        for i in 0..6 {
            xt[i] = x[i] + 0.5 * h * k1[i];
        }
        let k2 = f(&xt);
        for i in 0..6 {
            xt[i] = x[i] + 0.5 * h * k2[i];
        }
        let k3 = f(&xt);
        for i in 0..6 {
            xt[i] = x[i] + h * k3[i];
        }
        let k4 = f(&xt);
        for i in 0..6 {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    x
}

/// The Jacobians of a vessel's continuous dynamics `f(x, p)`, `x = [x, y, psi, u,
/// v, r]`, at one point:
///
/// ```text
/// A = df/dx = [ 0 0 eta_psi[0] c  -s  0 ]      B = df/dp = [  0   ]
///             [ 0 0 eta_psi[1] s   c  0 ]                  [  0   ]
///             [ 0 0 0          0   0  1 ]                  [  0   ]
///             [ 0 0 nu_psi     nu_nu    ]                  [ nu_p ]
/// ```
///
/// with `(c, s) = (cos psi, sin psi)` (`eta_dot = R(psi) nu`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StageJacobian<const NP: usize> {
    /// `d(x_dot, y_dot) / d psi`.
    pub eta_psi: [f64; 2],
    /// `(cos psi, sin psi)`.
    pub cos_sin: [f64; 2],
    /// `d nu_dot / d psi`.
    pub nu_psi: [f64; 3],
    /// `d nu_dot / d nu`.
    pub nu_nu: Matrix3<f64>,
    /// `d nu_dot / d p`, one column per input.
    pub nu_p: [[f64; 3]; NP],
}

impl<const NP: usize> StageJacobian<NP> {
    /// The kinematic rows at state `x` (`(s, c)` = `x[2].sin_cos()`, computed once
    /// by the caller), the kinetic rows given.
    #[inline(always)]
    pub(crate) fn new(
        x: &State,
        (s, c): (f64, f64),
        nu_psi: [f64; 3],
        nu_nu: Matrix3<f64>,
        nu_p: [[f64; 3]; NP],
    ) -> Self {
        let (u, v) = (x[3], x[4]);
        StageJacobian {
            eta_psi: [-s * u - c * v, c * u - s * v],
            cos_sin: [c, s],
            nu_psi,
            nu_nu,
            nu_p,
        }
    }

    /// `A col` for one sensitivity column.
    #[inline(always)]
    fn apply(&self, col: &State) -> State {
        let [c, s] = self.cos_sin;
        let (p, u, v, r) = (col[2], col[3], col[4], col[5]);
        let j = &self.nu_nu;
        [
            self.eta_psi[0] * p + c * u - s * v,
            self.eta_psi[1] * p + s * u + c * v,
            r,
            self.nu_psi[0] * p + j[(0, 0)] * u + j[(0, 1)] * v + j[(0, 2)] * r,
            self.nu_psi[1] * p + j[(1, 0)] * u + j[(1, 1)] * v + j[(1, 2)] * r,
            self.nu_psi[2] * p + j[(2, 0)] * u + j[(2, 1)] * v + j[(2, 2)] * r,
        ]
    }

    /// `A col + B e_k` for the sensitivity column of input `k`.
    #[inline(always)]
    fn apply_input(&self, col: &State, k: usize) -> State {
        let mut out = self.apply(col);
        for i in 0..3 {
            out[3 + i] += self.nu_p[k][i];
        }
        out
    }

    /// As a dense `(A, B)` (tests).
    #[cfg(test)]
    pub(crate) fn dense(&self) -> (SMatrix<f64, 6, 6>, SMatrix<f64, 6, NP>) {
        let a = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
            let mut e = [0.0; 6];
            e[j] = 1.0;
            self.apply(&e)[i]
        });
        let b =
            SMatrix::<f64, 6, NP>::from_fn(|i, k| if i < 3 { 0.0 } else { self.nu_p[k][i - 3] });
        (a, b)
    }
}

/// `s + w d`, column by column.
#[inline(always)]
fn axpy<const K: usize>(s: &[State; K], w: f64, d: &[State; K]) -> [State; K] {
    std::array::from_fn(|k| std::array::from_fn(|i| s[k][i] + w * d[k][i]))
}

/// [`integrate`] plus the exact Jacobians of the result w.r.t. `x0` and the held
/// input `p`: returns `(x_n, dx_n/dx0, dx_n/dp)`. `f` returns the value and the
/// continuous Jacobians at a point; its values are those [`integrate`] would use,
/// so `x_n` is bit-identical to [`integrate`]'s.
#[inline(always)]
pub(crate) fn integrate_linearised<const NP: usize, F>(
    mut f: F,
    x0: &State,
    n: usize,
    h: f64,
) -> (State, SMatrix<f64, 6, 6>, SMatrix<f64, 6, NP>)
where
    F: FnMut(&State) -> (State, StageJacobian<NP>),
{
    let mut x = *x0;
    // Sensitivities as arrays of columns.
    let mut sx: [State; 6] = std::array::from_fn(|j| std::array::from_fn(|i| f64::from(i == j)));
    let mut sp: [State; NP] = [[0.0; 6]; NP];
    let mut xt = [0.0; 6];
    let dx = |jac: &StageJacobian<NP>, s: &[State; 6]| -> [State; 6] {
        std::array::from_fn(|k| jac.apply(&s[k]))
    };
    let dp = |jac: &StageJacobian<NP>, s: &[State; NP]| -> [State; NP] {
        std::array::from_fn(|k| jac.apply_input(&s[k], k))
    };
    for _ in 0..n {
        // Stage 1 at x.
        let (k1, a) = f(&x);
        let (dk1x, dk1p) = (dx(&a, &sx), dp(&a, &sp));
        for i in 0..6 {
            xt[i] = x[i] + 0.5 * h * k1[i];
        }
        // Stage 2 at x + h/2 k1.
        let (k2, a) = f(&xt);
        let dk2x = dx(&a, &axpy(&sx, 0.5 * h, &dk1x));
        let dk2p = dp(&a, &axpy(&sp, 0.5 * h, &dk1p));
        for i in 0..6 {
            xt[i] = x[i] + 0.5 * h * k2[i];
        }
        // Stage 3 at x + h/2 k2.
        let (k3, a) = f(&xt);
        let dk3x = dx(&a, &axpy(&sx, 0.5 * h, &dk2x));
        let dk3p = dp(&a, &axpy(&sp, 0.5 * h, &dk2p));
        for i in 0..6 {
            xt[i] = x[i] + h * k3[i];
        }
        // Stage 4 at x + h k3.
        let (k4, a) = f(&xt);
        let dk4x = dx(&a, &axpy(&sx, h, &dk3x));
        let dk4p = dp(&a, &axpy(&sp, h, &dk3p));
        for i in 0..6 {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        let w = h / 6.0;
        for k in 0..6 {
            for i in 0..6 {
                sx[k][i] += w * (dk1x[k][i] + 2.0 * dk2x[k][i] + 2.0 * dk3x[k][i] + dk4x[k][i]);
            }
        }
        for k in 0..NP {
            for i in 0..6 {
                sp[k][i] += w * (dk1p[k][i] + 2.0 * dk2p[k][i] + 2.0 * dk3p[k][i] + dk4p[k][i]);
            }
        }
    }
    (
        x,
        SMatrix::<f64, 6, 6>::from_fn(|i, j| sx[j][i]),
        SMatrix::<f64, 6, NP>::from_fn(|i, k| sp[k][i]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A toy vessel with the structure of [`StageJacobian`]: kinematics plus
    /// `nu_dot` nonlinear in `psi`, `nu` and two inputs.
    fn f(x: &State, p: &[f64; 2]) -> State {
        let (s, c) = x[2].sin_cos();
        let (u, v, r) = (x[3], x[4], x[5]);
        [
            c * u - s * v,
            s * u + c * v,
            r,
            p[0] - 0.3 * u * u + v * r,
            -0.5 * v - u * r + p[1] * (x[2] - p[0]).sin(),
            p[0] * p[1] - 0.2 * r * r * r + 0.1 * v,
        ]
    }

    fn jac(x: &State, p: &[f64; 2]) -> (State, StageJacobian<2>) {
        let (u, v, r) = (x[3], x[4], x[5]);
        let g = (x[2] - p[0]).cos();
        let nu_nu = Matrix3::new(-0.6 * u, r, v, -r, -0.5, -u, 0.0, 0.1, -0.6 * r * r);
        let nu_p = [[1.0, -p[1] * g, p[1]], [0.0, (x[2] - p[0]).sin(), p[0]]];
        (
            f(x, p),
            StageJacobian::new(x, x[2].sin_cos(), [0.0, p[1] * g, 0.0], nu_nu, nu_p),
        )
    }

    #[test]
    fn linearised_recursion_matches_values_and_central_differences() {
        let x0 = [0.3, -0.2, 0.5, 0.1, 0.0, 0.7];
        let p = [0.8, -0.4];
        let (n, h) = (7, 0.13);
        let value = integrate(|x| f(x, &p), &x0, n, h);
        let (xn, sx, sp) = integrate_linearised(|x| jac(x, &p), &x0, n, h);
        assert_eq!(value, xn);
        let eps = 1e-6;
        for j in 0..6 {
            let (mut a, mut b) = (x0, x0);
            a[j] += eps;
            b[j] -= eps;
            let (fa, fb) = (
                integrate(|x| f(x, &p), &a, n, h),
                integrate(|x| f(x, &p), &b, n, h),
            );
            for i in 0..6 {
                let fd = (fa[i] - fb[i]) / (2.0 * eps);
                assert!(
                    (fd - sx[(i, j)]).abs() < 1e-8,
                    "dx{i}/dx0{j}: {fd} vs {}",
                    sx[(i, j)]
                );
            }
        }
        for j in 0..2 {
            let (mut a, mut b) = (p, p);
            a[j] += eps;
            b[j] -= eps;
            let (fa, fb) = (
                integrate(|x| f(x, &a), &x0, n, h),
                integrate(|x| f(x, &b), &x0, n, h),
            );
            for i in 0..6 {
                let fd = (fa[i] - fb[i]) / (2.0 * eps);
                assert!(
                    (fd - sp[(i, j)]).abs() < 1e-8,
                    "dx{i}/dp{j}: {fd} vs {}",
                    sp[(i, j)]
                );
            }
        }
    }

    /// The structured product is the dense `A S + B`.
    #[test]
    fn structured_product_is_the_dense_one() {
        let x = [1.0, 2.0, 0.4, 0.3, -0.1, 0.2];
        let (_, j) = jac(&x, &[0.5, 0.7]);
        let (a, b) = j.dense();
        let s: State = [0.1, -0.2, 0.3, 0.4, -0.5, 0.6];
        let dense = a * nalgebra::Vector6::from(s);
        let structured = j.apply(&s);
        for i in 0..6 {
            assert!((dense[i] - structured[i]).abs() < 1e-15);
        }
        let with_input = j.apply_input(&s, 1);
        for i in 0..6 {
            assert!((dense[i] + b[(i, 1)] - with_input[i]).abs() < 1e-15);
        }
        // The kinematic rows: d(x_dot)/d psi, R(psi).
        let (sn, cs) = x[2].sin_cos();
        assert!((a[(0, 2)] - (-sn * x[3] - cs * x[4])).abs() < 1e-15);
        assert!((a[(1, 3)] - sn).abs() < 1e-15 && (a[(2, 5)] - 1.0).abs() < 1e-15);
    }
}
