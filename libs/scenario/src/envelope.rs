//! The certified envelope of the target's motion (docs/SAFETY.md, "The certified
//! envelope"): how fast the line of sight to the grasping point can turn, against how fast
//! the boresight may follow it.
//!
//! The line of sight `ρ = p_G − r` from the servicer's CoM to the grasping point turns at
//! `‖P⊥ρ̇‖/‖ρ‖ ≤ (‖v_G‖ + ‖P⊥v‖)/‖ρ‖` (`P⊥` across `ρ`). The grasping point's speed `v_G`
//! is the target's; the servicer's part `‖P⊥v‖ ≤ √2 w_tr ‖ρ‖` is the translational filter's
//! line-of-sight contract (`safety.translational.los_speed_budget_rad_s`, four rows on two
//! axes across the line of sight); the zone and the corridor, barriers that hold, keep
//! `‖ρ‖` above a least length. The attitude filter keeps the boresight's rate across itself
//! at most `w̄` (`boresight_rate_max_rad_s`), and in steady state it can follow a turning
//! line of sight at `w̄` less its sampled-data margin only. So a scenario is in the envelope
//! only if `v̄_G / ρ_min + √2 w_tr` does not exceed that rate (E1) and the base can hold the
//! tumble's rate within its rate and boresight-rate rows (E2): a conservative rate budget,
//! worst case over the whole approach; the red team and the spin sweep measure the rest.

use crate::{Scenario, ScenarioError, V3};

/// `ω̂` is a principal axis of the target when `‖(Iω̂) × ω̂‖ ≤ PRINCIPAL_TOLERANCE ‖Iω̂‖`
/// [-]: the torque-free tumble is then a constant spin about it.
pub const PRINCIPAL_TOLERANCE: f64 = 1e-9;

/// The least `σ = ‖c × s‖` [-] the translational filter's line-of-sight contract needs
/// between its fixed reference `c` (across the corridor axis) and the line of sight `s`
/// (`sc_cbf::los_contract`): the geometry must keep the line of sight less than
/// `acos(MIN_LOS_CONTRACT_SIGMA)` (84°) off the corridor axis.
pub const MIN_LOS_CONTRACT_SIGMA: f64 = 0.1;

/// The largest amplification `κ` of a tumble off the target's principal axes [-]: the
/// attitude filter's in-sample bounds take the grasping point's acceleration as at most
/// `2‖ω_T‖²‖p_G‖`, and a torque-free tumble's is at most `((κ + 1)/2)‖ω_T‖²‖p_G‖`.
pub const MAX_OFF_PRINCIPAL_AMPLIFICATION: f64 = 3.0;

/// Two unit axes across the boresight `d` (unit): `e₁ ⊥ d`, `e₂ = d × e₁` — the axes of the
/// attitude filter's boresight-rate rows (`sc_cbf::attitude::boresight_rate`).
pub fn across_boresight(d: &V3) -> [V3; 2] {
    // the body axis least aligned with d, made orthogonal to it
    let k = (0..3)
        .min_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let e1 = normalize(&sub(&e, &scale(d, dot(d, &e))));
    [e1, cross(d, &e1)]
}

/// Where the grasping fixture is, in F_T, as far as the envelope is concerned: a point and
/// the radius of a ball about it that holds the fixture [m] (the declared fixture: its
/// point, radius 0). Every quantity of the envelope the fixture enters — its distance from
/// the spin axis and from the centre, its reach along the corridor axis — is 1-Lipschitz
/// in the fixture's position, so the ball's worst case is the point's plus the radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixtureBall {
    pub point_m: V3,
    pub radius_m: f64,
}

