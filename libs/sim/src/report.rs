//! `safe-capture model`: the servicer model evaluated at one state, in the conventions of
//! Featherstone and Pinocchio so that engineers can compare it with other tools.
//!
//! * `position`: base-frame origin in the inertial frame [m]
//! * `quaternion`: scalar-first, rotates base-frame vectors into the inertial frame
//! * `velocity`: base-origin velocity in the inertial frame [m/s]
//! * `omega`: base angular velocity in the base frame [rad/s]
//! * `theta` [rad], `theta_dot` [rad/s], `tau` [N m] (7 each)
//! * `force_b`, `torque_b`: base frame, about the base-frame origin [N, N m]
//!
//! Generalised velocity ν = [base-origin linear velocity in the base frame, base angular
//! velocity in the base frame, θ̇] (free-flyer convention); `mass_matrix` (13×13),
//! `bias` (= nonlinear effects, no gravity) and `nu_dot` (= Pinocchio's `aba`) are in that
//! basis. No gravity acts inside the model: orbital gravity moves the whole system and is
//! not part of these internal dynamics.

use nalgebra::Vector3;
use sc_models::quat;
use sc_multibody::{NJ, Robot, Vector7, Vector13};
use serde::{Deserialize, Serialize};

/// Input state of `safe-capture model --state STATE.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelState {
    pub position: [f64; 3],
    pub quaternion: [f64; 4],
    pub velocity: [f64; 3],
    pub omega: [f64; 3],
    pub theta: [f64; NJ],
    pub theta_dot: [f64; NJ],
    #[serde(default)]
    pub force_b: [f64; 3],
    #[serde(default)]
    pub torque_b: [f64; 3],
    #[serde(default)]
    pub tau: [f64; NJ],
}

/// A point with its position and Jacobian.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointReport {
    pub name: String,
    /// Radius [m] (collision spheres) or 0 (end-effector).
    pub radius: f64,
    /// Position relative to the base origin, base frame [m].
    pub position_b: [f64; 3],
    /// Position in the inertial frame [m].
    pub position_i: [f64; 3],
    /// ∂p_B/∂θ, base frame, 3×7 rows [m/rad].
    pub jacobian_b: Vec<Vec<f64>>,
}

/// Output of `safe-capture model`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelReport {
    pub conventions: String,
    pub total_mass: f64,
    /// System CoM relative to the base origin, base frame [m].
    pub com_b: [f64; 3],
    pub nu: [f64; 13],
    pub mass_matrix: Vec<Vec<f64>>,
    pub bias: Vec<f64>,
    pub nu_dot: Vec<f64>,
    pub end_effector: PointReport,
    /// End-effector geometric Jacobian [linear; angular], base frame, 6×7.
    pub end_effector_jacobian_b: Vec<Vec<f64>>,
    pub collision_spheres: Vec<PointReport>,
}

/// Why a model state was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelStateError {
    #[error("`{0}` has a non-finite component")]
    NonFinite(&'static str),
    #[error("`quaternion` = {0:?} is not a unit quaternion (norm {1})")]
    Quaternion([f64; 4], f64),
    #[error("forward dynamics failed (singular mass matrix)")]
    Singular,
}

fn rows<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> Vec<Vec<f64>> {
    (0..R)
        .map(|i| (0..C).map(|j| m[(i, j)]).collect())
        .collect()
}

/// Every component finite, and the quaternion of unit norm (within 1e-6): the
/// quaternion normalised.
fn checked_attitude(s: &ModelState) -> Result<quat::Quat, ModelStateError> {
    let checks: [(&'static str, &[f64]); 9] = [
        ("position", &s.position),
        ("quaternion", &s.quaternion),
        ("velocity", &s.velocity),
        ("omega", &s.omega),
        ("theta", &s.theta),
        ("theta_dot", &s.theta_dot),
        ("force_b", &s.force_b),
        ("torque_b", &s.torque_b),
        ("tau", &s.tau),
    ];
    for (name, v) in checks {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(ModelStateError::NonFinite(name));
        }
    }
    let n = quat::norm(&s.quaternion);
    if (n - 1.0).abs() > 1e-6 {
        return Err(ModelStateError::Quaternion(s.quaternion, n));
    }
    quat::normalized(&s.quaternion).ok_or(ModelStateError::Quaternion(s.quaternion, n))
}

