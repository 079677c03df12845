//! The conformance suite of the safety filters: the properties every [`SafetyFilter`]
//! must have, written once and run against each filter of the paper (in the style of
//! iceoryx2's conformance tests). A filter enters through a small adapter
//! ([`Conformance`]): how to build it, how to draw its inputs (near its barriers,
//! realistic, wild), its braking law, and how many cases each check must reach.
//!
//! The properties (docs/SAFETY.md, "The promise"):
//! * any input — NaN, ±∞, 1e300 anywhere — gives a finite command inside `input_bound`,
//!   with the right fault flags; so does the chain's stage at any observation;
//! * memoryless: the same input gives the same bits, whatever came before, on any thread;
//! * a feasible nominal is returned unchanged and equals the solved QP;
//! * a missing or invalid nominal gets the QP on the substitute nominal (the backup);
//! * a solver that produces no command gives the braking law, and the braking law brakes;
//! * the dumped QP is the one solved: the command is its KKT point (multipliers of our
//!   own), its brute-force minimiser (three inputs), Clarabel's solution, and the engine's
//!   recorded multipliers are the KKT ones;
//! * report names are unique.
//!
//! Where a filter's relaxed command is the engine's lexicographic relaxation of its rows
//! (translational and attitude; the robotic filter's comes from its verification), that
//! is checked too ([`Lexicographic`]).

mod common;
use common::*;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use proptest::option::weighted;
use proptest::prelude::*;
use proptest::strategy::BoxedStrategy;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use sc_cbf::robotic::{Matrix7, SphereTerms, Vector7};
use sc_cbf::{
    AttitudeFilter, AttitudeInput, Coupling, FilterOutput, FilterReport, FilterStatus,
    RoboticFilter, RoboticInput, SafetyFilter, TranslationalFilter, TranslationalInput, faults,
};
use sc_core::Observation;
use sc_models::quat::{self, Quat};
use std::fmt::Debug;
use std::sync::OnceLock;

// ================================================================== the adapter

/// A wild input of the property tests.
#[derive(Debug, Clone)]
struct Wild<I> {
    x: I,
    /// The filter's realistic base input, unchanged: it must be accepted.
    realistic: bool,
}

/// What the suite needs to know of one filter beyond [`SafetyFilter`].
trait Conformance<const M: usize, const N: usize>:
    SafetyFilter<M, N, Input: Debug + Clone + 'static> + Sized + 'static
{
    /// A fresh filter of the default scenario.
    fn fresh() -> Self;
    /// Its braking law at `x`: the substitute nominal and the command when no solver
    /// produces one.
    fn braking_law(&self, x: &Self::Input) -> SVector<f64, M>;
    /// The command when no solver produces one: the braking law, unless the filter keeps
    /// a contract with the others (the robotic filter's arm-reaction budget).
    fn emergency(&self, x: &Self::Input) -> SVector<f64, M> {
        self.braking_law(x)
    }
    /// The motion the braking law opposes (`braking_law · motion < 0` while moving).
    fn motion(x: &Self::Input) -> SVector<f64, M>;
    /// Inputs near the barriers, moving towards them, with nominals up to 1.5× the bound.
    fn cases(seed: u64, count: usize) -> Vec<(Self::Input, SVector<f64, M>)>;
    /// Seed and count of the cases of the dumped-QP checks, and what they must reach:
    /// solved cases, compared multipliers (0: the filter records none), Clarabel's
    /// agreement (fraction of the bound) and the radius of its box.
    const QP_CASES: (u64, usize);
    const MIN_SOLVED: usize;
    const MIN_DUALS: usize;
    const CLARABEL_TOL: f64;
    fn clarabel_radius(&self) -> f64;
    /// Seed and count of the cases of the substitute-nominal checks.
    const SUBSTITUTE_CASES: (u64, usize);
    /// Seed and number of input pairs of the memoryless check, and the statuses it must
    /// reach at least (skipped, solved, relaxed).
    const MEMORYLESS: (u64, usize, [usize; 3]);
    /// One input and nominal of the memoryless check (missing one time in ten).
    fn draw(rng: &mut Lcg) -> (Self::Input, Option<SVector<f64, M>>);
    /// A state and nominals that satisfy every row there.
    fn feasible() -> (Self::Input, Vec<SVector<f64, M>>);
    /// Candidate states outside the certified set (the barrier rows cannot all hold),
    /// with a nominal direction; those the filter relaxes are used.
    fn infeasible() -> Vec<(Self::Input, SVector<f64, M>)>;
    /// At least this many of [`Self::infeasible`] must be relaxed.
    const MIN_RELAXED: usize;
    /// Realistic inputs with wild values (NaN, ±∞, 1e300, 1e8) mixed in, and the scale of
    /// the nominals drawn with them.
    fn wild() -> BoxedStrategy<Wild<Self::Input>>;
    const NOMINAL_SCALE: f64;
    /// The input with every state quantity set to `v`.
    fn filled(v: f64) -> Self::Input;
    /// Every state quantity finite (the coupling aside).
    fn state_finite(x: &Self::Input) -> bool;
    /// The upstream coupling ξ finite.
    fn coupling_finite(_: &Self::Input) -> bool {
        true
    }
    /// Within every physical range (for inputs beyond them only the output is checked).
    fn sane(_: &Self::Input) -> bool {
        true
    }
    /// The filter's own checks of an output.
    fn check_output(
        _: &Self::Input,
        _: &FilterOutput<M, N>,
        _bound: f64,
    ) -> Result<(), TestCaseError> {
        Ok(())
    }
}

// ------------------------------------------------------------------ translational

