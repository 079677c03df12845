//! The translational filter's line-of-sight contract (docs/SAFETY.md, "The certified
//! envelope"): the servicer's own motion turns the line of sight to the grasping point at
//! most `√2 w_tr`, so that the attitude filter, whose boresight follows at most `w̄` less
//! its margins, can keep it inside the cone for every tumble of the envelope
//! (`sc_scenario::envelope`). Beyond the paper, which has no such coupling.
//!
//! Four linear rows on two unit axes `e₁, e₂` across the line of sight `s = ρ/L`
//! (`ρ = p_G − r`, `L = ‖ρ‖`, all in the inertially fixed F_R):
//! `h_k± = w_tr L ∓ e_kᵀv ≥ 0`, relative degree one,
//! `ḣ = w_tr sᵀρ̇ ∓ (ė_kᵀv + e_kᵀ(a_tide + R_RH f_H/m))`. The axes follow the line of sight
//! smoothly: `e₁ = (c × s)/‖c × s‖`, `e₂ = s × e₁`, with `c` one fixed unit vector across
//! the corridor axis `d`. Then `σ = ‖c × s‖ ≥ cos∠(s, ±d)`, and inside the certified set
//! (the servicer in the corridor and outside the zone) the line of sight is at most
//! `asin(sin ψ + ‖p_G‖(1 + sin ψ)/L_min)` off the axis, which the scenario's validation
//! keeps below `acos(MIN_SIGMA)` (`sc_scenario::envelope`): `σ` is bounded away from 0.
//! Where it is not (outside the certified set: `σ < MIN_SIGMA`, `L < MIN_LOS_M`, or no valid
//! grasping point), the contract's rows are dropped and the barriers' rows still filter.

use crate::barrier::RelDegOne;
use crate::sampled::RateBounds;
use nalgebra::{Matrix3, Vector3};

/// Number of rows: `[+e₁, +e₂, −e₁, −e₂]`.
pub const ROWS: usize = 4;

/// Below this `σ = ‖c × s‖` [-] the axes are not defined well enough: the rows are dropped
/// (the scenario's validation keeps the certified set above it).
pub const MIN_SIGMA: f64 = sc_scenario::envelope::MIN_LOS_CONTRACT_SIGMA;
/// Below this line-of-sight length [m] the rows are dropped (the certified set keeps it
/// above `L_min`, the shortest line of sight the zone and the corridor allow).
pub const MIN_LOS_M: f64 = 1e-2;

/// The fixed unit vector across the corridor axis `d` (unit, F_R) the axes are built from
/// (the first of the boresight's: `sc_scenario::envelope::across_boresight`).
pub fn reference(d: &Vector3<f64>) -> Vector3<f64> {
    Vector3::from(sc_scenario::envelope::across_boresight(&[d.x, d.y, d.z])[0])
}

/// The line of sight and what its rows are built from, at one sample (F_R).
#[derive(Debug, Clone, Copy)]
pub struct LineOfSight {
    /// `ρ = p_G − r` [m] and `ρ̇` [m/s].
    pub rho: Vector3<f64>,
    pub rho_dot: Vector3<f64>,
    /// The servicer CoM's inertial velocity [m/s] and the tide's acceleration [m/s²].
    pub v: Vector3<f64>,
    pub tide: Vector3<f64>,
}

/// The axes across `s` from the reference `c`, their rates for `ṡ`, and `σ = ‖c × s‖`.
struct Axes {
    e: [Vector3<f64>; 2],
    e_dot: [Vector3<f64>; 2],
    sigma: f64,
}

fn axes(s: &Vector3<f64>, s_dot: &Vector3<f64>, c: &Vector3<f64>) -> Axes {
    let u = c.cross(s);
    let sigma = u.norm();
    let e1 = u / sigma;
    let u_dot = c.cross(s_dot);
    let e1_dot = (u_dot - e1 * e1.dot(&u_dot)) / sigma;
    let e2 = s.cross(&e1);
    let e2_dot = s_dot.cross(&e1) + s.cross(&e1_dot);
    Axes {
        e: [e1, e2],
        e_dot: [e1_dot, e2_dot],
        sigma,
    }
}

