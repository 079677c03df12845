//! Rigid-body dynamics of the servicer: fixed-base arm (paper: `M(θ) θ̈ + C(θ, θ̇) θ̇ = τ_M`),
//! the coupled free-flying system (13 DoF, Pinocchio free-flyer convention), momenta, energy and
//! the Schur-reduced arm dynamics on a free-floating base used by the robotic safety filter.
//!
//! Free-flyer convention (identical to Pinocchio with `JointModelFreeFlyer`):
//! * generalized velocity `ν = [v_B; ω_B; θ̇]` (13): `v_B` velocity of the base-frame origin
//!   (m/s), `ω_B` base angular velocity (rad/s), both in base-frame coordinates;
//! * input `u = [f_B; τ_B; τ_M]`: force on the base (N, base frame, applied at the base
//!   origin), torque on the base about its origin (N m, base frame), joint torques (N m);
//! * `ν̇` as returned by Pinocchio's `aba`: its first three entries are `d/dt (v_B in base
//!   coordinates)`, i.e. the classical acceleration of the base origin in base coordinates is
//!   `ν̇[0..3] + ω_B × v_B`.
//!
//! No gravity anywhere (orbital free flight: the orbit is propagated for the system CoM
//! separately). The dynamics do not depend on the base pose.

use nalgebra::{Cholesky, Matrix3, Matrix6, SMatrix, Vector3, Vector6};

use crate::model::Robot;
use crate::spatial::{ArticulatedInertia, Force, Inertia, Motion, Transform};
use crate::{Matrix7, Matrix13, NJ, Vector7, Vector13};

/// Base rows of the generalized coordinates: 0..6. Joint `i` (0-based) is at index `6 + i`.
const NB: usize = 6;

/// Momentum of the whole servicer, base frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Momentum {
    /// System centre of mass (m, base frame).
    pub com: Vector3<f64>,
    /// Total linear momentum (kg m/s, base frame).
    pub linear: Vector3<f64>,
    /// Angular momentum about the base-frame origin (kg m²/s, base frame).
    pub angular_base: Vector3<f64>,
    /// Angular momentum about the system CoM (kg m²/s, base frame).
    pub angular_com: Vector3<f64>,
}

/// The base's angular acceleration as an affine map of the inputs, from the 13-DoF
/// forward dynamics:
///
/// ```text
/// ω̇_B = P τ_B + Q τ_M + r = P_L τ_B + r_L + Q (τ_M − τ_hold(τ_B))
/// ```
///
/// where `τ_hold` is the joint torque that keeps the joint rates constant (`θ̈ = 0`, the
/// arm "locked" as it moves) and `P_L`, `r_L` describe the base with the arm locked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseAngularDynamics {
    /// `∂ω̇_B/∂τ_B` (3×3, 1/(kg m²)): the inverse of the base's articulated inertia.
    pub p: Matrix3<f64>,
    /// `∂ω̇_B/∂τ_M` (3×7, 1/(kg m²)): the arm's reaction on the base per joint torque.
    pub q: SMatrix<f64, 3, NJ>,
    /// `ω̇_B` at `τ_B = 0`, `τ_M = 0` under the given base force (rad/s²): velocity
    /// products of the whole servicer and the torque of the force about the system CoM.
    pub r: Vector3<f64>,
    /// `∂ω̇_B/∂τ_B` with the arm locked (`θ̈ = 0`): the inverse of the locked inertia
    /// about the base, 1/(kg m²).
    pub p_locked: Matrix3<f64>,
    /// `ω̇_B` at `τ_B = 0` with the arm locked, under the given base force (rad/s²).
    pub r_locked: Vector3<f64>,
}