impl Conformance<3, 2> for TranslationalFilter {
    fn fresh() -> Self {
        TranslationalFilter::from_scenario(&scenario(), mass())
    }
    fn braking_law(&self, x: &TranslationalInput) -> Vector3<f64> {
        self.brake(x).0
    }
    fn motion(x: &TranslationalInput) -> Vector3<f64> {
        x.v_h
    }
    fn cases(seed: u64, count: usize) -> Vec<(TranslationalInput, Vector3<f64>)> {
        tr_cases(seed, count)
    }
    const QP_CASES: (u64, usize) = (21, 200);
    const MIN_SOLVED: usize = 50;
    const MIN_DUALS: usize = 10;
    const CLARABEL_TOL: f64 = 1e-6;
    fn clarabel_radius(&self) -> f64 {
        3f64.sqrt() * self.params.force_max
    }
    const SUBSTITUTE_CASES: (u64, usize) = (8, 30);
    const MEMORYLESS: (u64, usize, [usize; 3]) = (11, 400, [20, 20, 20]);
    fn draw(rng: &mut Lcg) -> (TranslationalInput, Option<Vector3<f64>>) {
        let s = scenario();
        // inside, near and outside the corridor (5°) and the collision-avoidance zone
        let ang = (3.0 + 3.0 * rng.next()).to_radians();
        let phi = std::f64::consts::PI * rng.next();
        let dir = Vector3::new(-ang.cos(), ang.sin() * phi.cos(), ang.sin() * phi.sin());
        let r = dir * (5.0 + 3.5 * rng.next());
        let x = tr_input(&s, r, rng.v3(0.04), rng.unit_quat(), rng.v3(0.1));
        let u = rng.v3(1.5 * s.limits.force_max_n);
        (x, maybe(rng, u))
    }
    /// On the axis, far from the zone, slow.
    fn feasible() -> (TranslationalInput, Vec<Vector3<f64>>) {
        let s = scenario();
        let x = tr_input(
            &s,
            Vector3::new(-6.0, 0.05, 0.0),
            Vector3::new(0.01, 0.0, 0.0),
            quat::IDENTITY,
            Vector3::zeros(),
        );
        let nominals = vec![
            Vector3::new(0.5, -0.2, 0.1),
            Vector3::new(-1.0, 0.0, 0.3),
            Vector3::zeros(),
        ];
        (x, nominals)
    }
    /// Inside or at the zone closing fast, or at the corridor wall moving out fast.
    fn infeasible() -> Vec<(TranslationalInput, Vector3<f64>)> {
        let s = scenario();
        let mut rng = Lcg(5);
        (0..40)
            .map(|k| {
                let (r, v) = if k % 2 == 0 {
                    (
                        Vector3::new(-1.7, 0.0, 0.0) + rng.v3(0.1),
                        Vector3::new(0.3 + 0.2 * rng.next(), 0.0, 0.0) + rng.v3(0.05),
                    )
                } else {
                    let a = (4.9f64 + 0.3 * rng.next()).to_radians();
                    (
                        Vector3::new(-5.0 * a.cos(), 5.0 * a.sin(), 0.0),
                        Vector3::new(0.0, 0.1 + 0.05 * rng.next(), 0.0) + rng.v3(0.02),
                    )
                };
                let x = tr_input(&s, r, v, rng.unit_quat(), rng.v3(0.1));
                (x, rng.v3(1.0))
            })
            .collect()
    }
    const MIN_RELAXED: usize = 20;
    const NOMINAL_SCALE: f64 = 20.0;
    fn wild() -> BoxedStrategy<Wild<TranslationalInput>> {
        (
            (
                mostly3(Vector3::new(-5.0, 0.0, 0.0), 5.0, 20.0),
                mostly3(Vector3::zeros(), 0.2, 0.5),
            ),
            (
                mostly3(Vector3::new(0.0, 0.0, 1.1e-3), 1e-4, 0.01),
                mostly3(Vector3::zeros(), 1e-6, 1e-4),
            ),
            (q4(), q4(), mostly3(Vector3::zeros(), 0.2, 0.3)),
        )
            .prop_map(|((r, v), (w, wd), (qhr, qrb, wb))| Wild {
                x: TranslationalInput {
                    r_h: r,
                    v_h: v,
                    q_hr: qhr,
                    omega_h: w,
                    omega_dot_h: wd,
                    q_rb: qrb,
                    omega_b: wb,
                    com_error: (0.0, 0.0),
                    grasp_r: Vector3::new(-0.55, 0.35, 0.0),
                    grasp_v_r: Vector3::new(0.0, 0.0, -0.028),
                    target_spin: 0.08,
                },
                realistic: false,
            })
            .boxed()
    }
    fn filled(v: f64) -> TranslationalInput {
        let v3 = Vector3::from_element(v);
        TranslationalInput {
            r_h: v3,
            v_h: v3,
            q_hr: [v; 4],
            omega_h: v3,
            omega_dot_h: v3,
            q_rb: [v; 4],
            omega_b: v3,
            com_error: (v, v),
            grasp_r: v3,
            grasp_v_r: v3,
            target_spin: v,
        }
    }
    fn state_finite(x: &TranslationalInput) -> bool {
        [
            x.r_h,
            x.v_h,
            x.omega_h,
            x.omega_dot_h,
            x.omega_b,
            x.grasp_r,
            x.grasp_v_r,
        ]
        .iter()
        .all(finite)
            && x.target_spin.is_finite()
            && [x.com_error.0, x.com_error.1]
                .iter()
                .all(|e| e.is_finite() && *e >= 0.0)
            && x.q_hr.iter().chain(x.q_rb.iter()).all(|c| c.is_finite())
    }
    /// A refused state gets no force; an accepted one `‖R_BH f_H‖∞ ≤ F` with `f_B = R_BH f_H`
    /// and finite barrier values.
    fn check_output(
        x: &TranslationalInput,
        out: &FilterOutput<3, 2>,
        fmax: f64,
    ) -> Result<(), TestCaseError> {
        if out.report.faults & faults::INVALID_STATE != 0 {
            prop_assert_eq!(out.u, Vector3::zeros());
            prop_assert_eq!(out.actuated, Vector3::zeros());
            return Ok(());
        }
        let r_bh = (quat::to_matrix(&quat::normalized(&x.q_hr).unwrap())
            * quat::to_matrix(&quat::normalized(&x.q_rb).unwrap()))
        .transpose();
        prop_assert!((r_bh * out.u).amax() <= fmax * (1.0 + 1e-12));
        prop_assert!((r_bh * out.u - out.actuated).amax() <= 1e-9 * fmax);
        prop_assert!(out.report.h.iter().all(|h| h.is_finite()));
        Ok(())
    }
}

// ------------------------------------------------------------------ attitude

static ATT: OnceLock<AttitudeInput> = OnceLock::new();
/// A realistic attitude input: 3 m from the target, pointing at the grasping point, the
/// upstream force acting.
fn att_base() -> AttitudeInput {
    *ATT.get_or_init(|| {
        let s = scenario();
        let com = Vector3::new(-3.0, 0.1, 0.0);
        let mut st = ServicerState::rest(&s, com, pointing(&s, &com, 5.0, &Vector3::z(), 0.03));
        st.t = 5.0;
        st.f_b = Vector3::new(2.0, -1.0, 0.5);
        st.omega_b = Vector3::new(0.01, -0.02, 0.01);
        att_input(&s, &robot(), &st)
    })
}