/// The four rows' terms (`[+e₁, +e₂, −e₁, −e₂]`) for the budget `w` [rad/s], mass `m`
/// [kg] and `R_HR` (the force is `f_H`), and `σ = ‖c × s‖`; `None` outside the rows'
/// domain (`L < MIN_LOS_M`, `σ < MIN_SIGMA`, or a non-finite line of sight).
pub fn terms(
    x: &LineOfSight,
    c: &Vector3<f64>,
    r_hr: &Matrix3<f64>,
    mass: f64,
    w: f64,
) -> Option<([RelDegOne<3>; ROWS], f64)> {
    let l = x.rho.norm();
    if !(l >= MIN_LOS_M && l.is_finite()) {
        return None;
    }
    let s = x.rho / l;
    if c.cross(&s).norm() < MIN_SIGMA {
        return None;
    }
    let s_dot = (x.rho_dot - s * s.dot(&x.rho_dot)) / l;
    let ax = axes(&s, &s_dot, c);
    let rows = std::array::from_fn(|k| {
        let sign = if k < 2 { 1.0 } else { -1.0 };
        let (e, e_dot) = (ax.e[k % 2] * sign, ax.e_dot[k % 2] * sign);
        RelDegOne {
            h: w * l - e.dot(&x.v),
            hdot_drift: w * s.dot(&x.rho_dot) - e_dot.dot(&x.v) - e.dot(&x.tide),
            hdot_u: r_hr * e * (-1.0 / mass),
        }
    });
    Some((rows, ax.sigma))
}

/// Bounds over the sample of the quantities the rows' `J` rests on.
#[derive(Debug, Clone, Copy)]
pub struct SampleMotion {
    /// Sample length `T` [s].
    pub period: f64,
    /// The servicer's inertial speed `V` [m/s], acceleration `A` [m/s²] and jerk [m/s³].
    pub speed: f64,
    pub accel: f64,
    pub jerk: f64,
    /// The grasping point's speed and acceleration [m/s, m/s²].
    pub grasp_speed: f64,
    pub grasp_accel: f64,
    /// The gravity model's error in acceleration [m/s²] (`D`).
    pub model_accel: f64,
}

