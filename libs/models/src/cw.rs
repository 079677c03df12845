//! The Clohessy–Wiltshire–Hill model of relative translational motion about a
//! circular target orbit (paper, eq. "rel motion system"):
//! `ẋ_tr = A x_tr + B f_H`, `x_tr = [r_H; v_H]` in the Hill frame (R-bar, V-bar, H-bar).

use nalgebra::{Matrix6, Matrix6x3, SMatrix, Vector6};

/// Clohessy–Wiltshire model for mean motion `n` [rad/s] and servicer mass `m` [kg].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClohessyWiltshire {
    /// Mean motion n [rad/s].
    pub n: f64,
    /// Servicer mass m [kg].
    pub mass: f64,
}

impl ClohessyWiltshire {
    /// System matrix A of the paper's eq. (rel motion system).
    pub fn a(&self) -> Matrix6<f64> {
        let n = self.n;
        let mut a = Matrix6::zeros();
        a[(0, 3)] = 1.0;
        a[(1, 4)] = 1.0;
        a[(2, 5)] = 1.0;
        a[(3, 0)] = 3.0 * n * n;
        a[(3, 4)] = 2.0 * n;
        a[(4, 3)] = -2.0 * n;
        a[(5, 2)] = -n * n;
        a
    }

    /// Input matrix B = [0; I/m].
    pub fn b(&self) -> Matrix6x3<f64> {
        let mut b = Matrix6x3::zeros();
        for i in 0..3 {
            b[(3 + i, i)] = 1.0 / self.mass;
        }
        b
    }

    /// Time derivative `A x + B f`.
    pub fn derivative(&self, x: &Vector6<f64>, f: &nalgebra::Vector3<f64>) -> Vector6<f64> {
        self.a() * x + self.b() * f
    }

    /// Closed-form state-transition matrix Φ(t) of the unforced motion. With n = 0 (zero
    /// gravity) the model is a double integrator, `Φ = [I, t I; 0, I]`, the limit of
    /// the formula below (which would divide 0 by 0).
    pub fn transition(&self, t: f64) -> Matrix6<f64> {
        let n = self.n;
        if n == 0.0 {
            let mut m = Matrix6::identity();
            for i in 0..3 {
                m[(i, i + 3)] = t;
            }
            return m;
        }
        let (s, c) = (n * t).sin_cos();
        #[rustfmt::skip]
        let m = Matrix6::new(
            4.0 - 3.0 * c,          0.0, 0.0,  s / n,               2.0 * (1.0 - c) / n,         0.0,
            6.0 * (s - n * t),      1.0, 0.0, -2.0 * (1.0 - c) / n, (4.0 * s - 3.0 * n * t) / n, 0.0,
            0.0,                    0.0, c,    0.0,                 0.0,                         s / n,
            3.0 * n * s,            0.0, 0.0,  c,                   2.0 * s,                     0.0,
            -6.0 * n * (1.0 - c),   0.0, 0.0, -2.0 * s,             4.0 * c - 3.0,               0.0,
            0.0,                    0.0, -n * s, 0.0,               0.0,                         c,
        );
        m
    }

    /// Exact zero-order-hold discretisation over `dt` [s]: `x⁺ = Ad x + Bd f`.
    pub fn discretize(&self, dt: f64) -> (Matrix6<f64>, Matrix6x3<f64>) {
        let mut aug = SMatrix::<f64, 9, 9>::zeros();
        aug.fixed_view_mut::<6, 6>(0, 0).copy_from(&(self.a() * dt));
        aug.fixed_view_mut::<6, 3>(0, 6).copy_from(&(self.b() * dt));
        let e = aug.exp();
        (
            e.fixed_view::<6, 6>(0, 0).into_owned(),
            e.fixed_view::<6, 3>(0, 6).into_owned(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transition_matches_matrix_exponential() {
        let cw = ClohessyWiltshire {
            n: 0.00108,
            mass: 270.0,
        };
        for t in [0.1, 10.0, 600.0] {
            let phi = cw.transition(t);
            let e = (cw.a() * t).exp();
            assert!((phi - e).norm() < 1e-9 * e.norm(), "t = {t}");
        }
    }

    #[test]
    fn discretisation_integrates_constant_force() {
        let cw = ClohessyWiltshire {
            n: 0.00108,
            mass: 270.0,
        };
        let (ad, bd) = cw.discretize(0.1);
        let x0 = Vector6::new(1.0, -10.0, 0.5, 0.01, 0.05, 0.0);
        let f = nalgebra::Vector3::new(2.0, -7.0, 1.0);
        // RK4 with a fine step as an independent reference
        let mut x = x0;
        let h = 1e-4;
        for _ in 0..1000 {
            let k1 = cw.derivative(&x, &f);
            let k2 = cw.derivative(&(x + k1 * (h / 2.0)), &f);
            let k3 = cw.derivative(&(x + k2 * (h / 2.0)), &f);
            let k4 = cw.derivative(&(x + k3 * h), &f);
            x += (k1 + 2.0 * k2 + 2.0 * k3 + k4) * (h / 6.0);
        }
        assert!((ad * x0 + bd * f - x).norm() < 1e-12);
    }

    #[test]
    fn zero_gravity_is_a_double_integrator() {
        let cw = ClohessyWiltshire {
            n: 0.0,
            mass: 250.0,
        };
        let dt = 0.1;
        let (ad, bd) = cw.discretize(dt);
        let phi = cw.transition(dt);
        assert!(
            ad.iter()
                .chain(bd.iter())
                .chain(phi.iter())
                .all(|x| x.is_finite())
        );
        assert!((ad - phi).norm() < 1e-15, "{ad} {phi}");
        for i in 0..3 {
            assert_eq!(phi[(i, i + 3)], dt);
            assert!((bd[(i, i)] - 0.5 * dt * dt / cw.mass).abs() < 1e-18);
            assert!((bd[(i + 3, i)] - dt / cw.mass).abs() < 1e-18);
        }
        // the closed form tends to the double integrator as n → 0 (Coriolis terms 2 n t)
        let n = 1e-9;
        let small = ClohessyWiltshire { n, mass: 250.0 }.transition(dt);
        assert!((small - phi).norm() < 3.0 * n * dt, "{small}");
    }
}