impl Conformance<3, 7> for AttitudeFilter {
    fn fresh() -> Self {
        AttitudeFilter::from_scenario(&scenario(), mass())
    }
    fn braking_law(&self, x: &AttitudeInput) -> Vector3<f64> {
        self.brake(x)
    }
    /// `P⁻¹ (ω_B − ω_T,B)`: the body's momentum relative to the target's rate.
    fn motion(x: &AttitudeInput) -> Vector3<f64> {
        x.p.try_inverse().unwrap_or_else(Matrix3::zeros) * (x.omega_b - x.omega_target_b)
    }
    fn cases(seed: u64, count: usize) -> Vec<(AttitudeInput, Vector3<f64>)> {
        att_cases(seed, count)
    }
    const QP_CASES: (u64, usize) = (33, 200);
    const MIN_SOLVED: usize = 40;
    const MIN_DUALS: usize = 20;
    // Clarabel is an interior-point method: on the line of sight's weak rows (gains of
    // ~1e-3 per N m) it is only good to ~1e-6 T; the exact check is the brute force
    const CLARABEL_TOL: f64 = 1e-5;
    fn clarabel_radius(&self) -> f64 {
        self.params.torque_max
    }
    const SUBSTITUTE_CASES: (u64, usize) = (9, 30);
    const MEMORYLESS: (u64, usize, [usize; 3]) = (12, 400, [20, 20, 20]);
    fn draw(rng: &mut Lcg) -> (AttitudeInput, Option<Vector3<f64>>) {
        let s = scenario();
        let com = Vector3::new(-3.0, 0.0, 0.0) + rng.v3(0.5);
        let t = 40.0 * (1.0 + rng.next());
        let st = ServicerState {
            theta: theta_inside(&s, rng, 0.1),
            theta_dot: rng.v7(0.1),
            // the roll about the boresight (body x) free, the rates across it mostly
            // inside the certified set's boresight-rate limit
            omega_b: Vector3::new(0.06 * rng.next(), 0.035 * rng.next(), 0.035 * rng.next()),
            q_rb: pointing(&s, &com, t, &rng.v3(1.0), 5f64.to_radians() * rng.next()),
            com_r: com,
            com_v_r: rng.v3(0.02),
            t,
            f_b: rng.v3(5.0),
        };
        let u = rng.v3(1.5 * s.limits.torque_max_nm);
        (att_input(&s, &robot(), &st), maybe(rng, u))
    }
    /// Pointing at the grasping point, at rest.
    fn feasible() -> (AttitudeInput, Vec<Vector3<f64>>) {
        let s = scenario();
        let com = Vector3::new(-3.0, 0.0, 0.0);
        let x = att_input(
            &s,
            &robot(),
            &ServicerState::rest(&s, com, pointing(&s, &com, 0.0, &Vector3::z(), 0.0)),
        );
        (x, vec![Vector3::new(0.1, -0.05, 0.02)])
    }
    /// At the cone's edge turning out fast, or beyond a rate limit.
    fn infeasible() -> Vec<(AttitudeInput, Vector3<f64>)> {
        let s = scenario();
        let robot = robot();
        let mut rng = Lcg(6);
        (0..30)
            .map(|k| {
                let com = Vector3::new(-2.8, 0.0, 0.0) + rng.v3(0.2);
                let axis = Vector3::new(0.0, rng.next(), rng.next()).normalize();
                let mut st = ServicerState::rest(
                    &s,
                    com,
                    pointing(&s, &com, 10.0, &axis, (4.8 + 0.3 * rng.next()).to_radians()),
                );
                st.t = 10.0;
                st.omega_b = if k % 2 == 0 {
                    axis * (0.05 + 0.1 * rng.next().abs())
                } else {
                    rng.v3(0.1) + Vector3::new(0.0, 0.0, 0.21)
                };
                st.theta = theta_inside(&s, &mut rng, 0.2);
                let x = att_input(&s, &robot, &st);
                (x, rng.v3(1.0))
            })
            .collect()
    }
    const MIN_RELAXED: usize = 15;
    const NOMINAL_SCALE: f64 = 30.0;
    fn wild() -> BoxedStrategy<Wild<AttitudeInput>> {
        (
            (u3(0.1), mostly3(Vector3::zeros(), 0.15, 0.5)),
            (sometimes(0.05, q4()), sometimes(0.05, v3(0.5))),
            (sometimes(0.05, mat::<3, 3>(0.05)), sometimes(0.05, v3(0.1))),
            (
                sometimes(0.05, v3(5.0)),
                sometimes(0.05, v3(0.1)),
                sometimes(0.05, v3(1e-4)),
            ),
            (
                sometimes(0.05, v3(1.0)),
                sometimes(0.05, v3(0.1)),
                sometimes(0.05, v3(0.01)),
            ),
            prop_oneof![9 => u3(0.03).prop_map(Some), 1 => v3(0.05).prop_map(Some)],
            (
                sometimes(0.05, mat::<7, 3>(0.5)),
                sometimes(0.05, vn::<7>(2.0)),
            ),
        )
            .prop_map(
                |((err, w), (q, wt), (p, r), (rr, vr, ad), (g, gv, ga), xi, (k, kf))| {
                    let base = att_base();
                    // a pointing error of up to ~6° and any body rate up to 0.26 rad/s
                    let q_err = quat::mul(&base.q_rb, &quat::from_axis_angle(&err, err.norm()));
                    let realistic = q.is_none()
                        && finite(&w)
                        && w.norm() <= 10.0
                        && [wt, r, rr, vr, ad, g, gv, ga].iter().all(Option::is_none)
                        && p.is_none()
                        && k.is_none()
                        && kf.is_none();
                    Wild {
                        x: AttitudeInput {
                            q_rb: q.unwrap_or(q_err),
                            omega_b: w,
                            omega_target_b: wt.unwrap_or(base.omega_target_b),
                            p: p.unwrap_or(base.p),
                            r: r.unwrap_or(base.r),
                            r_r: rr.unwrap_or(base.r_r),
                            v_r: vr.unwrap_or(base.v_r),
                            a_drift_r: ad.unwrap_or(base.a_drift_r),
                            grasp_r: g.unwrap_or(base.grasp_r),
                            grasp_vel_r: gv.unwrap_or(base.grasp_vel_r),
                            grasp_acc_r: ga.unwrap_or(base.grasp_acc_r),
                            xi_r: xi.unwrap_or(base.xi_r),
                            joint_coupling: k.unwrap_or(base.joint_coupling),
                            joint_coupling_force: kf.unwrap_or(base.joint_coupling_force),
                        },
                        realistic,
                    }
                },
            )
            .boxed()
    }
    fn filled(v: f64) -> AttitudeInput {
        let v3 = Vector3::from_element(v);
        AttitudeInput {
            q_rb: [v; 4],
            omega_b: v3,
            p: Matrix3::from_element(v),
            r: v3,
            r_r: v3,
            v_r: v3,
            a_drift_r: v3,
            grasp_r: v3,
            grasp_vel_r: v3,
            grasp_acc_r: v3,
            xi_r: v3,
            omega_target_b: v3,
            joint_coupling: SMatrix::from_element(v),
            joint_coupling_force: SVector::from_element(v),
        }
    }
    fn state_finite(x: &AttitudeInput) -> bool {
        x.q_rb.iter().all(|c| c.is_finite())
            && [
                x.omega_b,
                x.omega_target_b,
                x.r,
                x.r_r,
                x.v_r,
                x.a_drift_r,
                x.grasp_r,
                x.grasp_vel_r,
                x.grasp_acc_r,
            ]
            .iter()
            .all(finite)
            && finite(&x.p)
            && finite(&x.joint_coupling)
            && finite(&x.joint_coupling_force)
    }
    fn coupling_finite(x: &AttitudeInput) -> bool {
        finite(&x.xi_r)
    }
    /// The torque acts in the body frame: the actuated command is the command.
    fn check_output(
        _: &AttitudeInput,
        out: &FilterOutput<3, 7>,
        _: f64,
    ) -> Result<(), TestCaseError> {
        prop_assert_eq!(out.u, out.actuated);
        Ok(())
    }
}

// ------------------------------------------------------------------ robotic

static ROB: OnceLock<RoboticInput> = OnceLock::new();
/// The stowed arm moving slowly, the base turning and pushed.
fn rob_base() -> RoboticInput {
    *ROB.get_or_init(|| {
        let s = scenario();
        rob_input(&robot(), theta0(&s), Vector7::from_element(0.02))
    })
}

/// The robotic input from the model at `θ₀ + dθ`, `θ̇` (any finite values).
fn rob_at(dth: Vector7, thd: Vector7) -> RoboticInput {
    let s = scenario();
    let mut x = rob_base();
    if let Some(m) = sc_cbf::robotic_input_from_model(
        &robot(),
        &(theta0(&s) + dth),
        &thd,
        &x.omega_b,
        &x.force_b,
        &x.torque_b,
    ) {
        x = m;
    } else {
        x.theta_dot = thd;
    }
    x
}

/// Replacements of the robotic input's terms, each `None` (keep) or a wild value.
type RoboticWild = (
    (Vector7, Vector7),
    Option<Vector7>,
    (Option<f64>, Option<f64>, Option<Vector7>),
    Option<Vector7>,
    (Option<Vector3<f64>>, Option<Vector3<f64>>, Option<f64>),
    (
        Option<SMatrix<f64, 3, 7>>,
        Option<Vector3<f64>>,
        Option<Vector3<f64>>,
        Option<Vector3<f64>>,
    ),
);

/// The model's own terms at the drawn joint state, then the wild replacements.
fn robotic_wild(w: RoboticWild) -> Wild<RoboticInput> {
    let ((dth, thd), th, (a_scale, m_scale, drift), xi, (sphere, base_c, base_r), rest) = w;
    let (reaction, wb, fb, tb) = rest;
    let mut x = rob_at(dth, thd);
    if let Some(v) = th {
        x.theta = v;
    }
    if let Some(v) = a_scale {
        x.a += Matrix7::identity() * v;
    }
    if let Some(v) = m_scale {
        x.m_eff += Matrix7::identity() * v;
    }
    if let Some(v) = drift {
        x.drift = v;
    }
    if let Some(v) = xi {
        x.xi = v;
    }
    if let Some(v) = sphere {
        x.spheres[4] = SphereTerms {
            center: v,
            ..x.spheres[4]
        };
    }
    if let Some(v) = base_c {
        x.base_center = v;
    }
    if let Some(v) = base_r {
        x.base_radius = v;
    }
    if let Some(v) = reaction {
        x.reaction = v;
    }
    if let Some(v) = wb {
        x.omega_b = v;
    }
    if let Some(v) = fb {
        x.force_b = v;
    }
    if let Some(v) = tb {
        x.torque_b = v;
    }
    let realistic = th.is_none()
        && finite(&thd)
        && thd.amax() <= 1.0
        && a_scale.is_none()
        && m_scale.is_none()
        && drift.is_none()
        && sphere.is_none()
        && base_c.is_none()
        && base_r.is_none()
        && reaction.is_none()
        && wb.is_none()
        && fb.is_none()
        && tb.is_none();
    Wild { x, realistic }
}