/// The line-of-sight envelope of a scenario (all bounds over the whole run).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineOfSightEnvelope {
    /// The rate at which the boresight can follow the line of sight in steady state: `w̄`
    /// less `ε_ω/γ_w + (D + ½JT)T/(1 − e^{−γ_w T})` of its rows [rad/s].
    pub boresight_follow_rad_s: f64,
    /// The translational filter's share, `√2 w_tr` [rad/s].
    pub translational_rad_s: f64,
    /// `‖ω_T(t)‖ ≤ amplification · ‖ω_T(0)‖` over the torque-free tumble [-] (1 for a spin
    /// about a principal axis).
    pub amplification: f64,
    /// The grasping point's speed per rad/s of tumble [m]: its distance from the spin axis
    /// (principal spin) or from the target's CoM.
    pub lever_m: f64,
    /// The shortest line of sight the zone and the corridor allow [m].
    pub los_min_m: f64,
    /// `‖ω_T(0)‖` [rad/s].
    pub spin_rad_s: f64,
    /// The fastest rate the base can hold on every axis in steady state, `min_i ω_max,i`
    /// less the rate rows' margin `ε_ω/γ_ω + (β_i + ½jT)T/(1 − e^{−γ_ω T})` [rad/s]: the
    /// rate synchronisation of phase II needs `‖ω_T‖` at most this.
    pub sync_limit_rad_s: f64,
    /// `sin∠(ω_T, d)` [-]: the share of the tumble across the corridor axis `d`, along which
    /// the boresight points in phase II (1 off the principal axes): the rate
    /// synchronisation turns the boresight at `amplification ‖ω_T‖` times this.
    pub spin_across_axis: f64,
    /// The least `σ` of the line-of-sight contract's axes over the certified set [-]:
    /// `√(1 − s²)`, `s = min(1, sin ψ + ‖p_G‖(1 + sin ψ)/L_min)`.
    pub contract_sigma_min: f64,
}

impl LineOfSightEnvelope {
    /// Bound on the grasping point's speed [m/s].
    pub fn grasp_speed_m_s(&self) -> f64 {
        self.amplification * self.spin_rad_s * self.lever_m
    }

    /// Bound on the rate at which the target turns the line of sight [rad/s] (infinite
    /// when the servicer could reach the fixture).
    pub fn target_rate_rad_s(&self) -> f64 {
        if self.los_min_m <= 0.0 {
            return f64::INFINITY;
        }
        self.grasp_speed_m_s() / self.los_min_m
    }

    /// The geometry the rows are defined for: the fixture out of reach, the line of sight
    /// within the contract's domain, a tumble whose rate the attitude filter's bounds cover.
    pub fn geometry_is_certifiable(&self) -> bool {
        self.los_min_m > 0.0
            && self.contract_sigma_min >= MIN_LOS_CONTRACT_SIGMA
            && self.amplification <= MAX_OFF_PRINCIPAL_AMPLIFICATION
    }

    /// Every rule of the envelope on the tumble and the geometry (what the validation
    /// checks for the scenario's own tumble, for any `ω_T(0)`: a Monte Carlo's draws).
    pub fn contains(&self) -> bool {
        self.limit_rad_s() > 0.0 && self.broken_tumble_rule().is_none()
    }

    /// What the target may take of the boresight's rate [rad/s].
    pub fn limit_rad_s(&self) -> f64 {
        self.boresight_follow_rad_s - self.translational_rad_s
    }

    /// The fastest tumble `‖ω_T(0)‖` of this geometry inside the envelope [rad/s]: the
    /// line of sight's (E1) and the synchronisation's (E2) limits.
    pub fn max_spin_rad_s(&self) -> f64 {
        let los = self.limit_rad_s() * self.los_min_m / (self.amplification * self.lever_m);
        let across = self.boresight_follow_rad_s / (self.amplification * self.spin_across_axis);
        los.min(self.sync_limit_rad_s / self.amplification)
            .min(across)
            .max(0.0)
    }

    /// The fastest rate of the tumble, `amplification ‖ω_T(0)‖` [rad/s].
    pub fn peak_spin_rad_s(&self) -> f64 {
        if self.spin_rad_s == 0.0 {
            0.0 // no tumble stays none, whatever the amplification
        } else {
            self.amplification * self.spin_rad_s
        }
    }

    /// (E2): the tumble's rate stays within what the base can hold on every axis and,
    /// across its boresight, within what the boresight may turn.
    pub fn base_can_hold_the_rate(&self) -> bool {
        let peak = self.peak_spin_rad_s();
        peak <= self.sync_limit_rad_s && peak * self.spin_across_axis <= self.boresight_follow_rad_s
    }
}

impl Scenario {
    /// The line-of-sight envelope of the scenario's own tumble.
    pub fn line_of_sight_envelope(&self) -> LineOfSightEnvelope {
        self.line_of_sight_envelope_for(&self.target.initial_omega_rad_s)
    }

    /// The line-of-sight envelope for the tumble `ω_T(0)` (in F_T) in this scenario's
    /// geometry (a Monte Carlo checks its fastest draw).
    pub fn line_of_sight_envelope_for(&self, omega_t: &V3) -> LineOfSightEnvelope {
        self.line_of_sight_envelope_at(omega_t, &self.declared_fixture())
    }