/// The collision spheres at the state `kin`, placed in the inertial frame by the base
/// position `p0` and attitude `r_ib`.
fn sphere_reports(
    robot: &Robot,
    kin: &sc_multibody::Kinematics,
    p0: &Vector3<f64>,
    r_ib: &nalgebra::Matrix3<f64>,
) -> Vec<PointReport> {
    robot
        .sphere_states(kin)
        .into_iter()
        .enumerate()
        .map(|(i, sp)| {
            let cs = &robot.collision_spheres()[i];
            PointReport {
                name: format!("{}#{}", cs.urdf_link, cs.urdf_index),
                radius: sp.radius,
                position_b: sp.center.into(),
                position_i: (p0 + r_ib * sp.center).into(),
                jacobian_b: rows(&sp.jacobian),
            }
        })
        .collect()
}

/// Evaluates the model at `s`.
pub fn evaluate_model(robot: &Robot, s: &ModelState) -> Result<ModelReport, ModelStateError> {
    let q = checked_attitude(s)?;
    let r_ib = quat::to_matrix(&q);
    let v3 = |a: [f64; 3]| Vector3::new(a[0], a[1], a[2]);
    let theta = Vector7::from_column_slice(&s.theta);
    let theta_dot = Vector7::from_column_slice(&s.theta_dot);
    let mut nu = Vector13::zeros();
    nu.fixed_rows_mut::<3>(0)
        .copy_from(&(r_ib.transpose() * v3(s.velocity)));
    nu.fixed_rows_mut::<3>(3).copy_from(&v3(s.omega));
    nu.fixed_rows_mut::<NJ>(6).copy_from(&theta_dot);
    let mut u = Vector13::zeros();
    u.fixed_rows_mut::<3>(0).copy_from(&v3(s.force_b));
    u.fixed_rows_mut::<3>(3).copy_from(&v3(s.torque_b));
    u.fixed_rows_mut::<NJ>(6)
        .copy_from(&Vector7::from_column_slice(&s.tau));
    let m = robot.mass_matrix(&theta);
    let bias = robot.nonlinear_effects(&theta, &nu);
    let nu_dot = robot
        .forward_dynamics(&theta, &nu, &u)
        .ok_or(ModelStateError::Singular)?;
    let kin = robot.kinematics_vel(&theta, &theta_dot);
    let p0 = v3(s.position);
    let ee = robot.ee_position(&kin);
    let jee = robot.ee_jacobian(&kin);
    let jee_lin: nalgebra::SMatrix<f64, 3, NJ> = jee.fixed_rows::<3>(0).into();
    let spheres = sphere_reports(robot, &kin, &p0, &r_ib);
    Ok(ModelReport {
        conventions: "nu = [v_base (base frame), omega_base (base frame), theta_dot]; \
                      quaternion scalar-first base->inertial; no gravity"
            .into(),
        total_mass: robot.total_mass(),
        com_b: robot.center_of_mass(&theta).into(),
        nu: nu.into(),
        mass_matrix: rows(&m),
        bias: bias.iter().copied().collect(),
        nu_dot: nu_dot.iter().copied().collect(),
        end_effector: PointReport {
            name: "end_effector".into(),
            radius: 0.0,
            position_b: ee.into(),
            position_i: (p0 + r_ib * ee).into(),
            jacobian_b: rows(&jee_lin),
        },
        end_effector_jacobian_b: rows(&jee),
        collision_spheres: spheres,
    })
}