impl Conformance<7, { sc_cbf::robotic::N }> for RoboticFilter {
    fn fresh() -> Self {
        RoboticFilter::from_scenario(&scenario(), robot())
    }
    fn braking_law(&self, x: &RoboticInput) -> Vector7 {
        self.brake(x)
    }
    fn emergency(&self, x: &RoboticInput) -> Vector7 {
        self.emergency_brake(x)
    }
    /// `M_eff θ̇`: the arm's momentum.
    fn motion(x: &RoboticInput) -> Vector7 {
        x.m_eff * x.theta_dot
    }
    fn cases(seed: u64, count: usize) -> Vec<(RoboticInput, Vector7)> {
        rob_cases(seed, count)
    }
    const QP_CASES: (u64, usize) = (44, 120);
    const MIN_SOLVED: usize = 30;
    // the robotic filter records no multipliers (its dumped rows are the certificate's)
    const MIN_DUALS: usize = 0;
    const CLARABEL_TOL: f64 = 1e-6;
    fn clarabel_radius(&self) -> f64 {
        self.params.torque_max
    }
    const SUBSTITUTE_CASES: (u64, usize) = (10, 20);
    const MEMORYLESS: (u64, usize, [usize; 3]) = (13, 250, [20, 20, 5]);
    fn draw(rng: &mut Lcg) -> (RoboticInput, Option<Vector7>) {
        rob_draw(rng)
    }
    /// The stowed arm at rest, a nominal near the holding torque.
    fn feasible() -> (RoboticInput, Vec<Vector7>) {
        let s = scenario();
        let x = rob_input(&robot(), theta0(&s), Vector7::zeros());
        let hold = -(x.m_eff * (x.drift + x.xi));
        (
            x,
            vec![hold + Vector7::from_fn(|i, _| 1e-4 * (i as f64 - 3.0))],
        )
    }
    /// Joints beyond their rate limits, anywhere inside the angle limits.
    fn infeasible() -> Vec<(RoboticInput, Vector7)> {
        let s = scenario();
        let robot = robot();
        let max = Vector7::from(s.safety.robotic.theta_dot_max_rad_s);
        let mut rng = Lcg(14);
        (0..30)
            .map(|_| {
                let th = theta_inside(&s, &mut rng, 0.2);
                let thd = max.component_mul(&rng.v7(1.0).map(|v| 2.0 * v.signum() + v));
                (rob_input(&robot, th, thd), rng.v7(1.0))
            })
            .collect()
    }
    const MIN_RELAXED: usize = 10;
    const NOMINAL_SCALE: f64 = 4.0;
    fn wild() -> BoxedStrategy<Wild<RoboticInput>> {
        (
            (u7(0.6), prop_oneof![9 => u7(0.3), 1 => vn::<7>(0.5)]),
            sometimes(0.05, vn::<7>(3.0)),
            (
                sometimes(0.05, wild(2.0)),
                sometimes(0.05, wild(2.0)),
                sometimes(0.05, vn::<7>(0.1)),
            ),
            sometimes(0.1, vn::<7>(1.0)),
            (
                sometimes(0.05, v3(1.0)),
                sometimes(0.05, v3(1.0)),
                sometimes(0.05, wild(1.0)),
            ),
            (
                sometimes(0.05, mat::<3, 7>(0.1)),
                sometimes(0.05, v3(0.2)),
                sometimes(0.05, v3(7.0)),
                sometimes(0.05, v3(10.0)),
            ),
        )
            .prop_map(robotic_wild)
            .boxed()
    }
    /// The joint state and the inertia (the rest is the model's own).
    fn filled(v: f64) -> RoboticInput {
        let mut x = rob_base();
        x.theta = Vector7::from_element(v);
        x.theta_dot = Vector7::from_element(v);
        x.m_eff = Matrix7::from_element(v);
        x
    }
    fn state_finite(x: &RoboticInput) -> bool {
        finite(&x.theta)
            && finite(&x.theta_dot)
            && finite(&x.a)
            && finite(&x.m_eff)
            && finite(&x.drift)
            && finite(&x.reaction)
            && finite(&x.omega_b)
            && finite(&x.force_b)
            && finite(&x.torque_b)
            && finite(&x.base_center)
            && x.base_radius.is_finite()
            && x.spheres.iter().all(|s| finite(&s.center))
            && finite(&x.com.position)
            && finite(&x.com.jacobian)
            && finite(&x.omega_dot_b0)
            && x.total_mass.is_finite()
            && x.around
                .is_none_or(|a| finite(&a.com_r) && finite(&a.com_v_r))
    }
    fn coupling_finite(x: &RoboticInput) -> bool {
        finite(&x.xi)
    }
    /// A base rate or upstream wrench far beyond any physical value is accepted by the
    /// robotic filter (`robotic_filter_refuses_an_absurd_upstream_wrench_or_rate` in
    /// faults.rs): then only the output is checked.
    fn sane(x: &RoboticInput) -> bool {
        [
            x.omega_b.amax() / 10.0,
            x.force_b.amax() / 1e3,
            x.torque_b.amax() / 1e3,
        ]
        .iter()
        .all(|v| *v <= 1.0)
    }
}

// ================================================================== strategies

fn wild(scale: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => (-1.0..1.0f64).prop_map(move |x| x * scale),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(1e300),
        1 => Just(-1e300),
        1 => Just(0.0),
        1 => (-1.0..1.0f64).prop_map(|x| x * 1e8),
    ]
}
fn v3(scale: f64) -> impl Strategy<Value = Vector3<f64>> {
    [wild(scale), wild(scale), wild(scale)].prop_map(Vector3::from)
}
fn vn<const K: usize>(scale: f64) -> impl Strategy<Value = SVector<f64, K>> {
    proptest::collection::vec(wild(scale), K).prop_map(|v| SVector::from_column_slice(&v))
}
fn mat<const R: usize, const C: usize>(scale: f64) -> impl Strategy<Value = SMatrix<f64, R, C>> {
    proptest::collection::vec(wild(scale), R * C).prop_map(|v| SMatrix::from_column_slice(&v))
}
fn q4() -> impl Strategy<Value = Quat> {
    prop_oneof![
        4 => [(-1.0..1.0f64), (-1.0..1.0f64), (-1.0..1.0f64), (-1.0..1.0f64)]
            .prop_map(|q| quat::normalized(&q).unwrap_or(quat::IDENTITY)),
        1 => [wild(1.0), wild(1.0), wild(1.0), wild(1.0)],
    ]
}
/// Uniform in `[-scale, scale]³`.
fn u3(scale: f64) -> impl Strategy<Value = Vector3<f64>> {
    [-scale..scale, -scale..scale, -scale..scale].prop_map(Vector3::from)
}
fn u7(scale: f64) -> impl Strategy<Value = Vector7> {
    proptest::collection::vec(-scale..scale, 7).prop_map(|v| Vector7::from_column_slice(&v))
}
/// `None` (keep the realistic value) or, with probability `p`, a wild replacement.
fn sometimes<T: Debug + Clone>(
    p: f64,
    s: impl Strategy<Value = T>,
) -> impl Strategy<Value = Option<T>> {
    weighted(p, s)
}
/// A realistic vector (offset, uniform) or, one time in ten, a wild one.
fn mostly3(
    center: Vector3<f64>,
    scale: f64,
    wild_scale: f64,
) -> impl Strategy<Value = Vector3<f64>> {
    prop_oneof![9 => u3(scale).prop_map(move |v| v + center), 1 => v3(wild_scale)]
}
/// A nominal: missing (None), or any vector, wild values included.
fn nominal<const K: usize>(scale: f64) -> impl Strategy<Value = Option<SVector<f64, K>>> {
    weighted(0.9, vn::<K>(scale))
}

fn finite<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// Every bit of an output except the timings.
fn bits<const M: usize, const N: usize>(o: &FilterOutput<M, N>) -> Vec<u64> {
    o.u.iter()
        .chain(o.actuated.iter())
        .map(|x| x.to_bits())
        .chain(o.report.deterministic_bits())
        .collect()
}

/// Counts of the statuses reached: skipped, solved, relaxed, fallback.
fn tally(seen: &mut [usize; 4], s: FilterStatus) {
    seen[s as usize] += 1;
}

// ================================================================== the properties

/// The flags every output must carry for its nominal, when the state was accepted.
fn check_nominal_flags<const K: usize, const N: usize>(
    r: &FilterReport<N>,
    nom: &Option<SVector<f64, K>>,
    bound: f64,
) -> Result<(), TestCaseError> {
    match nom {
        None => prop_assert!(r.faults & faults::NOMINAL_MISSING != 0),
        Some(u) if !finite(u) || u.amax() > 1e3 * bound => {
            prop_assert!(r.faults & faults::INVALID_NOMINAL != 0);
            prop_assert!(r.faults & faults::NOMINAL_MISSING == 0);
        }
        Some(_) => {
            prop_assert!(r.faults & (faults::INVALID_NOMINAL | faults::NOMINAL_MISSING) == 0)
        }
    }
    // a missing or invalid nominal is replaced, the QP still runs: only a solver failure
    // gives the fallback
    if r.status == FilterStatus::Fallback {
        prop_assert!(r.faults & faults::QP_FAILED_FALLBACK != 0, "{r:?}");
    }
    Ok(())
}