    /// [`Self::line_of_sight_envelope_for`] with the fixture anywhere in `fixture`.
    pub fn line_of_sight_envelope_at(
        &self,
        omega_t: &V3,
        fixture: &FixtureBall,
    ) -> LineOfSightEnvelope {
        self.envelope_about(omega_t, self.principal_axis(omega_t), fixture)
    }

    /// The declared fixture, `target.grasp_point_m`, as a ball of radius 0.
    pub fn declared_fixture(&self) -> FixtureBall {
        FixtureBall {
            point_m: self.target.grasp_point_m,
            radius_m: 0.0,
        }
    }

    /// The envelope of a tumble `omega_t` that is a constant spin about `principal`, or
    /// (`None`) one off the principal axes (amplification `κ`, lever `‖p_G‖`), with the
    /// fixture anywhere in `fixture` (the lever grows by its radius).
    fn envelope_about(
        &self,
        omega_t: &V3,
        principal: Option<V3>,
        fixture: &FixtureBall,
    ) -> LineOfSightEnvelope {
        let t = &self.target;
        let (p, e) = (&fixture.point_m, fixture.radius_m);
        let spin = norm(omega_t);
        let d = normalize(&self.safety.translational.corridor_axis);
        let (amplification, lever_m, axial, across) = match principal {
            Some(a) => {
                let a_r = rotate(&t.initial_attitude, &a);
                let across = norm(&cross(&a_r, &d));
                (1.0, norm(&cross(&a, p)) + e, Some((a, dot(&a, p))), across)
            }
            None => (self.target_inertia_ratio(), norm(p) + e, None, 1.0),
        };
        let los_min_m = self.shortest_line_of_sight(fixture, axial);
        LineOfSightEnvelope {
            boresight_follow_rad_s: self.boresight_follow_rad_s(),
            translational_rad_s: 2f64.sqrt() * self.safety.translational.los_speed_budget(),
            amplification,
            lever_m,
            los_min_m,
            spin_rad_s: spin,
            sync_limit_rad_s: self.sync_limit_rad_s(),
            spin_across_axis: across,
            contract_sigma_min: self.contract_sigma_min(los_min_m, norm(p) + e),
        }
    }

    /// `√(1 − s²)`, `s = min(1, sin ψ + ‖p_G‖(1 + sin ψ)/L_min)`: the line of sight's
    /// component across the corridor axis is at most `‖P⊥r‖ + ‖p_G‖ ≤ (L + ‖p_G‖) sin ψ +
    /// ‖p_G‖` for a CoM in the corridor, over `L ≥ L_min` (`p` the bound on `‖p_G‖` [m]).
    fn contract_sigma_min(&self, los_min_m: f64, p: f64) -> f64 {
        let psi = self
            .safety
            .translational
            .corridor_half_angle_deg
            .to_radians();
        let s = if los_min_m > 0.0 {
            (psi.sin() + p * (1.0 + psi.sin()) / los_min_m).min(1.0)
        } else {
            1.0
        };
        (1.0 - s * s).sqrt()
    }

    /// The unit spin axis in F_T when the tumble is a constant spin about a principal axis
    /// of the target in every realisation of the declared target inertia (its error scales
    /// the principal moments about F_T's axes, docs/UNCERTAINTY.md: a coordinate axis of
    /// F_T that is principal stays principal).
    fn principal_axis(&self, omega_t: &V3) -> Option<V3> {
        let spin = norm(omega_t);
        if spin == 0.0 {
            return None;
        }
        let a = scale(omega_t, 1.0 / spin);
        let ia = mat_vec(&self.target.inertia_kg_m2, &a);
        let principal = norm(&cross(&ia, &a)) <= PRINCIPAL_TOLERANCE * norm(&ia);
        let along_frame_axis = a.iter().filter(|c| c.abs() > PRINCIPAL_TOLERANCE).count() == 1;
        let inertia_known = self.uncertainty_bounds().model.target_inertia_rel == 0.0;
        (principal && (inertia_known || along_frame_axis)).then_some(a)
    }

