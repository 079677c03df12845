//! The condensed MPC gain against an independent algorithm: the finite-horizon Riccati
//! recursion (dynamic programming) of the same cost gives the same first-step gain.

use nalgebra::{Matrix3, Matrix3x6, Matrix6, Matrix6x3};
use sc_nominal::attitude_mpc::{AttitudeMpc, AttitudeMpcParams};
use sc_nominal::condensed::{CondensedGain, CondensedWeights};
use sc_nominal::translational::{TranslationalMpc, TranslationalMpcParams};

/// `u_0 = −K_0 x_0` of the backward recursion `P_N = w_N Q`,
/// `K_k = (R + Bᵀ P_{k+1} B)⁻¹ Bᵀ P_{k+1} A`, `P_k = Q + Aᵀ P_{k+1} (A − B K_k)`.
fn riccati_first_gain(
    a: &Matrix6<f64>,
    b: &Matrix6x3<f64>,
    w: &CondensedWeights,
    n: usize,
) -> Matrix3x6<f64> {
    let q = Matrix6::from_diagonal(&w.state.into());
    let r = Matrix3::identity() * w.input;
    let mut p = q * w.terminal;
    let mut k = Matrix3x6::zeros();
    for step in (0..n).rev() {
        let s = r + b.transpose() * p * b;
        k = s.try_inverse().expect("R + BᵀPB invertible") * b.transpose() * p * a;
        let stage = if step == 0 { Matrix6::zeros() } else { q };
        p = stage + a.transpose() * p * (a - b * k);
    }
    -k
}

fn close(a: &Matrix3x6<f64>, b: &Matrix3x6<f64>) -> f64 {
    (a - b).amax() / b.amax().max(1e-12)
}

#[test]
fn condensed_gain_equals_the_riccati_recursion_on_a_generic_system() {
    // a lightly coupled, unstable system with a non-diagonal input map
    let a = Matrix6::from_fn(|i, j| {
        if i == j {
            1.01
        } else {
            0.02 * ((i * 7 + j * 3) % 5) as f64 - 0.03
        }
    });
    let b =
        Matrix6x3::from_fn(|i, j| 0.1 * ((i + 2 * j) % 4) as f64 + 0.05 * (i == j) as u8 as f64);
    for (n, w) in [
        (1, [1.0; 6], 1.0, 0.1),
        (7, [2.0, 1.0, 0.5, 0.1, 0.2, 0.3], 10.0, 0.01),
        (30, [1.0, 0.0, 1.0, 5.0, 0.0, 1.0], 0.0, 1.0),
    ]
    .map(|(n, s, t, u)| {
        (
            n,
            CondensedWeights {
                state: s,
                terminal: t,
                input: u,
            },
        )
    }) {
        let g = CondensedGain::new("test", &a, &b, &w, n).unwrap();
        let k = riccati_first_gain(&a, &b, &w, n);
        let e = close(&g.k_x, &k);
        assert!(e < 1e-9, "N = {n}: relative difference {e:e}");
    }
}

#[test]
fn the_attitude_mpc_gain_is_the_riccati_gain_of_its_model() {
    let inertia = Matrix3::new(60.0, 2.0, -1.0, 2.0, 80.0, 0.5, -1.0, 0.5, 70.0);
    let p = AttitudeMpcParams {
        dt: 0.1,
        horizon: 25,
        inertia,
        weight_pointing: 50.0,
        weight_rate: 400.0,
        weight_torque: 0.05,
        weight_terminal: 20.0,
    };
    let mpc = AttitudeMpc::new(p).unwrap();
    let (a, b) = mpc.model();
    // the exact ZOH discretisation of the double integrator J ë = u
    let j_inv = inertia.try_inverse().unwrap();
    let b_exp: Matrix6x3<f64> = Matrix6x3::from_fn(|i, c| {
        if i < 3 {
            0.005 * j_inv[(i, c)]
        } else {
            0.1 * j_inv[(i - 3, c)]
        }
    });
    assert!((b - b_exp).amax() < 1e-15);
    assert!((a[(0, 3)] - 0.1).abs() < 1e-15 && a[(0, 0)] == 1.0 && a[(3, 0)] == 0.0);
    let w = CondensedWeights {
        state: [50.0, 50.0, 50.0, 400.0, 400.0, 400.0],
        terminal: 20.0,
        input: 0.05,
    };
    let e = close(mpc.gain(), &riccati_first_gain(a, b, &w, 25));
    assert!(e < 1e-9, "relative difference {e:e}");
}

#[test]
fn the_translational_mpc_gain_is_the_riccati_gain_of_the_cw_model() {
    let mpc = TranslationalMpc::new(TranslationalMpcParams {
        mean_motion: 0.0011,
        mass: 269.0,
        dt: 0.1,
        horizon: 30,
        gfc_point_r: [-2.2, 0.0, 0.0].into(),
        weight_position: 1.0,
        weight_velocity: 12.0,
        weight_force: 0.002,
        weight_terminal: 50.0,
    })
    .unwrap();
    let (a, b) = mpc.model();
    let w = CondensedWeights {
        state: [1.0, 1.0, 1.0, 12.0, 12.0, 12.0],
        terminal: 50.0,
        input: 0.002,
    };
    let k = riccati_first_gain(a, b, &w, 30);
    let g = mpc.gain();
    let k_x = Matrix3x6::from_fn(|i, j| g[(i, j)]);
    let e = close(&k_x, &k);
    assert!(e < 1e-8, "relative difference {e:e}");
}

#[test]
fn bad_parameters_are_errors_not_panics() {
    let a = Matrix6::identity();
    let b = Matrix6x3::from_element(0.1);
    let ok = CondensedWeights {
        state: [1.0; 6],
        terminal: 1.0,
        input: 1.0,
    };
    assert!(CondensedGain::new("t", &a, &b, &ok, 0).is_err());
    assert!(CondensedGain::new("t", &a, &b, &ok, 1001).is_err());
    for bad in [
        CondensedWeights { input: 0.0, ..ok },
        CondensedWeights {
            input: f64::NAN,
            ..ok
        },
        CondensedWeights {
            terminal: -1.0,
            ..ok
        },
        CondensedWeights {
            state: [1.0, 1.0, f64::INFINITY, 1.0, 1.0, 1.0],
            ..ok
        },
    ] {
        assert!(CondensedGain::new("t", &a, &b, &bad, 5).is_err(), "{bad:?}");
    }
    let base = AttitudeMpcParams {
        dt: 0.1,
        horizon: 10,
        inertia: Matrix3::identity() * 50.0,
        weight_pointing: 1.0,
        weight_rate: 1.0,
        weight_torque: 1.0,
        weight_terminal: 1.0,
    };
    assert!(AttitudeMpc::new(base).is_ok());
    for bad in [
        AttitudeMpcParams { dt: 0.0, ..base },
        AttitudeMpcParams {
            inertia: Matrix3::zeros(),
            ..base
        },
        AttitudeMpcParams {
            inertia: Matrix3::from_element(f64::NAN),
            ..base
        },
        AttitudeMpcParams {
            weight_torque: 0.0,
            ..base
        },
    ] {
        assert!(AttitudeMpc::new(bad).is_err(), "{bad:?}");
    }
}