/// Report invariants. `sane` is false for inputs beyond any physical range that the filter
/// nevertheless accepts: then the report's violation and the idle clamp are not checked.
fn check_report<const N: usize>(r: &FilterReport<N>, sane: bool) -> Result<(), TestCaseError> {
    if r.status == FilterStatus::Fallback {
        prop_assert!(r.faults != 0, "a fallback is always explained: {r:?}");
    }
    prop_assert_eq!(r.faults & !faults::ALL, 0);
    // the relaxed problem is flagged exactly when it gave the command
    prop_assert_eq!(
        r.faults & faults::QP_INFEASIBLE_RELAXED != 0,
        r.status == FilterStatus::Relaxed
    );
    prop_assert!(r.violation >= 0.0 || r.violation.is_nan() && !sane);
    if sane {
        prop_assert!(r.violation.is_finite(), "{r:?}");
        prop_assert_eq!(
            r.faults & faults::OUTPUT_CLAMPED,
            0,
            "the QP's box margin makes the clamp idle"
        );
    }
    Ok(())
}

/// One output of a wild input: finite, inside the bound, flagged for what was wrong.
fn check_wild<F, const M: usize, const N: usize>(
    w: &Wild<F::Input>,
    nom: &Option<SVector<f64, M>>,
    out: &FilterOutput<M, N>,
    bound: f64,
) -> Result<(), TestCaseError>
where
    F: Conformance<M, N>,
{
    let x = &w.x;
    prop_assert!(finite(&out.u) && finite(&out.actuated));
    prop_assert!(out.actuated.amax() <= bound);
    check_report(&out.report, F::sane(x))?;
    let state_finite = F::state_finite(x);
    if !state_finite {
        prop_assert!(out.report.faults & faults::INVALID_STATE != 0);
        prop_assert_eq!(out.report.status, FilterStatus::Fallback);
    }
    if out.report.faults & faults::INVALID_STATE == 0 {
        prop_assert!(state_finite);
        if !F::coupling_finite(x) {
            prop_assert!(out.report.faults & faults::INVALID_COUPLING != 0);
        }
        if out.report.faults & faults::INVALID_COUPLING == 0 {
            check_nominal_flags(&out.report, nom, bound)?;
        }
    }
    if w.realistic {
        prop_assert_eq!(
            out.report.faults & faults::INVALID_STATE,
            0,
            "the realistic base input is accepted"
        );
    }
    F::check_output(x, out, bound)
}

/// Over random inputs — NaN, ±∞, 1e300 and large finite values anywhere — and any
/// nominal: no panic, every command finite and inside its bound, invalid inputs flagged,
/// a missing or invalid nominal still gets the QP.
fn output_is_finite_bounded_and_flagged<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    // deterministic: a fixed seed, and no regression files written into the source tree
    let config = Config {
        cases: 500,
        rng_seed: RngSeed::Fixed(0x5afe_ca97),
        failure_persistence: None,
        ..Config::default()
    };
    let bound = F::fresh().input_bound();
    let mut runner = TestRunner::new(config);
    runner
        .run(&(F::wild(), nominal::<M>(F::NOMINAL_SCALE)), |(w, nom)| {
            let out = F::fresh().filter_with(&w.x, nom.as_ref());
            check_wild::<F, M, N>(&w, &nom, &out, bound)
        })
        .unwrap();
}

/// The defined outputs on the invalid inputs the property test hits only by chance:
/// all-NaN, all-infinite and all-1e300 inputs.
fn all_nan_inf_or_huge_inputs_give_a_flagged_bounded_command<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
        let mut f = F::fresh();
        let bound = f.input_bound();
        let x = F::filled(v);
        let o = f.filter_with(&x, Some(&SVector::from_element(v)));
        assert!(finite(&o.u) && finite(&o.actuated) && o.actuated.amax() <= bound);
        assert_ne!(o.report.faults & faults::INVALID_STATE, 0, "{v}");
        assert_eq!(o.report.status, FilterStatus::Fallback);
        F::check_output(&x, &o, bound).unwrap();
    }
}

/// A step's output depends on its inputs only, not on the steps the same filter object
/// took before (the partition's pre-tick warm-up relies on it, docs/PARTITION.md): for
/// random pairs (a, b) a fresh filter's output on b equals, bit for bit, that of a filter
/// that first took a step on a (and then on b once more). The pairs reach the skip path,
/// the solved and the relaxed QP.
fn output_depends_on_its_inputs_only<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    let (seed, pairs, min) = F::MEMORYLESS;
    let mut rng = Lcg(seed);
    let mut seen = [0usize; 4];
    for _ in 0..pairs {
        let (xa, na) = F::draw(&mut rng);
        let (xb, nb) = F::draw(&mut rng);
        let fresh = F::fresh().filter_with(&xb, nb.as_ref());
        let mut used = F::fresh();
        used.filter_with(&xa, na.as_ref());
        assert_eq!(
            bits(&used.filter_with(&xb, nb.as_ref())),
            bits(&fresh),
            "after a step on {xa:?}"
        );
        assert_eq!(
            bits(&used.filter_with(&xb, nb.as_ref())),
            bits(&fresh),
            "repeated"
        );
        tally(&mut seen, fresh.report.status);
    }
    println!(
        "{:?}: skipped, solved, relaxed, fallback {seen:?}",
        F::SUBSYSTEM
    );
    assert!(
        seen[0] >= min[0] && seen[1] >= min[1] && seen[2] >= min[2],
        "{seen:?}"
    );
}

/// Threads do not share state either: the same sequence on another thread gives the same
/// bits.
fn outputs_are_the_same_on_another_thread<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    fn run<F: Conformance<M, N>, const M: usize, const N: usize>() -> Vec<u64> {
        let mut rng = Lcg(99);
        let mut f = F::fresh();
        (0..50)
            .flat_map(|_| {
                let (x, u) = F::draw(&mut rng);
                bits(&f.filter_with(&x, u.as_ref()))
            })
            .collect()
    }
    let here = run::<F, M, N>();
    let there = std::thread::spawn(run::<F, M, N>).join().unwrap();
    assert_eq!(here, there);
}

/// A nominal that satisfies every row is returned unchanged (bit for bit) and is the
/// solved QP's answer too.
fn feasible_nominal_is_returned_unchanged_and_equals_the_solved_qp<
    F,
    const M: usize,
    const N: usize,
>()
where
    F: Conformance<M, N>,
{
    let (x, nominals) = F::feasible();
    let mut skipping = F::fresh();
    let mut solving = F::fresh();
    solving.set_skip_enabled(false);
    let bound = skipping.input_bound();
    for un in nominals {
        let (a, b) = (
            skipping.filter_with(&x, Some(&un)),
            solving.filter_with(&x, Some(&un)),
        );
        assert_eq!(a.report.status, FilterStatus::Skipped, "{:?}", a.report);
        assert_eq!(b.report.status, FilterStatus::Solved);
        assert_eq!(a.u, un, "bit for bit");
        assert!((a.u - b.u).amax() <= 1e-12 * bound, "{} vs {}", a.u, b.u);
        assert_eq!(a.report.active, b.report.active);
        assert_eq!(a.report.faults, 0);
        assert_eq!(b.report.faults, 0);
    }
}