    /// `κ = λ_max(I)(1 + e)/(λ_min(I)(1 − e))` of the target's inertia `I` with its declared
    /// relative error `e`: a torque-free tumble (`‖Iω‖` conserved) keeps `‖ω(t)‖ ≤ κ ‖ω(0)‖`
    /// and `‖ω̇‖ ≤ κ ‖ω‖²`. Infinite when `I` is not positive definite (refused by the
    /// validation).
    pub fn target_inertia_ratio(&self) -> f64 {
        let e = self.uncertainty_bounds().model.target_inertia_rel;
        let (lo, hi) = symmetric_eigen_range(&self.target.inertia_kg_m2);
        let lo = lo * (1.0 - e);
        if lo.is_nan() || lo <= 0.0 {
            return f64::INFINITY;
        }
        hi * (1.0 + e) / lo
    }

    /// The shortest line of sight from a servicer CoM outside the zone (`‖r‖ ≥ R_CAZ`) and
    /// inside the corridor (`d·r ≥ ‖r‖ cos ψ`) to the grasping point: `R_CAZ − ‖p_G‖`, and
    /// `R_CAZ cos ψ − max_t d·p_G(t)` (for a principal spin `max_t d·p_G = (â·p)(â_R·d) +
    /// ‖â × p‖ √(1 − (â_R·d)²)`, `â_R` the spin axis in F_R; else `‖p_G‖`), with the fixture anywhere in
    /// `fixture`: both grow by its radius.
    fn shortest_line_of_sight(&self, fixture: &FixtureBall, axial: Option<(V3, f64)>) -> f64 {
        let tr = &self.safety.translational;
        let r_caz = tr.caz_radius_m;
        let (p, e) = (&fixture.point_m, fixture.radius_m);
        let p_norm = norm(p) + e;
        let d = normalize(&tr.corridor_axis);
        let reach_along_d = match axial {
            Some((a, along)) => {
                let a_r = rotate(&self.target.initial_attitude, &a);
                let c = dot(&a_r, &d).clamp(-1.0, 1.0);
                along * c + norm(&cross(&a, p)) * (1.0 - c * c).max(0.0).sqrt() + e
            }
            None => p_norm,
        };
        let cos_psi = tr.corridor_half_angle_deg.to_radians().cos();
        (r_caz - p_norm).max(r_caz * cos_psi - reach_along_d)
    }

    /// `w̄ − ε_ω/γ_w − (D + ½JT)T/(1 − e^{−γ_w T})`, the worse of the two boresight-rate
    /// axes (`D = Σ|e_k,i| β_i`, `J = Σ|e_k,i| j`, as the attitude filter's rows).
    fn boresight_follow_rad_s(&self) -> f64 {
        let at = &self.safety.attitude;
        let t = self.mission.control_period_s;
        let g = at.gamma_boresight_rate_per_s;
        let worst = across_boresight(&normalize(&self.servicer.boresight_body))
            .iter()
            .map(|e| {
                let d: f64 = (0..3)
                    .map(|i| e[i].abs() * at.arm_reaction_budget_rad_s2[i])
                    .sum();
                let j: f64 = e.iter().map(|c| c.abs()).sum::<f64>() * at.angular_jerk_bound_rad_s3;
                (d + 0.5 * j * t) * t / (1.0 - (-g * t).exp())
            })
            .fold(0.0, f64::max);
        at.boresight_rate_max_rad_s - at.eps_omega / g - worst
    }

