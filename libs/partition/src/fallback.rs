//! The defined fallback of each filter, as the partition applies it when a safe
//! command (or a filter's input) is missing: the filter's own bounded backup law,
//! flagged `UPSTREAM_MISSING`. Never the unfiltered nominal command.

use nalgebra::Vector3;
use sc_cbf::{
    AttitudeOutput, FilterOutput, FilterReport, RoboticOutput, SafetyLayer, TranslationalOutput,
    faults,
};
use sc_mission::stages;
use sc_multibody::Robot;
use sc_sim::Observation;

fn report<const N: usize>() -> FilterReport<N> {
    let mut r = FilterReport::<N>::default();
    r.faults |= faults::UPSTREAM_MISSING;
    r
}

/// Translational fallback (brake relative motion), `u = f_H`, `actuated = f_B`.
pub fn translational(layer: &SafetyLayer, o: &Observation) -> TranslationalOutput {
    let (u, actuated) = layer
        .translational
        .fallback(&stages::translational_input(o));
    FilterOutput {
        u,
        actuated,
        report: report(),
    }
}

/// Attitude fallback (brake the body rate) given the safe force `f_b` acting.
pub fn attitude(
    layer: &SafetyLayer,
    o: &Observation,
    robot: &Robot,
    f_b: &Vector3<f64>,
) -> AttitudeOutput {
    let u = layer
        .attitude
        .fallback(&stages::attitude_input(o, robot, f_b));
    FilterOutput {
        u,
        actuated: u,
        report: report(),
    }
}

/// Robotic fallback (brake the joints) given the safe base force and torque.
pub fn robotic(
    layer: &SafetyLayer,
    o: &Observation,
    robot: &Robot,
    f_b: &Vector3<f64>,
    tau_b: &Vector3<f64>,
) -> RoboticOutput {
    match stages::robotic_input(o, robot, f_b, tau_b) {
        Some(x) => {
            let u = layer.robotic.fallback(&x);
            FilterOutput {
                u,
                actuated: u,
                report: report(),
            }
        }
        None => {
            let mut r = stages::robotic_invalid_state();
            r.report.faults |= faults::UPSTREAM_MISSING;
            r
        }
    }
}

/// Marks an output computed with a missing input.
pub fn flag_missing<const M: usize, const N: usize>(
    mut out: FilterOutput<M, N>,
) -> FilterOutput<M, N> {
    out.report.faults |= faults::UPSTREAM_MISSING;
    out
}
