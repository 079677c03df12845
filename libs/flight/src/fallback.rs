//! The backup command of each filter, as the partition applies it when a safe command (or
//! a filter's input) is missing: the filter's own safety QP on its substitute nominal (the
//! braking law), flagged `UPSTREAM_MISSING` — exactly what the filter itself computes for a
//! missing nominal. Never an unfiltered command.

use nalgebra::Vector3;
use sc_cbf::{AttitudeOutput, RoboticOutput, SafetyLayer, TranslationalOutput, faults};
use sc_mission::stages;
use sc_multibody::Robot;
use sc_sim::Observation;

/// Translational backup, `u = f_H`, `actuated = f_B`.
pub fn translational(layer: &mut SafetyLayer, o: &Observation) -> TranslationalOutput {
    flag_missing(layer.translational.backup(&stages::translational_input(o)))
}

/// Attitude backup given the safe force `f_b` acting.
pub fn attitude(
    layer: &mut SafetyLayer,
    o: &Observation,
    robot: &Robot,
    f_b: &Vector3<f64>,
) -> AttitudeOutput {
    flag_missing(
        layer
            .attitude
            .backup(&stages::attitude_input(o, robot, f_b)),
    )
}

/// Robotic backup given the safe base force and torque.
pub fn robotic(
    layer: &mut SafetyLayer,
    o: &Observation,
    robot: &Robot,
    f_b: &Vector3<f64>,
    tau_b: &Vector3<f64>,
) -> RoboticOutput {
    flag_missing(stages::robotic_step(
        &mut layer.robotic,
        o,
        robot,
        f_b,
        tau_b,
        None,
    ))
}

/// Marks an output computed with a missing input.
pub fn flag_missing<const M: usize, const N: usize>(
    mut out: sc_cbf::FilterOutput<M, N>,
) -> sc_cbf::FilterOutput<M, N> {
    out.report.faults |= faults::UPSTREAM_MISSING;
    out
}