    /// `min_i min(ω_max,i, −ω_min,i) − ε_ω/γ_ω − (β_i + ½jT)T/(1 − e^{−γ_ω T})`: the
    /// steady state of the rate rows (docs/SAFETY.md, "Sampled-data rows": relative degree
    /// one), any body axis may have to carry the whole tumble.
    fn sync_limit_rad_s(&self) -> f64 {
        let at = &self.safety.attitude;
        let t = self.mission.control_period_s;
        let g = at.gamma_omega_per_s;
        (0..3)
            .map(|i| {
                let limit = at.omega_max_rad_s[i].min(-at.omega_min_rad_s[i]);
                let d = at.arm_reaction_budget_rad_s2[i];
                let j = at.angular_jerk_bound_rad_s3;
                limit - at.eps_omega / g - (d + 0.5 * j * t) * t / (1.0 - (-g * t).exp())
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The envelope's rules (after every other rule: they combine the sections), each
    /// naming the key that decides it (alone: the partition's check at a rate group's
    /// hold).
    pub fn validate_envelope(&self) -> Result<(), ScenarioError> {
        let env = self.line_of_sight_envelope();
        self.validate_target_geometry(&env)?;
        self.validate_rate_rows(&env)?;
        self.validate_tumble(&env)
    }

    /// The target's inertia, the grasping point's distance and the contract's axes.
    fn validate_target_geometry(&self, env: &LineOfSightEnvelope) -> Result<(), ScenarioError> {
        if !self.target_inertia_ratio().is_finite() {
            return Err(outside(
                "target.inertia_kg_m2",
                self.target.inertia_kg_m2,
                "is not positive definite (its least eigenvalue, less the declared error target_inertia_rel, is not positive): the tumble's rate cannot be bounded".into(),
            ));
        }
        if env.los_min_m <= 0.0 {
            return Err(outside(
                "target.grasp_point_m",
                self.target.grasp_point_m,
                format!(
                    "the zone and the corridor let the servicer come to {:.3} m of the grasping point: the fixture must lie nearer the target's centre than the zone's radius (safety.translational.caz_radius_m = {}) or, on the corridor's side, than R_CAZ cos ψ",
                    env.los_min_m, self.safety.translational.caz_radius_m
                ),
            ));
        }
        if env.contract_sigma_min < MIN_LOS_CONTRACT_SIGMA {
            return Err(outside(
                "target.grasp_point_m",
                self.target.grasp_point_m,
                format!(
                    "the line of sight to it may turn {:.1} deg off the corridor axis at the shortest {:.3} m, beyond the {:.1} deg the translational filter's line-of-sight contract is defined for; bring the fixture nearer the spin axis or the zone's radius out",
                    (1.0 - env.contract_sigma_min.powi(2))
                        .sqrt()
                        .asin()
                        .to_degrees(),
                    env.los_min_m,
                    MIN_LOS_CONTRACT_SIGMA.acos().to_degrees()
                ),
            ));
        }
        Ok(())
    }

    /// The attitude filter's rate rows leave room to move at all.
    fn validate_rate_rows(&self, env: &LineOfSightEnvelope) -> Result<(), ScenarioError> {
        let at = &self.safety.attitude;
        if env.boresight_follow_rad_s <= 0.0 {
            return Err(outside(
                "safety.attitude.boresight_rate_max_rad_s",
                at.boresight_rate_max_rad_s,
                format!(
                    "its rows' margins take all of it ({:.4} rad/s left): the boresight could not follow the line of sight at all (the margins grow with the control period, mission.control_period_s = {} s, and the jerk bound)",
                    env.boresight_follow_rad_s, self.mission.control_period_s
                ),
            ));
        }
        if env.sync_limit_rad_s <= 0.0 {
            return Err(outside(
                "safety.attitude.omega_max_rad_s",
                at.omega_max_rad_s,
                format!(
                    "with omega_min_rad_s = {:?}, the rate rows' margins take all of the smallest limit ({:.4} rad/s left): the base could not turn at all (the margins grow with the control period, mission.control_period_s = {} s, and the jerk bound)",
                    at.omega_min_rad_s, env.sync_limit_rad_s, self.mission.control_period_s
                ),
            ));
        }
        if env.limit_rad_s() <= 0.0 {
            return Err(outside(
                "safety.translational.los_speed_budget_rad_s",
                self.safety.translational.los_speed_budget(),
                format!(
                    "√2 times it takes all of the {:.4} rad/s at which the boresight can follow the line of sight (safety.attitude.boresight_rate_max_rad_s less its margins), none is left for the tumble",
                    env.boresight_follow_rad_s
                ),
            ));
        }
        Ok(())
    }

    /// (E2), then (E1): the tumble the base and the boresight can follow — the declared
    /// one and the fastest the run-time watch may take it for ([`Self::watched_envelope_for`]).
    fn validate_tumble(&self, env: &LineOfSightEnvelope) -> Result<(), ScenarioError> {
        let omega = self.target.initial_omega_rad_s;
        let watched = self.watched_envelope_for(&omega);
        let (env, margin) = match (env.broken_tumble_rule(), watched.broken_tumble_rule()) {
            (Some(rule), _) => (*env, (rule, String::new())),
            (None, Some(rule)) => (watched, (rule, self.watch_margin_note())),
            (None, None) => return Ok(()),
        };
        Err(outside(
            "target.initial_omega_rad_s",
            omega,
            format!("{}{}", env.explain(margin.0), margin.1),
        ))
    }

    /// The declared tumble's principal axis (unit, F_T), if it spins about one
    /// ([`Self::line_of_sight_envelope`] takes the spin as constant then).
    pub fn declared_spin_axis(&self) -> Option<V3> {
        self.principal_axis(&self.target.initial_omega_rad_s)
    }

    /// The declared bound `ē` on the error of the target's rate estimate [rad/s].
    pub fn target_rate_error(&self) -> f64 {
        self.uncertainty_bounds()
            .navigation
            .target_rate_rad_s
            .bound()
    }

    /// The declared bound `ē_G` on the error of the grasping point's estimate [m].
    pub fn grasp_point_error(&self) -> f64 {
        self.uncertainty_bounds().navigation.grasp_point_m.bound()
    }

    /// What the run-time watch adds to a true tumble at most: `2ē` [rad/s] (the estimate
    /// is up to `ē` off, and the watch adds `ē` to it; docs/SAFETY.md, "Safe mode").
    pub fn watch_margin_rad_s(&self) -> f64 {
        2.0 * self.target_rate_error()
    }

    /// The envelope of the fastest tumble the run-time watch may take the true tumble
    /// `omega_t` (F_T) for: about the declared axis at `|â·ω| + 2ē` (the start and a Monte
    /// Carlo's fastest draw are checked with it, so that the watch never fires on a
    /// declared spin about a principal axis; a declared tumble off the axes is judged as
    /// the watch judges it, `‖ω‖ + 2ē` with `κ`).
    pub fn watched_envelope_for(&self, omega_t: &V3) -> LineOfSightEnvelope {
        let e = self.target_rate_error();
        if e == 0.0 {
            // nothing unknown: the declared tumble as the start has always judged it
            return self.line_of_sight_envelope_for(omega_t);
        }
        let margin = 2.0 * (e + KNOWLEDGE_ROUNDING_RAD_S);
        self.knowledge_envelope(omega_t, self.watch_axis_tolerance_rad_s(), margin)
    }

    /// How far off the declared axis the run-time watch still takes an estimate for a
    /// spin about it [rad/s]: `2ē` (a true tumble within `ē` of the axis, seen through an
    /// estimate up to `ē` off) plus the navigation gate's rounding.
    pub fn watch_axis_tolerance_rad_s(&self) -> f64 {
        2.0 * self.target_rate_error() + KNOWLEDGE_ROUNDING_RAD_S
    }

    /// The suffix of a refusal that only the watch's margin causes.
    fn watch_margin_note(&self) -> String {
        let limit = self.line_of_sight_envelope().max_spin_rad_s() - self.watch_margin_rad_s();
        format!(
            " (this includes twice the declared error of the target's rate estimate, 2 × {:.4} rad/s, which the run-time watch adds: docs/SAFETY.md, \"Safe mode\"; so the declared tumble may be at most {:.4} rad/s)",
            self.target_rate_error(),
            limit.max(0.0)
        )
    }

    /// The envelope of the fastest tumble consistent with `omega` (F_T) known to within
    /// `error` [rad/s]: within `axis_tolerance` of the declared principal axis `â` a
    /// constant spin about it at `|â·ω| + error`; anywhere else a tumble off the principal
    /// axes at `‖ω‖ + error` (amplification `κ`, lever `‖p_G‖`) — whatever axis `omega`
    /// itself lies on, since the truth within `error` of it need not. The off-axes
    /// envelope is never less restrictive than a principal one: `κ ≥ 1`, `‖p_G‖ ≥ ‖â × p_G‖`,
    /// the tumble wholly across the corridor axis, the shortest line of sight no longer.
    /// Non-finite when `omega` is.
    pub fn knowledge_envelope(
        &self,
        omega: &V3,
        axis_tolerance: f64,
        error: f64,
    ) -> LineOfSightEnvelope {
        self.knowledge_envelope_at(omega, axis_tolerance, error, &self.declared_fixture())
    }

    /// [`Self::knowledge_envelope`] with the fixture anywhere in `fixture`.
    pub fn knowledge_envelope_at(
        &self,
        omega: &V3,
        axis_tolerance: f64,
        error: f64,
        fixture: &FixtureBall,
    ) -> LineOfSightEnvelope {
        let spin = norm(omega);
        if let Some(a) = self.declared_spin_axis() {
            let along = dot(omega, &a);
            if norm(&sub(omega, &scale(&a, along))) <= axis_tolerance {
                let sign = if along < 0.0 { -1.0 } else { 1.0 };
                let tumble = scale(&a, sign * (along.abs() + error));
                return self.envelope_about(&tumble, Some(a), fixture);
            }
        }
        let tumble = if spin == 0.0 {
            // no direction known: off every axis, as a noisy estimate of a still target
            scale(&[1.0, 1.0, 1.0], error / 3f64.sqrt())
        } else {
            scale(omega, (spin + error) / spin)
        };
        self.envelope_about(&tumble, None, fixture)
    }
}

/// The rounding the navigation gate allows beyond a declared error bound [rad/s]
/// (`sc_sim::navigation::NAVIGATION_ERROR_ROUNDING`): an estimate admitted at its bound
/// stays on the declared axis for the watch.
pub const KNOWLEDGE_ROUNDING_RAD_S: f64 = 1e-12;

/// A rule of the envelope on the tumble ((E1), (E2)) that a tumble breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TumbleRule {
    /// Off the principal axes with an inertia ratio beyond what the rows' bounds cover.
    OffPrincipal,
    /// (E2): faster than the base can hold within its rate rows.
    Sync,
    /// (E2): the synchronisation would turn the boresight faster than it may turn.
    AcrossAxis,
    /// (E1): the grasping point turns the line of sight faster than the boresight follows.
    LineOfSight,
    /// The geometry the rows are defined for: the fixture within reach, the line of sight
    /// outside the contract's domain.
    Geometry,
    /// Nothing is known of the tumble (a non-finite estimate).
    Unknown,
}

impl TumbleRule {
    /// Stable name (summary, logs).
    pub fn name(&self) -> &'static str {
        match self {
            TumbleRule::OffPrincipal => "off_principal",
            TumbleRule::Sync => "rate_synchronisation",
            TumbleRule::AcrossAxis => "boresight_rate",
            TumbleRule::LineOfSight => "line_of_sight_rate",
            TumbleRule::Geometry => "geometry",
            TumbleRule::Unknown => "unknown",
        }
    }
}

impl LineOfSightEnvelope {
    /// The first rule the tumble breaks, (E2) before (E1); `None` inside the envelope
    /// ([`Self::contains`] is `broken_tumble_rule().is_none()` with a positive limit).
    /// A tumble that is not a finite number is `Unknown`; no tumble at all cannot speed up
    /// (its amplification does not matter). Every comparison fails safe on a NaN.
    pub fn broken_tumble_rule(&self) -> Option<TumbleRule> {
        // above the limit, or not comparable (a NaN)
        let exceeds = |x: f64, limit: f64| {
            !matches!(
                x.partial_cmp(&limit),
                Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
            )
        };
        if !(self.spin_rad_s.is_finite() && self.lever_m.is_finite()) {
            return Some(TumbleRule::Unknown);
        }
        let still = self.spin_rad_s == 0.0;
        let off_principal = !still && exceeds(self.amplification, MAX_OFF_PRINCIPAL_AMPLIFICATION);
        let geometry = self.los_min_m > 0.0 && self.contract_sigma_min >= MIN_LOS_CONTRACT_SIGMA;
        if !off_principal && !geometry {
            return Some(TumbleRule::Geometry);
        }
        let peak = self.peak_spin_rad_s();
        if off_principal {
            Some(TumbleRule::OffPrincipal)
        } else if exceeds(peak, self.sync_limit_rad_s) {
            Some(TumbleRule::Sync)
        } else if exceeds(peak * self.spin_across_axis, self.boresight_follow_rad_s) {
            Some(TumbleRule::AcrossAxis)
        } else if exceeds(self.target_rate_rad_s(), self.limit_rad_s()) {
            Some(TumbleRule::LineOfSight)
        } else {
            None
        }
    }