/// `filter_with(None)` and an invalid nominal run the QP on the substitute (the braking
/// law): the same command as filtering the braking law itself, never the fallback; the
/// backup is that call.
fn missing_or_invalid_nominal_runs_the_qp_on_the_substitute<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    let (seed, count) = F::SUBSTITUTE_CASES;
    let mut f = F::fresh();
    let bound = f.input_bound();
    let mut statuses = [0usize; 4];
    for (x, _) in F::cases(seed, count) {
        let brake = f.braking_law(&x);
        let reference = f.filter_with(&x, Some(&brake));
        assert_eq!(
            reference.report.faults & (faults::NOMINAL_MISSING | faults::INVALID_NOMINAL),
            0
        );
        let missing = f.filter_with(&x, None);
        assert_ne!(missing.report.faults & faults::NOMINAL_MISSING, 0);
        assert_eq!(missing.report.faults & faults::INVALID_NOMINAL, 0);
        assert_ne!(missing.report.status, FilterStatus::Fallback);
        assert_eq!(missing.u, reference.u, "missing nominal");
        assert_eq!(missing.report.status, reference.report.status);
        assert_eq!(f.backup(&x).u, missing.u, "the backup is the same call");
        let mut over = SVector::<f64, M>::zeros();
        over[0] = sc_cbf::common::NOMINAL_RANGE * bound * 1.001;
        let mut nan = SVector::<f64, M>::zeros();
        nan[M - 1] = f64::NAN;
        let mut inf = SVector::<f64, M>::repeat(0.1);
        inf[0] = f64::NEG_INFINITY;
        for bad in [nan, inf, SVector::repeat(1e300), over] {
            let o = f.filter_with(&x, Some(&bad));
            assert_ne!(o.report.faults & faults::INVALID_NOMINAL, 0, "{bad}");
            assert_eq!(o.report.faults & faults::NOMINAL_MISSING, 0);
            assert_ne!(
                o.report.status,
                FilterStatus::Fallback,
                "the QP must still run"
            );
            assert_eq!(o.u, reference.u, "invalid nominal {bad}");
            assert_output_sane(&o, bound);
        }
        // the largest accepted nominal is used as given
        let mut big = SVector::<f64, M>::zeros();
        big[0] = sc_cbf::common::NOMINAL_RANGE * bound * 0.999;
        let o = f.filter_with(&x, Some(&big));
        assert_eq!(o.report.faults & faults::INVALID_NOMINAL, 0);
        assert_output_sane(&o, bound);
        tally(&mut statuses, missing.report.status);
    }
    // the substitute is not always feasible as it is: the QP really ran
    assert!(statuses[0] < count, "{statuses:?}");
}

/// When no solver produces a command (here: the relaxed problem's LP allowed no
/// iteration, on states whose rows cannot all hold), the command is the emergency command
/// (the braking law, the robotic one within its arm-reaction contract), flagged; and the
/// braking law brakes the subsystem's motion, inside the bound.
fn solver_failure_gives_the_braking_law<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    let mut f = F::fresh();
    let mut failing = F::fresh();
    failing.set_solver_settings(sc_qp::Settings {
        max_outer_iterations: Some(0),
        ..Default::default()
    });
    let bound = f.input_bound();
    let mut relaxed = 0;
    for (x, dir) in F::infeasible() {
        if f.filter_with(&x, Some(&dir)).report.status != FilterStatus::Relaxed {
            continue;
        }
        relaxed += 1;
        // (inside the bound in the actuator frame: checked on the output below)
        let brake = f.braking_law(&x);
        assert!(finite(&brake));
        let motion = F::motion(&x);
        if motion.norm() > 0.0 {
            assert!(brake.dot(&motion) < 0.0, "{brake} against {motion}");
        }
        let o = failing.filter_with(&x, Some(&dir));
        assert_eq!(o.report.status, FilterStatus::Fallback, "{:?}", o.report);
        assert_ne!(o.report.faults & faults::QP_FAILED_FALLBACK, 0);
        assert_eq!(o.report.faults & faults::QP_INFEASIBLE_RELAXED, 0);
        assert_eq!(o.u, failing.emergency(&x));
        assert_output_sane(&o, bound);
    }
    println!("{:?}: {relaxed} states braked", F::SUBSYSTEM);
    assert!(relaxed >= F::MIN_RELAXED, "only {relaxed} relaxed states");
}

/// Every solved command is the minimiser of the QP the filter dumps (`dump_qp()`): a KKT
/// point with multipliers computed here, the brute-force minimiser (three inputs),
/// Clarabel's solution, and the engine's recorded multipliers are the KKT ones.
fn dumped_qp_is_the_solved_one<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    let (seed, count) = F::QP_CASES;
    let mut f = F::fresh();
    let bound = f.input_bound();
    let mut seen = [0usize; 4];
    let (mut clarabel_err, mut duals, mut brute) = (0.0f64, 0, 0);
    for (k, (x, un)) in F::cases(seed, count).into_iter().enumerate() {
        let out = f.filter_with(&x, Some(&un));
        tally(&mut seen, out.report.status);
        assert_output_sane(&out, bound);
        assert_eq!(
            out.report.faults & !faults::QP_INFEASIBLE_RELAXED,
            0,
            "case {k}: {:?}",
            out.report
        );
        let relaxed = out.report.status == FilterStatus::Relaxed;
        assert_eq!(
            out.report.faults & faults::QP_INFEASIBLE_RELAXED != 0,
            relaxed,
            "case {k}: {:?}",
            out.report
        );
        assert_eq!(out.report.violation > 0.0, relaxed, "case {k}");
        if out.report.status != FilterStatus::Solved {
            continue;
        }
        let what = format!("case {k}");
        let d = f.dump_qp();
        let qp = Qp::from_dump(&d);
        let u = dvec(&out.u);
        check_kkt(&qp, &u, bound, &what);
        for (i, phi) in out.report.phi.iter().enumerate() {
            assert!(*phi >= -1e-9, "{what}: row {i} Φ = {phi}");
        }
        if F::MIN_DUALS > 0 {
            duals += check_duals(&d, &qp, &u, bound, &what);
        }
        if M <= 3 {
            let bf = brute_force(&qp).expect("feasible");
            assert!(
                near(&u, &bf, 1e-9 * bound),
                "{what}: {u} vs brute force {bf}"
            );
            brute += 1;
        }
        let cl = clarabel(&qp, f.clarabel_radius()).expect("Clarabel solves it");
        clarabel_err = clarabel_err.max((&u - &cl).amax() / bound);
    }
    println!(
        "{:?}: statuses {seen:?}; {duals} multipliers compared; {brute} brute-force minimisers; \
         max |u − u_Clarabel|∞ / bound = {clarabel_err:e}",
        F::SUBSYSTEM
    );
    assert!(
        clarabel_err <= F::CLARABEL_TOL,
        "Clarabel disagrees by {clarabel_err:e} of the bound"
    );
    assert!(
        seen[1] >= F::MIN_SOLVED,
        "only {} solved cases: {seen:?}",
        seen[1]
    );
    assert!(
        duals >= F::MIN_DUALS,
        "only {duals} barrier multipliers compared"
    );
}

/// A realistic observation: the servicer 3 m from the target, pointing at the grasping
/// point, the arm stowed and moving slowly.
fn observation() -> Observation {
    let s = scenario();
    let n = mean_motion(&s);
    let q_hr = s.reference_frame.attitude_in_hill;
    let r_hr = quat::to_matrix(&q_hr);
    let t = 5.0;
    let com_r = Vector3::new(-3.0, 0.1, 0.0);
    let com_v_r = Vector3::new(0.01, 0.0, 0.0);
    let omega_h = Vector3::new(0.0, 0.0, n);
    let com_h = r_hr * com_r;
    let com_v_h = r_hr * com_v_r - omega_h.cross(&com_h);
    let (grasp_r, grasp_v_r, grasp_a_r, _) = grasp_at(&s, t);
    let q_rb = pointing(&s, &com_r, t, &Vector3::z(), 0.02);
    let w_t = Vector3::from(s.target.initial_omega_rad_s);
    let q_rt0 = s.target.initial_attitude;
    let w_r = quat::to_matrix(&q_rt0) * w_t;
    let q_rt = quat::mul(&quat::from_axis_angle(&w_r, w_r.norm() * t), &q_rt0);
    Observation {
        step: 50,
        t,
        r_h: com_h,
        v_h: com_v_h,
        r_r: com_r,
        v_r: com_v_r,
        q_hr,
        omega_h,
        omega_dot_h: Vector3::zeros(),
        mean_motion: n,
        q_rb,
        omega_b: Vector3::new(0.01, -0.02, 0.01),
        theta: theta0(&s),
        theta_dot: Vector7::from_element(0.02),
        q_rt,
        omega_t: w_t,
        omega_dot_t: Vector3::zeros(),
        grasp_r,
        grasp_v_r,
        grasp_a_r,
        grasp_b: Vector3::zeros(),
        ee_b: Vector3::zeros(),
        ee_r: Vector3::zeros(),
        ee_v_r: Vector3::zeros(),
        com_h,
        com_v_h,
        com_r,
        com_v_r,
    }
}

