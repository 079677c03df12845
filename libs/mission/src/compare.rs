//! How far two runs of the same mission part, step by step: e.g. Basilisk as the plant
//! against our simulator (`safe-capture compare`, docs/SIMULATOR.md).

use crate::StepRecord;
use sc_models::quat::{self, Quat};
use serde::Serialize;

/// The differences at one control step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepDifference {
    pub t: f64,
    /// ‖Δ r_H‖: the servicer's base origin in the Hill frame [m].
    pub hill_position_m: f64,
    /// Angle of the rotation between the two base attitudes `q_RB` [rad].
    pub attitude_rad: f64,
    /// max_i |Δθ_i| [rad].
    pub joint_angle_rad: f64,
    /// Angle between the two target attitudes `q_RT` [rad].
    pub target_attitude_rad: f64,
}

/// The largest differences up to a time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LargestDifference {
    /// Up to this time [s] (the last compared step's time when the window is longer).
    pub until_s: f64,
    pub steps: usize,
    pub hill_position_m: f64,
    pub attitude_rad: f64,
    pub joint_angle_rad: f64,
    pub target_attitude_rad: f64,
}

/// Angle of the rotation between two unit quaternions [rad], accurate when small
/// (from the vector part of `p⁻¹ r`, not from its scalar part).
pub fn rotation_angle(p: &Quat, r: &Quat) -> f64 {
    let d = quat::mul(&quat::conj(p), r);
    2.0 * (d[1] * d[1] + d[2] * d[2] + d[3] * d[3])
        .sqrt()
        .atan2(d[0].abs())
}

/// Two runs that cannot be compared step by step.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CompareError {
    /// The runs' control steps are at different times.
    #[error("step {step}: times differ ({a} s and {b} s)")]
    TimesDiffer { step: u64, a: f64, b: f64 },
}

/// The differences at every control step both runs have (paired by step index); an
/// error when the runs' times differ at a step.
pub fn differences(
    a: &[StepRecord],
    b: &[StepRecord],
) -> Result<Vec<StepDifference>, CompareError> {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            if x.t != y.t {
                return Err(CompareError::TimesDiffer {
                    step: x.step,
                    a: x.t,
                    b: y.t,
                });
            }
            let (o, p) = (&x.obs, &y.obs);
            Ok(StepDifference {
                t: x.t,
                hill_position_m: (o.r_h - p.r_h).norm(),
                attitude_rad: rotation_angle(&o.q_rb, &p.q_rb),
                joint_angle_rad: (o.theta - p.theta).amax(),
                target_attitude_rad: rotation_angle(&o.q_rt, &p.q_rt),
            })
        })
        .collect()
}

/// The largest of `d` up to time `until` [s].
pub fn largest(d: &[StepDifference], until: f64) -> LargestDifference {
    let w: Vec<&StepDifference> = d.iter().take_while(|x| x.t <= until).collect();
    let max = |f: fn(&StepDifference) -> f64| w.iter().map(|x| f(x)).fold(0.0, f64::max);
    LargestDifference {
        until_s: w.last().map_or(0.0, |x| x.t),
        steps: w.len(),
        hill_position_m: max(|x| x.hill_position_m),
        attitude_rad: max(|x| x.attitude_rad),
        joint_angle_rad: max(|x| x.joint_angle_rad),
        target_attitude_rad: max(|x| x.target_attitude_rad),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_rotations_are_measured_without_cancellation() {
        let a = 1e-12_f64;
        let q = [(a / 2.0).cos(), (a / 2.0).sin(), 0.0, 0.0];
        let got = rotation_angle(&quat::IDENTITY, &q);
        assert!((got - a).abs() < 1e-24, "{got}");
        // the other sign of the same rotation
        let neg = q.map(|x| -x);
        assert!((rotation_angle(&quat::IDENTITY, &neg) - a).abs() < 1e-24);
        assert_eq!(rotation_angle(&q, &q), 0.0);
    }
}