/// Arm dynamics on a free-floating base reduced to the joint space (Schur complement):
/// `θ̈ = M_eff⁻¹ (τ_M − c_eff)` reproduces the 13-DoF forward dynamics exactly for the given
/// base angular velocity and base wrench.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedArmDynamics {
    /// `M_eff = M_θθ − M_θb M_bb⁻¹ M_bθ` (7×7, kg m²), symmetric positive definite.
    pub m_eff: Matrix7,
    /// `c_eff = c_free + ξ` (N m).
    pub c_eff: Vector7,
    /// Velocity-product part: `b_θ − M_θb M_bb⁻¹ b_b` (N m), `b` = nonlinear effects.
    pub c_free: Vector7,
    /// `K = M_θb M_bb⁻¹` (7×6): maps a base wrench `[f_B; τ_B]` to its joint-space coupling.
    pub wrench_map: SMatrix<f64, NJ, 6>,
    /// Coupling input `ξ = K [f_B; τ_B]` (N m): what the base wrench contributes to `c_eff`.
    pub xi: Vector7,
}

impl Robot {
    #[inline]
    fn joint_motion(&self, i: usize, qd: f64) -> Motion {
        Motion::new(Vector3::zeros(), self.joints[i].axis * qd)
    }

    #[inline]
    fn placements(&self, theta: &Vector7) -> [Transform; NJ] {
        let mut x = [Transform::IDENTITY; NJ];
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = self.joint_placement(i, theta[i]);
        }
        x
    }

    /// Recursive Newton-Euler: generalized forces `[f_B; τ_B; τ_M]` that produce `nu_dot` at
    /// `(θ, ν)` (no gravity, base frame for the base part). With `nu_dot = 0` this is
    /// Pinocchio's `nonLinearEffects`.
    pub fn rnea(&self, theta: &Vector7, nu: &Vector13, nu_dot: &Vector13) -> Vector13 {
        self.rnea_with(&self.inertias, theta, nu, nu_dot)
    }

    /// [`Self::rnea`] with the bodies' inertias `inertias` (base first) in place of the
    /// model's: linear in them, so with one body's inertia a direction of its mass
    /// properties and every other zero it is that direction's column of the inverse
    /// dynamics' regressor (the robotic filter's bound on a model error).
    pub fn rnea_with(
        &self,
        inertias: &[Inertia; NJ + 1],
        theta: &Vector7,
        nu: &Vector13,
        nu_dot: &Vector13,
    ) -> Vector13 {
        let x = self.placements(theta);
        let mut v = [Motion::ZERO; NJ + 1];
        let mut f = [Force::ZERO; NJ + 1];
        v[0] = Motion::new(nu.fixed_rows::<3>(0).into(), nu.fixed_rows::<3>(3).into());
        let mut a = Motion::new(
            nu_dot.fixed_rows::<3>(0).into(),
            nu_dot.fixed_rows::<3>(3).into(),
        );
        let iv = inertias[0].mul_motion(&v[0]);
        f[0] = inertias[0].mul_motion(&a) + v[0].cross_force(&iv);
        for i in 0..NJ {
            let s_qd = self.joint_motion(i, nu[NB + i]);
            let vi = x[i].inv_act_motion(&v[i]) + s_qd;
            a = x[i].inv_act_motion(&a) + self.joint_motion(i, nu_dot[NB + i]) + vi.cross(&s_qd);
            let inertia = &inertias[i + 1];
            let iv = inertia.mul_motion(&vi);
            f[i + 1] = inertia.mul_motion(&a) + vi.cross_force(&iv);
            v[i + 1] = vi;
        }
        let mut tau = Vector13::zeros();
        for i in (0..NJ).rev() {
            tau[NB + i] = self.joints[i].axis.dot(&f[i + 1].ang);
            let fp = x[i].act_force(&f[i + 1]);
            f[i] = f[i] + fp;
        }
        tau.fixed_rows_mut::<3>(0).copy_from(&f[0].lin);
        tau.fixed_rows_mut::<3>(3).copy_from(&f[0].ang);
        tau
    }

    /// Free-flyer nonlinear effects `b(θ, ν)` (13): Coriolis/centrifugal generalized forces,
    /// zero gravity (= Pinocchio `nonLinearEffects`, `rnea(q, v, 0)`).
    pub fn nonlinear_effects(&self, theta: &Vector7, nu: &Vector13) -> Vector13 {
        self.rnea(theta, nu, &Vector13::zeros())
    }

    /// Composite-rigid-body algorithm: the 13×13 free-flyer mass matrix `M(θ)` (symmetric,
    /// both triangles filled). Rows/columns ordered like `ν`.
    pub fn mass_matrix(&self, theta: &Vector7) -> Matrix13 {
        self.mass_matrix_with(&self.inertias, theta)
    }

    /// [`Self::mass_matrix`] with the bodies' inertias `inertias` (base first): linear in
    /// them, as [`Self::rnea_with`].
    pub fn mass_matrix_with(&self, inertias: &[Inertia; NJ + 1], theta: &Vector7) -> Matrix13 {
        let x = self.placements(theta);
        let mut ic: [Inertia; NJ + 1] = *inertias;
        for i in (0..NJ).rev() {
            let t = ic[i + 1].transformed(&x[i]);
            ic[i] = ic[i].add(&t);
        }
        let mut m = Matrix13::zeros();
        m.fixed_view_mut::<6, 6>(0, 0).copy_from(&ic[0].to_matrix());
        for i in 0..NJ {
            let s = Motion::new(Vector3::zeros(), self.joints[i].axis);
            let mut fi = ic[i + 1].mul_motion(&s);
            m[(NB + i, NB + i)] = self.joints[i].axis.dot(&fi.ang);
            for j in (0..=i).rev() {
                fi = x[j].act_force(&fi); // now in body j
                if j > 0 {
                    let mij = self.joints[j - 1].axis.dot(&fi.ang);
                    m[(NB + j - 1, NB + i)] = mij;
                    m[(NB + i, NB + j - 1)] = mij;
                }
            }
            let fv = fi.to_vector6();
            m.fixed_view_mut::<6, 1>(0, NB + i).copy_from(&fv);
            m.fixed_view_mut::<1, 6>(NB + i, 0)
                .copy_from(&fv.transpose());
        }
        m
    }

    /// Articulated-body algorithm: free-flyer forward dynamics `ν̇ = FD(θ, ν, u)` with exactly
    /// Pinocchio `aba`'s output convention (see the module doc). `None` only if the model is
    /// numerically singular (cannot happen for a validated model with finite inputs).
    pub fn forward_dynamics(
        &self,
        theta: &Vector7,
        nu: &Vector13,
        u: &Vector13,
    ) -> Option<Vector13> {
        let v0 = Motion::new(nu.fixed_rows::<3>(0).into(), nu.fixed_rows::<3>(3).into());
        let qd: Vector7 = nu.fixed_rows::<NJ>(NB).into();
        self.aba(theta, &v0, &qd, u)
    }

    /// Forward dynamics for the simulator, evaluated with the base linear velocity set to zero
    /// (the internal dynamics do not depend on it, and feeding an orbital speed of 7.6 km/s
    /// would cost precision).
    ///
    /// Inputs: `theta` (rad), `omega_b` base angular velocity (rad/s, base frame), `theta_dot`
    /// (rad/s), `u = [f_B; τ_B; τ_M]` as in [`Robot::forward_dynamics`].
    /// Output `[a_B; ω̇_B; θ̈]`: `a_B` is the CLASSICAL acceleration of the base origin in
    /// base-frame coordinates (m/s², valid for any actual base linear velocity), `ω̇_B`
    /// (rad/s², base frame), `θ̈` (rad/s²).
    pub fn forward_dynamics_sim(
        &self,
        theta: &Vector7,
        omega_b: &Vector3<f64>,
        theta_dot: &Vector7,
        u: &Vector13,
    ) -> Option<Vector13> {
        self.aba(
            theta,
            &Motion::new(Vector3::zeros(), *omega_b),
            theta_dot,
            u,
        )
    }

    fn aba(&self, theta: &Vector7, v0: &Motion, qd: &Vector7, u: &Vector13) -> Option<Vector13> {
        let x = self.placements(theta);
        let mut v = [Motion::ZERO; NJ + 1];
        let mut c = [Motion::ZERO; NJ + 1];
        let mut ia = [ArticulatedInertia::from_rigid(&Inertia::ZERO); NJ + 1];
        let mut pa = [Force::ZERO; NJ + 1];
        v[0] = *v0;
        ia[0] = ArticulatedInertia::from_rigid(&self.inertias[0]);
        pa[0] = v[0].cross_force(&self.inertias[0].mul_motion(&v[0]));
        for i in 0..NJ {
            let s_qd = self.joint_motion(i, qd[i]);
            let vi = x[i].inv_act_motion(&v[i]) + s_qd;
            let inertia = &self.inertias[i + 1];
            c[i + 1] = vi.cross(&s_qd);
            pa[i + 1] = vi.cross_force(&inertia.mul_motion(&vi));
            ia[i + 1] = ArticulatedInertia::from_rigid(inertia);
            v[i + 1] = vi;
        }
        let mut ua = [Vector3::zeros(); NJ]; // U = IA S: angular part (lin part in ul)
        let mut ul = [Vector3::zeros(); NJ];
        let mut dinv = [0.0; NJ];
        let mut uu = [0.0; NJ];
        for i in (0..NJ).rev() {
            let s = &self.joints[i].axis;
            let b = i + 1;
            let ul_i = ia[b].b * s;
            let ua_i = ia[b].d * s;
            let d = s.dot(&ua_i);
            if d <= 0.0 || !d.is_finite() {
                return None;
            }
            let di = 1.0 / d;
            let u_i = u[NB + i] - s.dot(&pa[b].ang);
            let mut iab = ia[b];
            iab.sub_rank1(&ul_i, &ua_i, di);
            let pab =
                pa[b] + iab.mul_motion(&c[b]) + Force::new(ul_i * (u_i * di), ua_i * (u_i * di));
            let t = iab.transformed(&x[i]);
            ia[i].add_assign(&t);
            pa[i] = pa[i] + x[i].act_force(&pab);
            ul[i] = ul_i;
            ua[i] = ua_i;
            dinv[i] = di;
            uu[i] = u_i;
        }
        let rhs: Vector6<f64> = u.fixed_rows::<6>(0) - pa[0].to_vector6();
        let a0 = Cholesky::new(ia[0].to_matrix())?.solve(&rhs);
        let mut out = Vector13::zeros();
        out.fixed_rows_mut::<6>(0).copy_from(&a0);
        let mut a = Motion::from_vector6(&a0);
        for i in 0..NJ {
            let b = i + 1;
            let ap = x[i].inv_act_motion(&a) + c[b];
            let qdd = (uu[i] - ul[i].dot(&ap.lin) - ua[i].dot(&ap.ang)) * dinv[i];
            a = ap + self.joint_motion(i, qdd);
            out[NB + i] = qdd;
        }
        if out.iter().all(|x| x.is_finite()) {
            Some(out)
        } else {
            None
        }
    }

    /// Fixed-base arm mass matrix `M(θ)` (7×7, kg m²) of the paper's robotic subsystem
    /// `M(θ) θ̈ + C(θ, θ̇) θ̇ = τ_M` (base held inertially fixed).
    pub fn arm_mass_matrix(&self, theta: &Vector7) -> Matrix7 {
        self.mass_matrix(theta).fixed_view::<NJ, NJ>(NB, NB).into()
    }

    /// Fixed-base Coriolis/centrifugal torques `C(θ, θ̇) θ̇` (N m), no gravity.
    pub fn arm_coriolis(&self, theta: &Vector7, theta_dot: &Vector7) -> Vector7 {
        let mut nu = Vector13::zeros();
        nu.fixed_rows_mut::<NJ>(NB).copy_from(theta_dot);
        self.nonlinear_effects(theta, &nu)
            .fixed_rows::<NJ>(NB)
            .into()
    }

    /// Fixed-base arm forward dynamics `θ̈ = M⁻¹ (τ_M − C θ̇)` (rad/s²).
    pub fn arm_forward_dynamics(
        &self,
        theta: &Vector7,
        theta_dot: &Vector7,
        tau: &Vector7,
    ) -> Option<Vector7> {
        let m = self.arm_mass_matrix(theta);
        let rhs = tau - self.arm_coriolis(theta, theta_dot);
        Cholesky::new(m).map(|ch| ch.solve(&rhs))
    }

    /// Arm dynamics on the free-floating base reduced to joint space (Schur complement of the
    /// base block), for base angular velocity `omega_b` (rad/s, base frame) and base wrench
    /// `wrench = [f_B; τ_B]` (N, N m; base frame, about the base origin). The base linear
    /// velocity does not enter (see [`Robot::forward_dynamics_sim`]).
    ///
    /// `θ̈ = M_eff⁻¹ (τ_M − c_eff)` equals the `θ̈` of the full 13-DoF forward dynamics with
    /// `u = [f_B; τ_B; τ_M]` for every `τ_M`.
    pub fn reduced_arm_dynamics(
        &self,
        theta: &Vector7,
        theta_dot: &Vector7,
        omega_b: &Vector3<f64>,
        wrench: &Vector6<f64>,
    ) -> Option<ReducedArmDynamics> {
        let m = self.mass_matrix(theta);
        let mut nu = Vector13::zeros();
        nu.fixed_rows_mut::<3>(3).copy_from(omega_b);
        nu.fixed_rows_mut::<NJ>(NB).copy_from(theta_dot);
        let b = self.nonlinear_effects(theta, &nu);
        let mbb: Matrix6<f64> = m.fixed_view::<6, 6>(0, 0).into();
        let mbt: SMatrix<f64, 6, NJ> = m.fixed_view::<6, NJ>(0, NB).into();
        let mtt: Matrix7 = m.fixed_view::<NJ, NJ>(NB, NB).into();
        let ch = Cholesky::new(mbb)?;
        // K = M_θb M_bb⁻¹ = (M_bb⁻¹ M_bθ)ᵀ
        let kt = ch.solve(&mbt);
        let k: SMatrix<f64, NJ, 6> = kt.transpose();
        let mut m_eff = mtt - k * mbt;
        m_eff = (m_eff + m_eff.transpose()) * 0.5;
        let bb: Vector6<f64> = b.fixed_rows::<6>(0).into();
        let bt: Vector7 = b.fixed_rows::<NJ>(NB).into();
        let c_free = bt - k * bb;
        let xi = k * wrench;
        Some(ReducedArmDynamics {
            m_eff,
            c_eff: c_free + xi,
            c_free,
            wrench_map: k,
            xi,
        })
    }

    /// `ω̇_B = P τ_B + Q τ_M + r` at `(θ, θ̇)` with base angular velocity `omega_b` and base
    /// force `force_b` (N, base frame, at the base origin). The base linear velocity does
    /// not enter. `None` if the mass matrix is not positive definite.
    pub fn base_angular_dynamics(
        &self,
        theta: &Vector7,
        theta_dot: &Vector7,
        omega_b: &Vector3<f64>,
        force_b: &Vector3<f64>,
    ) -> Option<BaseAngularDynamics> {
        let m = self.mass_matrix(theta);
        let mut nu = Vector13::zeros();
        nu.fixed_rows_mut::<3>(3).copy_from(omega_b);
        nu.fixed_rows_mut::<NJ>(NB).copy_from(theta_dot);
        let b = self.nonlinear_effects(theta, &nu);
        let minv = Cholesky::new(m)?.inverse();
        let mut u0 = -b;
        u0[0] += force_b.x;
        u0[1] += force_b.y;
        u0[2] += force_b.z;
        let acc = minv * u0;
        // arm locked: M_bb ν̇_b = [f; τ_B] − b_b
        let mbb: Matrix6<f64> = m.fixed_view::<6, 6>(0, 0).into();
        let mbb_inv = Cholesky::new(mbb)?.inverse();
        let u0b: Vector6<f64> = u0.fixed_rows::<6>(0).into();
        let acc_locked = mbb_inv * u0b;
        Some(BaseAngularDynamics {
            p: minv.fixed_view::<3, 3>(3, 3).into(),
            q: minv.fixed_view::<3, NJ>(3, NB).into(),
            r: acc.fixed_rows::<3>(3).into(),
            p_locked: mbb_inv.fixed_view::<3, 3>(3, 3).into(),
            r_locked: acc_locked.fixed_rows::<3>(3).into(),
        })
    }

    /// System CoM, linear momentum and angular momenta (base frame) for `(θ, ν)`.
    pub fn momentum(&self, theta: &Vector7, nu: &Vector13) -> Momentum {
        let x = self.placements(theta);
        let mut pose = Transform::IDENTITY;
        let mut v = Motion::new(nu.fixed_rows::<3>(0).into(), nu.fixed_rows::<3>(3).into());
        let mut h = self.inertias[0].mul_motion(&v);
        let mut mc = self.inertias[0].h;
        for i in 0..NJ {
            pose = pose.compose(&x[i]);
            v = x[i].inv_act_motion(&v) + self.joint_motion(i, nu[NB + i]);
            let inertia = &self.inertias[i + 1];
            h = h + pose.act_force(&inertia.mul_motion(&v));
            mc += pose.rot * inertia.h + pose.trans * inertia.mass;
        }
        let com = mc / self.total_mass;
        Momentum {
            com,
            linear: h.lin,
            angular_base: h.ang,
            angular_com: h.ang - com.cross(&h.lin),
        }
    }

    /// A bound over every joint state on each body's CoM distance from a point fixed in
    /// the base frame (m), body 0 the base: `‖q − c_0‖` for the base, and for link `k`
    /// the chain `‖q − o_1‖ + Σ_{i<k} ‖o_{i+1} − o_i‖ + ‖c_k − o_k‖` (`o_i` the origin of
    /// link `i`, on joint `i`'s axis: each term is a fixed offset in one body's frame, so
    /// the triangle inequality bounds the distance at every `θ`). A body without mass
    /// gets 0.
    pub fn body_com_distance_bounds(&self, q: &Vector3<f64>) -> [f64; NJ + 1] {
        let kin = self.kinematics(&Vector7::zeros());
        let com_of = |k: usize| {
            let i = &self.inertias[k];
            (i.mass > 0.0).then(|| i.h / i.mass)
        };
        let mut out = [0.0; NJ + 1];
        if let Some(c0) = com_of(0) {
            out[0] = (q - (kin.pose[0].trans + kin.pose[0].rot * c0)).norm();
        }
        let mut chain = (q - kin.pose[1].trans).norm();
        for (k, bound) in out.iter_mut().enumerate().skip(1) {
            if k > 1 {
                chain += (kin.pose[k].trans - kin.pose[k - 1].trans).norm();
            }
            if let Some(ck) = com_of(k) {
                *bound = chain + ck.norm();
            }
        }
        out
    }

    /// The mass of body `k` (0 the base) [kg]; 0 beyond the arm.
    pub fn body_mass(&self, k: usize) -> f64 {
        self.inertias.get(k).map_or(0.0, |i| i.mass)
    }

    /// A bound on how far the plant's system CoM lies from this model's at `θ` [m], for
    /// every plant whose base mass is within `±base_mass_rel` of the model's, whose base
    /// CoM is within `base_com_m` of it and whose link masses are each within
    /// `±link_mass_rel` (links' CoMs as modelled). With `m'_k = m_k (1 + ε_k)` and
    /// `Σ_k m_k (c_k − c) = 0`:
    /// `c' − c = (Σ_k m_k ε_k (c_k − c) + m'_0 s) / Σ_k m'_k`, so
    /// `‖c' − c‖ ≤ (Σ_k m_k ε̄_k ‖c_k − c‖ + m_0 (1 + ε̄_0) s̄) / Σ_k m_k (1 − ε̄_k)`.
    /// `None` when the masses at their declared extremes leave the servicer none.
    pub fn com_shift_bound(
        &self,
        theta: &Vector7,
        base_mass_rel: f64,
        base_com_m: f64,
        link_mass_rel: f64,
    ) -> Option<f64> {
        let kin = self.kinematics(theta);
        let c = self.center_of_mass(theta);
        let rel = |k: usize| if k == 0 { base_mass_rel } else { link_mass_rel };
        let (mut moved, mut low) = (0.0, 0.0);
        for (k, (p, i)) in kin.pose.iter().zip(self.inertias.iter()).enumerate() {
            if i.mass <= 0.0 {
                continue;
            }
            let c_k = p.act_point(&(i.h / i.mass));
            moved += i.mass * rel(k) * (c_k - c).norm();
            low += i.mass * (1.0 - rel(k));
        }
        let shifted = self.body_mass(0) * (1.0 + base_mass_rel) * base_com_m;
        (low > 0.0).then(|| (moved + shifted) / low)
    }

    /// System centre of mass in the base frame (m).
    pub fn center_of_mass(&self, theta: &Vector7) -> Vector3<f64> {
        let kin = self.kinematics(theta);
        let mut mc = Vector3::zeros();
        for (p, i) in kin.pose.iter().zip(self.inertias.iter()) {
            mc += p.rot * i.h + p.trans * i.mass;
        }
        mc / self.total_mass
    }

    /// Velocity of the system CoM relative to the base frame (m/s, base frame) for joint
    /// rates `theta_dot` with the base held fixed: `ċ_B = J_c θ̇` (the total linear momentum
    /// of `ν = [0; 0; θ̇]` divided by the total mass).
    pub fn center_of_mass_velocity(&self, theta: &Vector7, theta_dot: &Vector7) -> Vector3<f64> {
        let mut nu = Vector13::zeros();
        nu.fixed_rows_mut::<NJ>(NB).copy_from(theta_dot);
        self.momentum(theta, &nu).linear / self.total_mass
    }

    /// Kinetic energy `½ νᵀ M ν` (J).
    pub fn kinetic_energy(&self, theta: &Vector7, nu: &Vector13) -> f64 {
        let x = self.placements(theta);
        let mut v = Motion::new(nu.fixed_rows::<3>(0).into(), nu.fixed_rows::<3>(3).into());
        let mut e = v.dot(&self.inertias[0].mul_motion(&v));
        for i in 0..NJ {
            v = x[i].inv_act_motion(&v) + self.joint_motion(i, nu[NB + i]);
            e += v.dot(&self.inertias[i + 1].mul_motion(&v));
        }
        0.5 * e
    }

    /// Rotational inertia of the whole servicer about its CoM at `θ`, base frame (kg m²).
    pub fn system_inertia_com(&self, theta: &Vector7) -> Matrix3<f64> {
        let m = self.mass_matrix(theta);
        let i_o: Matrix3<f64> = m.fixed_view::<3, 3>(3, 3).into();
        let c = self.center_of_mass(theta);
        let sc = crate::spatial::skew(&c);
        i_o + sc * sc * self.total_mass
    }
}