/// `o` with its `k`-th quantity (of [`OBSERVED`]) set to `v` everywhere.
fn perturbed(o: &Observation, k: usize, v: f64) -> Observation {
    let mut o = *o;
    let v3 = Vector3::from_element(v);
    match k {
        0 => o.t = v,
        1 => o.r_h = v3,
        2 => o.v_h = v3,
        3 => o.r_r = v3,
        4 => o.v_r = v3,
        5 => o.q_hr = [v; 4],
        6 => o.omega_h = v3,
        7 => o.omega_dot_h = v3,
        8 => o.mean_motion = v,
        9 => o.q_rb = [v; 4],
        10 => o.omega_b = v3,
        11 => o.theta = Vector7::from_element(v),
        12 => o.theta_dot = Vector7::from_element(v),
        13 => o.q_rt = [v; 4],
        14 => o.omega_t = v3,
        15 => o.grasp_r = v3,
        16 => o.grasp_v_r = v3,
        17 => o.grasp_a_r = v3,
        18 => o.com_h = v3,
        19 => o.com_v_h = v3,
        20 => o.com_r = v3,
        21 => o.com_v_r = v3,
        _ => {}
    }
    o
}
/// How many quantities [`perturbed`] can replace.
const OBSERVED: usize = 22;

/// The chain's stage (paper Fig. "control_safety_framework"): at a realistic observation
/// it is the filter on its input; at an observation with any quantity non-finite or huge,
/// and with a wild coupling, its command is finite and inside the bound; with every
/// quantity wild it is flagged.
fn stage_is_the_filter_on_its_input_and_bounded_at_any_observation<
    F,
    const M: usize,
    const N: usize,
>()
where
    F: Conformance<M, N>,
{
    let model = robot();
    let o = observation();
    let xi = Coupling {
        force_b: Vector3::new(2.0, -1.0, 0.5),
        torque_b: Vector3::new(0.3, 0.1, -0.2),
    };
    let mut f = F::fresh();
    let bound = f.input_bound();
    let nominal = SVector::<f64, M>::from_fn(|i, _| 0.1 * bound * (i as f64 - 1.0));
    let x = f
        .input(&model, &o, &xi)
        .expect("a realistic observation has an input");
    let staged = f.stage(&model, &o, &xi, Some(&nominal));
    assert_eq!(
        bits(&staged),
        bits(&F::fresh().filter_with(&x, Some(&nominal)))
    );
    assert_eq!(
        staged.report.faults & (faults::INVALID_STATE | faults::INVALID_COUPLING),
        0,
        "{:?}",
        staged.report
    );
    for v in [f64::NAN, f64::INFINITY, -1e300] {
        for k in 0..OBSERVED {
            let out = f.stage(&model, &perturbed(&o, k, v), &xi, Some(&nominal));
            assert!(finite(&out.u) && finite(&out.actuated), "{k} = {v}");
            assert!(out.actuated.amax() <= bound, "{k} = {v}");
        }
        let wild_xi = Coupling {
            force_b: Vector3::from_element(v),
            torque_b: Vector3::from_element(v),
        };
        let out = f.stage(&model, &o, &wild_xi, None);
        assert!(finite(&out.u) && out.actuated.amax() <= bound, "ξ = {v}");
        let all = (0..OBSERVED).fold(o, |o, k| perturbed(&o, k, v));
        let out = f.stage(&model, &all, &wild_xi, Some(&nominal));
        assert!(finite(&out.u) && out.actuated.amax() <= bound);
        assert_ne!(out.report.faults & faults::INVALID_STATE, 0, "all = {v}");
    }
}

/// Names: `N` of them, unique, stable (the trait's are the module's).
fn names_are_unique<F, const M: usize, const N: usize>(names: &[&str])
where
    F: Conformance<M, N>,
{
    assert_eq!(F::NAMES.len(), N);
    assert_eq!(F::NAMES.as_slice(), names);
    let mut v = F::NAMES.to_vec();
    v.sort();
    v.dedup();
    assert_eq!(v.len(), N, "names are unique");
}

/// The dumped QP serialises and reads back as itself, in the filter's dimensions.
fn dump_serialises<F, const M: usize, const N: usize>()
where
    F: Conformance<M, N>,
{
    let mut f = F::fresh();
    let (x, un) = F::cases(21, 1).into_iter().next().unwrap();
    f.filter_with(&x, Some(&un));
    let d = f.dump_qp();
    let back: sc_cbf::QpDump = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back, d);
    assert_eq!(back.u_nom.len(), M);
    assert!(back.rows_a.len() >= N);
    assert!(
        back.rows_a
            .iter()
            .chain(&back.bounds_g)
            .all(|r| r.len() == M)
    );
    assert_eq!(back.rows_c.len(), back.rows_a.len());
    assert_eq!(back.bounds_g_max.len(), back.bounds_g.len());
}

// ================================================================== instantiation

/// The suite for one filter.
macro_rules! conformance {
    ($module:ident, $filter:ty, $m:literal, $n:literal, $names:expr) => {
        mod $module {
            use super::*;
            type F = $filter;

            #[test]
            fn output_is_finite_bounded_and_flagged() {
                super::output_is_finite_bounded_and_flagged::<F, $m, $n>();
            }
            #[test]
            fn all_nan_inf_or_huge_inputs_give_a_flagged_bounded_command() {
                super::all_nan_inf_or_huge_inputs_give_a_flagged_bounded_command::<F, $m, $n>();
            }
            #[test]
            fn output_depends_on_its_inputs_only() {
                super::output_depends_on_its_inputs_only::<F, $m, $n>();
            }
            #[test]
            fn outputs_are_the_same_on_another_thread() {
                super::outputs_are_the_same_on_another_thread::<F, $m, $n>();
            }
            #[test]
            fn feasible_nominal_is_returned_unchanged_and_equals_the_solved_qp() {
                super::feasible_nominal_is_returned_unchanged_and_equals_the_solved_qp::<F, $m, $n>(
                );
            }
            #[test]
            fn missing_or_invalid_nominal_runs_the_qp_on_the_substitute() {
                super::missing_or_invalid_nominal_runs_the_qp_on_the_substitute::<F, $m, $n>();
            }
            #[test]
            fn solver_failure_gives_the_braking_law() {
                super::solver_failure_gives_the_braking_law::<F, $m, $n>();
            }
            #[test]
            fn dumped_qp_is_the_solved_one() {
                super::dumped_qp_is_the_solved_one::<F, $m, $n>();
            }
            #[test]
            fn stage_is_the_filter_on_its_input_and_bounded_at_any_observation() {
                super::stage_is_the_filter_on_its_input_and_bounded_at_any_observation::<F, $m, $n>(
                );
            }
            #[test]
            fn names_are_unique() {
                super::names_are_unique::<F, $m, $n>(&$names);
            }
            #[test]
            fn dump_serialises() {
                super::dump_serialises::<F, $m, $n>();
            }
        }
    };
}

conformance!(
    translational,
    TranslationalFilter,
    3,
    2,
    sc_cbf::names::TRANSLATIONAL
);
conformance!(attitude, AttitudeFilter, 3, 7, sc_cbf::names::ATTITUDE);
conformance!(robotic, RoboticFilter, 7, 63, sc_cbf::names::ROBOTIC);

/// The names of all filters together: 72 barriers, every name once.
#[test]
fn report_names_are_unique_across_the_filters() {
    let mut all: Vec<&str> = sc_cbf::names::TRANSLATIONAL
        .iter()
        .chain(sc_cbf::names::ATTITUDE.iter())
        .chain(sc_cbf::names::ROBOTIC.iter())
        .copied()
        .collect();
    assert_eq!(all.len(), 72);
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 72, "names are unique");
}

// ================================================================== the relaxed problem

/// Filters whose relaxed command is the engine's lexicographic relaxation of their rows
/// (`rows()`): the robotic filter's relaxed command comes from its verification (rows
/// tightened by simulated shortfalls), so it is not among them.
trait Lexicographic<const M: usize, const N: usize>: Conformance<M, N> {
    /// The barrier rows, their weights and the hard rows at `x`.
    fn rows(&self, x: &Self::Input)
    -> Option<(Vec<sc_cbf::Row<M>>, Vec<f64>, Vec<sc_cbf::Row<M>>)>;
    /// The rows' priority tiers (empty: one tier).
    const TIERS: &'static [u8];
}