/// `D` and `J` of every row: with `V_ρ = V + v_G`, `A_ρ = A + a_G`, `L` within
/// `[L − V_ρT, L + V_ρT]`, `Ṡ = V_ρ/L`, `S̈ = A_ρ/L + 3V_ρ²/L²`, `σ` within `σ − ṠT`:
/// `‖ė_k‖ ≤ Ṡ(1 + 1/σ)`, `‖ë_k‖ ≤ S̈(1 + 1/σ) + (2/σ + 3/σ²)Ṡ²`, `L̈ ≤ A_ρ + V_ρ²/L`, and
/// `|ḧ| ≤ w L̈ + ‖ë‖V + 2‖ė‖A + jerk`. `D` is the gravity model's error along `e_k`.
pub fn bounds(rho: f64, sigma: f64, w: f64, m: &SampleMotion) -> RateBounds {
    let t = m.period;
    let v_rho = m.speed + m.grasp_speed;
    let a_rho = m.accel + m.grasp_accel;
    let l_lo = (rho - v_rho * t).max(MIN_LOS_M);
    let s_dot = v_rho / l_lo;
    let s_ddot = a_rho / l_lo + 3.0 * v_rho * v_rho / (l_lo * l_lo);
    let sig = (sigma - s_dot * t).max(MIN_SIGMA);
    let e_dot = s_dot * (1.0 + 1.0 / sig);
    let e_ddot = s_ddot * (1.0 + 1.0 / sig) + (2.0 / sig + 3.0 / (sig * sig)) * s_dot * s_dot;
    let l_ddot = a_rho + v_rho * v_rho / l_lo;
    RateBounds {
        period: t,
        d: m.model_accel,
        j: w * l_ddot + e_ddot * m.speed + 2.0 * e_dot * m.accel + m.jerk,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_draws::lcg;

    fn draw(seed: &mut u64) -> Vector3<f64> {
        Vector3::new(lcg(seed) - 0.5, lcg(seed) - 0.5, lcg(seed) - 0.5)
    }

    /// `ḣ` of every row against a central difference of `h` along a motion with constant
    /// acceleration (servicer and grasping point), and the axes orthonormal across `s`.
    #[test]
    fn the_rows_rates_match_finite_differences() {
        let mut next = 7u64;
        let c = reference(&Vector3::new(-1.0, 0.0, 0.0));
        let (mass, w) = (250.0, 0.005);
        // a general R_HR: the force's frame must not be confused with its transpose
        let r_hr = *nalgebra::Rotation3::new(Vector3::new(0.3, -0.7, 0.5)).matrix();
        for _ in 0..200 {
            let r0 = Vector3::new(-2.0, 0.0, 0.0) + draw(&mut next);
            let v = draw(&mut next) * 0.2;
            let pg0 = draw(&mut next);
            let vg = draw(&mut next) * 0.1;
            let tide = draw(&mut next) * 1e-6;
            let f = draw(&mut next) * 7.0;
            let a = tide + f / mass;
            let at = |t: f64| LineOfSight {
                rho: (pg0 + vg * t) - (r0 + v * t + a * 0.5 * t * t),
                rho_dot: vg - (v + a * t),
                v: v + a * t,
                tide,
            };
            let Some((rows, sigma)) = terms(&at(0.0), &c, &r_hr, mass, w) else {
                continue;
            };
            assert!(sigma >= MIN_SIGMA);
            let dt = 1e-6;
            let (plus, _) = terms(&at(dt), &c, &r_hr, mass, w).unwrap();
            let (minus, _) = terms(&at(-dt), &c, &r_hr, mass, w).unwrap();
            for k in 0..ROWS {
                let fd = (plus[k].h - minus[k].h) / (2.0 * dt);
                // the force in F_H is f_H = R_HR f_R
                let model = rows[k].hdot(&(r_hr * f));
                assert!((fd - model).abs() < 1e-7, "row {k}: {fd} vs {model}");
            }
        }
    }

    /// `J` bounds `|ḧ|` along sampled motions that stay within the stated speeds and
    /// accelerations over the sample (the servicer's force turning with the body).
    #[test]
    fn the_bound_covers_the_second_derivative() {
        let mut next = 11u64;
        let c = reference(&Vector3::new(-1.0, 0.0, 0.0));
        let (mass, w, t) = (250.0, 0.005, 0.1);
        let mut checked = 0;
        for _ in 0..500 {
            let r0 = Vector3::new(-1.6, 0.0, 0.0) + draw(&mut next) * 0.4;
            let v0 = draw(&mut next) * 0.3;
            let f0 = draw(&mut next) * 14.0;
            let turn = draw(&mut next) * 0.4; // body rate turning the force [rad/s]
            let (omega_t, p0) = (draw(&mut next) * 0.3, draw(&mut next) * 1.2);
            let state = |t: f64| {
                // the servicer: force turning at `turn`, integrated exactly enough by steps
                let n = 200;
                let (mut r, mut v) = (r0, v0);
                let h = t / n as f64;
                for i in 0..n {
                    let f = nalgebra::Rotation3::new(turn * (i as f64 + 0.5) * h) * f0;
                    v += f / mass * h;
                    r += v * h;
                }
                let f = nalgebra::Rotation3::new(turn * t) * f0;
                let rot = nalgebra::Rotation3::new(omega_t * t);
                let pg = rot * p0;
                let vg = omega_t.cross(&pg);
                (r, v, f, pg, vg)
            };
            let h_at = |tt: f64, k: usize| {
                let (r, v, f, pg, vg) = state(tt);
                let x = LineOfSight {
                    rho: pg - r,
                    rho_dot: vg - v,
                    v,
                    tide: Vector3::zeros(),
                };
                let _ = f;
                terms(&x, &c, &Matrix3::identity(), mass, w).map_or(f64::NAN, |t| t.0[k].h)
            };
            let (_, _, _, pg, _) = state(0.0);
            let x0 = LineOfSight {
                rho: pg - r0,
                rho_dot: omega_t.cross(&pg) - v0,
                v: v0,
                tide: Vector3::zeros(),
            };
            let Some((_, sigma)) = terms(&x0, &c, &Matrix3::identity(), mass, w) else {
                continue;
            };
            let acc = f0.norm() / mass;
            let motion = SampleMotion {
                period: t,
                speed: v0.norm() + acc * t,
                accel: acc,
                jerk: acc * turn.norm(),
                grasp_speed: omega_t.norm() * p0.norm(),
                grasp_accel: omega_t.norm_squared() * p0.norm(),
                model_accel: 0.0,
            };
            let b = bounds(x0.rho.norm(), sigma, w, &motion);
            let dt = 1e-3;
            for k in 0..ROWS {
                for i in 1..10 {
                    let s = t * i as f64 / 10.0;
                    let dd = (h_at(s + dt, k) - 2.0 * h_at(s, k) + h_at(s - dt, k)) / (dt * dt);
                    if dd.is_nan() {
                        continue; // the motion left the rows' domain
                    }
                    checked += 1;
                    assert!(
                        dd.abs() <= b.j * (1.0 + 1e-6) + 1e-6,
                        "row {k} at {s}: {dd} > {}",
                        b.j
                    );
                }
            }
        }
        assert!(
            checked > 400 * ROWS * 9,
            "only {checked} samples inside the rows' domain"
        );
    }
}