    /// The line of sight's least length at which the boresight can follow this tumble's
    /// grasping point: `v̄_G / (w_follow − √2 w_tr)` [m] (infinite when nothing is left).
    pub fn range_needed_m(&self) -> f64 {
        let left = self.limit_rad_s();
        if left <= 0.0 {
            return f64::INFINITY;
        }
        self.grasp_speed_m_s() / left
    }

    /// One line: what `rule` says about this tumble, with its numbers and the limit.
    pub fn explain(&self, rule: TumbleRule) -> String {
        let peak = self.peak_spin_rad_s();
        match rule {
            TumbleRule::OffPrincipal => format!(
                "a tumble off the target's principal axes with the inertia ratio {:.2} (target.inertia_kg_m2 with its declared error) can speed up beyond what the attitude filter's in-sample bounds cover (ratio at most {MAX_OFF_PRINCIPAL_AMPLIFICATION}); spin about a principal axis",
                self.amplification
            ),
            TumbleRule::Sync => format!(
                "the target turns at up to {peak:.4} rad/s, faster than the {:.4} rad/s the base can hold within its rate limits (safety.attitude.omega_max_rad_s/omega_min_rad_s less the rate rows' margins), so the rate synchronisation cannot be certified; the tumble may be at most {:.4} rad/s",
                self.sync_limit_rad_s,
                self.max_spin_rad_s()
            ),
            TumbleRule::AcrossAxis => format!(
                "the rate synchronisation would turn the boresight at up to {:.4} rad/s (the tumble's part across the corridor axis), faster than the {:.4} rad/s it may turn (safety.attitude.boresight_rate_max_rad_s less its margins); the tumble may be at most {:.4} rad/s",
                peak * self.spin_across_axis,
                self.boresight_follow_rad_s,
                self.max_spin_rad_s()
            ),
            TumbleRule::LineOfSight => format!(
                "the grasping point moves at up to {:.4} m/s and the servicer may come to {:.3} m of it, so the tumble turns the line of sight at up to {:.4} rad/s, more than the {:.4} rad/s left for it (the boresight follows at {:.4} rad/s, the translational filter's contract takes {:.4}); this geometry allows a tumble of at most {:.4} rad/s",
                self.grasp_speed_m_s(),
                self.los_min_m,
                self.target_rate_rad_s(),
                self.limit_rad_s(),
                self.boresight_follow_rad_s,
                self.translational_rad_s,
                self.max_spin_rad_s()
            ),
            TumbleRule::Unknown => "the target's rate is not known (a non-finite estimate)".into(),
            TumbleRule::Geometry => format!(
                "the grasping point's geometry leaves no certified line of sight (least length {:.3} m, the contract's least σ {:.3})",
                self.los_min_m, self.contract_sigma_min
            ),
        }
    }
}

/// A rule of the certified envelope broken: `rule` after the envelope's reference.
fn outside(key: &str, value: impl std::fmt::Debug, rule: String) -> ScenarioError {
    crate::validate::invalid(
        key,
        value,
        format!(
            "outside the certified envelope (docs/SAFETY.md, \"The certified envelope\"): {rule}"
        ),
    )
}

fn dot(a: &V3, b: &V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: &V3) -> f64 {
    dot(a, a).sqrt()
}

fn scale(a: &V3, k: f64) -> V3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

fn sub(a: &V3, b: &V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn normalize(a: &V3) -> V3 {
    scale(a, 1.0 / norm(a))
}

fn mat_vec(m: &[V3; 3], v: &V3) -> V3 {
    [dot(&m[0], v), dot(&m[1], v), dot(&m[2], v)]
}

/// `v` rotated by the unit quaternion `q` (scalar-first): `q ⊗ v ⊗ q*`.
fn rotate(q: &[f64; 4], v: &V3) -> V3 {
    let (w, u) = (q[0], [q[1], q[2], q[3]]);
    let t = scale(&cross(&u, v), 2.0);
    let wt = scale(&t, w);
    let ut = cross(&u, &t);
    [
        v[0] + wt[0] + ut[0],
        v[1] + wt[1] + ut[1],
        v[2] + wt[2] + ut[2],
    ]
}

/// The least and the largest eigenvalue of a symmetric 3×3 matrix (the trigonometric
/// closed form; NaN for a non-finite matrix).
fn symmetric_eigen_range(a: &[V3; 3]) -> (f64, f64) {
    if !a.iter().flatten().all(|v| v.is_finite()) {
        return (f64::NAN, f64::NAN);
    }
    let p1 = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
    let diag = [a[0][0], a[1][1], a[2][2]];
    if p1 == 0.0 {
        let lo = diag.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = diag.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        return (lo, hi);
    }
    let q = (diag[0] + diag[1] + diag[2]) / 3.0;
    let p2 = diag.iter().map(|d| (d - q).powi(2)).sum::<f64>() + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b = |i: usize, j: usize| (a[i][j] - if i == j { q } else { 0.0 }) / p;
    let det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1))
        - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
        + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    let hi = q + 2.0 * p * phi.cos();
    let lo = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    (lo, hi)
}