impl Lexicographic<3, 2> for TranslationalFilter {
    fn rows(
        &self,
        x: &TranslationalInput,
    ) -> Option<(Vec<sc_cbf::Row<3>>, Vec<f64>, Vec<sc_cbf::Row<3>>)> {
        TranslationalFilter::rows(self, x)
    }
    const TIERS: &'static [u8] = &sc_cbf::translational::TIERS;
}

impl Lexicographic<3, 7> for AttitudeFilter {
    fn rows(
        &self,
        x: &AttitudeInput,
    ) -> Option<(Vec<sc_cbf::Row<3>>, Vec<f64>, Vec<sc_cbf::Row<3>>)> {
        AttitudeFilter::rows(self, x)
    }
    const TIERS: &'static [u8] = &sc_cbf::attitude::TIERS;
}

/// The relaxed command is the lexicographic least violation (against Clarabel's LPs and
/// projection) for nominals of every magnitude, and `t*` does not depend on the nominal.
fn relaxed_command_is_the_lexicographic_least_violation<F, const M: usize, const N: usize>()
where
    F: Lexicographic<M, N>,
{
    let mut f = F::fresh();
    let bound = f.input_bound();
    let radius = f.clarabel_radius();
    let mut stats = RelaxedStats::default();
    for (k, (x, dir)) in F::infeasible().into_iter().enumerate() {
        let rows = f.rows(&x).unwrap();
        if f.filter_with(&x, Some(&dir)).report.status != FilterStatus::Relaxed {
            continue;
        }
        check_relaxed(
            &format!("case {k}"),
            bound,
            radius,
            &rows,
            F::TIERS,
            &dir,
            &mut stats,
            |un| {
                let o = f.filter_with(&x, Some(un));
                assert_output_sane(&o, bound);
                (o.u, o.report.status, o.report.violation, o.report.faults)
            },
        );
    }
    println!("{:?}: {stats:?}", F::SUBSYSTEM);
    assert!(stats.cases >= F::MIN_RELAXED, "{stats:?}");
    assert!(
        stats.compared >= 3 * stats.cases,
        "Clarabel resolved too few: {stats:?}"
    );
}

mod lexicographic {
    use super::*;

    #[test]
    fn translational_relaxed_command_is_the_lexicographic_least_violation() {
        relaxed_command_is_the_lexicographic_least_violation::<TranslationalFilter, 3, 2>();
    }
    #[test]
    fn attitude_relaxed_command_is_the_lexicographic_least_violation() {
        relaxed_command_is_the_lexicographic_least_violation::<AttitudeFilter, 3, 7>();
    }
}

// ================================================================== the chain in safe mode

/// The chain's stages in safe mode (a tumble beyond the certified envelope known at the
/// observation, `sc_cbf::safe_mode`): every stage flagged; the translational stage is its
/// filter on the retreat and the robotic stage its filter on the arm's brake, whatever
/// their nominals; the attitude stage its filter on its own nominal. At any observation —
/// a non-finite or huge tumble among them — every stage's command is finite and bounded.
#[test]
fn the_chain_in_safe_mode_filters_the_retreat_and_the_arm_brake() {
    let s = scenario();
    let model = robot();
    let mut layer = sc_cbf::SafetyLayer::from_scenario(&s, model.clone());
    let mut o = observation();
    assert!(
        layer.watch.check(&o).is_none(),
        "the declared tumble is inside"
    );
    o.omega_t = Vector3::new(-0.3, 0.0, 0.0);
    assert!(layer.watch.check(&o).is_some(), "0.3 rad/s is outside");
    let f_nom = Vector3::new(5.0, -5.0, 5.0);
    let tr = layer.translational_stage(&o, Some(&f_nom));
    let x = layer
        .translational
        .input(&model, &o, &Coupling::default())
        .unwrap();
    let retreat = layer
        .translational
        .toward_velocity(&x, &layer.watch.retreat_velocity(&x.r_h, &x.omega_h));
    let mut alone = TranslationalFilter::new(layer.translational.params.clone());
    let mut expected = alone.filter_with(&x, Some(&retreat));
    expected.report.faults |= faults::SAFE_MODE;
    assert_eq!(bits(&tr), bits(&expected));
    // the retreat points away from the target (in F_H, against the relative position)
    assert!(retreat.dot(&x.r_h) > 0.0, "{retreat:?}");
    let tau_nom = Vector3::new(0.5, 0.5, 0.5);
    let at = layer.attitude_stage(&o, &tr.actuated, Some(&tau_nom));
    assert_ne!(at.report.faults & faults::SAFE_MODE, 0);
    let tau_m_nom = Vector7::from_element(0.5);
    let rb = layer.robotic_stage(&o, &tr.actuated, &at.u, Some(&tau_m_nom));
    let xr = layer
        .robotic
        .input(
            &model,
            &o,
            &Coupling {
                force_b: tr.actuated,
                torque_b: at.u,
            },
        )
        .unwrap();
    let brake = layer.robotic.brake(&xr);
    let mut expected =
        RoboticFilter::from_scenario(&s, model.clone()).filter_with(&xr, Some(&brake));
    expected.report.faults |= faults::SAFE_MODE;
    assert_eq!(bits(&rb), bits(&expected));
    // the partner is still accounted for: a missing or invalid nominal is flagged
    let silent = layer.translational_stage(&o, None);
    assert_eq!(
        silent.report.faults & (faults::SAFE_MODE | faults::NOMINAL_MISSING),
        faults::SAFE_MODE | faults::NOMINAL_MISSING
    );
    assert_eq!(bits(&silent)[..6], bits(&tr)[..6], "the same retreat");
    let bad = layer.robotic_stage(
        &o,
        &tr.actuated,
        &at.u,
        Some(&Vector7::from_element(f64::NAN)),
    );
    assert_ne!(bad.report.faults & faults::INVALID_NOMINAL, 0);
    for v in [f64::NAN, f64::INFINITY, -1e300, 1e3] {
        for k in 0..OBSERVED {
            let o = perturbed(&o, k, v);
            let tr = layer.translational_stage(&o, Some(&f_nom));
            let at = layer.attitude_stage(&o, &tr.actuated, Some(&tau_nom));
            let rb = layer.robotic_stage(&o, &tr.actuated, &at.u, Some(&tau_m_nom));
            assert!(
                finite(&tr.actuated) && tr.actuated.amax() <= layer.translational.input_bound()
            );
            assert!(finite(&at.actuated) && at.actuated.amax() <= layer.attitude.input_bound());
            assert!(finite(&rb.actuated) && rb.actuated.amax() <= layer.robotic.input_bound());
        }
    }
}

/// The attitude filter's emergency brake (no solver produced a command) keeps the
/// joint-coupling contract the robotic filter's certificate rests on: with the arm
/// extended and the base turning at 0.5 rad/s, the plain braking law's (saturated) torque
/// breaks it; the emergency brake is gentler, within it, and still against the rate
/// error; a slow base gets the plain braking law.
#[test]
fn the_attitude_emergency_brake_keeps_the_joint_coupling_contract() {
    let s = scenario();
    let model = robot();
    let f = AttitudeFilter::from_scenario(&s, model.total_mass());
    let at = |w: f64| {
        let mut o = observation();
        o.omega_b = Vector3::new(w, -w, w);
        o.theta = Vector7::from_row_slice(&[0.0, -0.6, 0.0, 0.6, 0.0, -0.6, 0.0]);
        f.input(&model, &o, &Coupling::default()).unwrap()
    };
    let holds = |x: &AttitudeInput, u: &Vector3<f64>| {
        let hard = f.rows(x).unwrap().2;
        hard[6..].iter().all(|r| r.a.dot(u) + r.c >= -1e-12)
    };
    let fast = at(0.5);
    assert!(
        !holds(&fast, &f.brake(&fast)),
        "the plain brake breaks the contract"
    );
    let u = f.emergency_brake(&fast);
    assert!(holds(&fast, &u) && u.amax() <= f.input_bound(), "{u}");
    assert!(
        u.dot(&(fast.omega_b - fast.omega_target_b)) < 0.0,
        "still a brake: {u}"
    );
    let slow = at(1e-4);
    assert!(holds(&slow, &f.brake(&slow)));
    assert_eq!(f.emergency_brake(&slow), f.brake(&slow));
}
