//! MCAP output of the recorder: one channel per service, JSON-encoded messages with
//! a JSON schema each (Foxglove plots every numeric field).

use anyhow::Context;
use serde_json::{Map, Value, json};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// A message field as JSON, written straight into the output buffer (no
/// intermediate `serde_json::Value`: the recorder writes every message of a run).
pub trait JsonField {
    fn write_json(&self, out: &mut Vec<u8>);
    fn schema() -> Value;
}
impl JsonField for u64 {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(&mut *out, self);
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for u32 {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(&mut *out, self);
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for f64 {
    // NaN/inf are not JSON numbers: written as null
    fn write_json(&self, out: &mut Vec<u8>) {
        if self.is_finite() {
            // serde_json's shortest round-trip formatting of a finite f64
            let _ = serde_json::to_writer(&mut *out, self);
        } else {
            out.extend_from_slice(b"null");
        }
    }
    fn schema() -> Value {
        json!({"type": ["number", "null"]})
    }
}
impl<const N: usize> JsonField for [f64; N] {
    fn write_json(&self, out: &mut Vec<u8>) {
        out.push(b'[');
        for (i, x) in self.iter().enumerate() {
            if i > 0 {
                out.push(b',');
            }
            x.write_json(out);
        }
        out.push(b']');
    }
    fn schema() -> Value {
        json!({"type": "array", "items": {"type": ["number", "null"]}, "minItems": N, "maxItems": N})
    }
}

/// An ICD message as a JSON object, with its JSON schema.
pub trait JsonMsg {
    /// Writes the message as one JSON object (fields in declaration order) to `out`.
    fn write_json(&self, out: &mut Vec<u8>);
    fn json_schema() -> Value;
    fn name() -> &'static str;
}

macro_rules! json_msg {
    ($t:ident { $($f:ident : $d:expr $(=> $items:expr)?),+ $(,)? }) => {
        impl JsonMsg for sc_icd::$t {
            fn write_json(&self, out: &mut Vec<u8>) {
                let mut sep = b'{';
                $(
                    out.push(sep);
                    sep = b',';
                    out.extend_from_slice(concat!("\"", stringify!($f), "\":").as_bytes());
                    JsonField::write_json(&self.$f, out);
                )+
                let _ = sep;
                out.push(b'}');
            }
            fn json_schema() -> Value {
                let mut p = Map::new();
                $(
                    #[allow(unused_mut, unused_assignments)]
                    let mut items: Option<String> = None;
                    $( items = Some(String::from($items)); )?
                    p.insert(
                        stringify!($f).into(),
                        described(field_schema(&|s: &sc_icd::$t| s.$f), $d, items),
                    );
                )+
                json!({
                    "title": sc_icd::type_name_of::<sc_icd::$t>(),
                    "description": $crate::mcap_out::message_doc(stringify!($t)),
                    "type": "object",
                    "properties": Value::Object(p),
                })
            }
            fn name() -> &'static str { sc_icd::type_name_of::<sc_icd::$t>() }
        }
    };
}

fn field_schema<T, F: JsonField>(_: &dyn Fn(&T) -> F) -> Value {
    F::schema()
}

/// `schema` with its `description` (and, for an array, its items' description).
fn described(mut schema: Value, description: &str, items: Option<String>) -> Value {
    schema["description"] = description.into();
    if let (Some(d), Some(it)) = (items, schema.get_mut("items")) {
        it["description"] = d.into();
    }
    schema
}

/// One line on what each message is (the doc comments of `sc_icd`).
pub fn message_doc(name: &str) -> &'static str {
    match name {
        "Tick" => {
            "Scheduler → simulator, every other process (stop), recorder: start one control step"
        }
        "SimState" => {
            "Simulator → nominal controllers, safety filters, recorder: the observation at the start of the step"
        }
        "NominalTranslational" => {
            "Nominal translational controller → translational safety filter, recorder"
        }
        "NominalAttitude" => "Nominal attitude controller → attitude safety filter, recorder",
        "NominalRobotic" => "Nominal robotic controller → robotic safety filter, recorder",
        "SafeTranslational" => {
            "Translational safety filter → attitude and robotic filters, simulator, recorder (constraints: AC, CAZ)"
        }
        "SafeAttitude" => {
            "Attitude safety filter → robotic filter, simulator, recorder (constraints: ATT, ω1..3 upper, ω1..3 lower)"
        }
        "SafeRobotic" => {
            "Robotic safety filter → simulator, recorder (constraints: θ limits, θ̇ upper, θ̇ lower, link-base)"
        }
        "StepResult" => {
            "Simulator → scheduler, recorder: the command applied over the step and how the step ended"
        }
        _ => "",
    }
}

/// The unit of a barrier `h` by its name (`sc_mission::constraint_names()`), as the
/// filters and the simulator's monitor compute it: the corridor `d·r − ‖r‖ cos ψ` [m],
/// the zone `‖r‖² − R²` [m²], the line of sight `d_B·ρ̂ − cos β` [-], the rate limits
/// [rad/s], the joint-angle limits `(θ − θ_min)(θ_max − θ)` [rad²], the link–base
/// spheres `‖d‖² − (ρ_i + ρ_B)²` [m²]. `None` for a name it does not know.
pub fn barrier_unit(name: &str) -> Option<&'static str> {
    Some(match name {
        "approach_corridor" => "m",
        "collision_avoidance_zone" => "m²",
        "line_of_sight" => "-",
        n if n.starts_with("omega_") || n.starts_with("theta_dot_") => "rad/s",
        n if n.starts_with("theta_") => "rad²",
        n if n.starts_with("link_base_") => "m²",
        _ => return None,
    })
}

/// "index name [unit]" of every barrier in `names`, for an array's items.
fn barrier_items(names: &[&str]) -> String {
    let list: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} {n} [{}]", barrier_unit(n).unwrap_or("?")))
        .collect();
    format!("by index: {}", list.join(", "))
}

/// The same as [`barrier_items`] for Φ_i, in units of h per second.
fn phi_items(names: &[&str]) -> String {
    let list: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} {n} [{}/s]", barrier_unit(n).unwrap_or("?")))
        .collect();
    format!("by index: {}", list.join(", "))
}

fn all_barrier_items() -> String {
    barrier_items(&sc_mission::constraint_names())
}

const D_TICK: &str = "tick index this message answers (+1 per tick of the fastest rate group) [-]";
const D_PUBLISH_NS: &str = "publish stamp, host CLOCK_MONOTONIC [ns]";
const JOINTS: &str = "joints 1..7 in order";
const XYZ: &str = "x, y, z";
const QUAT: &str = "w, x, y, z (scalar first)";

json_msg!(Tick {
    tick: D_TICK,
    due_mask: "subsystems due in this tick, bits 1 translational, 2 attitude, 4 robotic [-]",
    clock_mode: "clock mode: 0 lock-step, 1 real time, 2 scaled real time [-]",
    t: "simulation time at which this step starts [s]",
    send_ns: "scheduler send stamp, host CLOCK_MONOTONIC [ns]",
    command: "0 step, 1 stop (the run is over) [-]",
});
json_msg!(SimState {
    tick: D_TICK,
    t: "simulation time [s]",
    due_mask: "subsystems due in this tick, bits 1 translational, 2 attitude, 4 robotic [-]",
    tick_send_ns: "send stamp of the tick this state answers, host CLOCK_MONOTONIC [ns]",
    recv_ns: "stamp at which the simulator received the tick, host CLOCK_MONOTONIC [ns]",
    publish_ns: D_PUBLISH_NS,
    step: "simulator step counter [-]",
    r_h: "servicer base origin relative to the target CoM r_H, Hill frame F_H [m]" => XYZ,
    v_h: "derivative of r_H in the rotating Hill frame F_H [m/s]" => XYZ,
    r_r: "servicer base origin relative to the target CoM r_R, reference frame F_R [m]" => XYZ,
    v_r: "inertial derivative of r_R, in F_R [m/s]" => XYZ,
    q_hr: "attitude q_HR of F_R in F_H, rotates F_R vectors into F_H [-]" => QUAT,
    omega_h: "angular velocity ω_H of F_H w.r.t. inertial, in F_H [rad/s]" => XYZ,
    omega_dot_h: "angular acceleration of F_H w.r.t. inertial, in F_H [rad/s²]" => XYZ,
    mean_motion: "mean motion of the target orbit |ω_H| [rad/s]",
    q_rb: "servicer attitude q_RB, rotates F_B vectors into F_R [-]" => QUAT,
    omega_b: "servicer body rate ω_B w.r.t. inertial, in F_B [rad/s]" => XYZ,
    theta: "joint angles θ [rad]" => JOINTS,
    theta_dot: "joint rates θ̇ [rad/s]" => JOINTS,
    q_rt: "target attitude q_RT, rotates F_T vectors into F_R [-]" => QUAT,
    omega_t: "target body rate ω_T w.r.t. inertial, in F_T [rad/s]" => XYZ,
    omega_dot_t: "derivative of ω_T, in F_T [rad/s²]" => XYZ,
    grasp_r: "grasping point relative to the target CoM, F_R [m]" => XYZ,
    grasp_v_r: "grasping point inertial velocity, F_R [m/s]" => XYZ,
    grasp_a_r: "grasping point inertial acceleration, F_R [m/s²]" => XYZ,
    grasp_b: "grasping point relative to the base origin, F_B [m]" => XYZ,
    ee_b: "end-effector position relative to the base origin, F_B [m]" => XYZ,
    ee_r: "end-effector position relative to the target CoM, F_R [m]" => XYZ,
    ee_v_r: "end-effector inertial velocity, F_R [m/s]" => XYZ,
    com_h: "servicer system centre of mass relative to the target CoM, Hill frame F_H [m]" => XYZ,
    com_v_h: "derivative of com_h in the rotating Hill frame F_H [m/s]" => XYZ,
    com_r: "servicer system centre of mass relative to the target CoM, F_R [m]" => XYZ,
    com_v_r: "inertial velocity of the servicer system centre of mass, F_R [m/s]" => XYZ,
    barriers: "every barrier h at this state from the simulator's own state (safety monitor), telemetry order; null = not evaluated [unit per barrier, see items]" => all_barrier_items(),
    barriers_between: "smallest value of every barrier over the physics steps since the previous state (this one included) [unit per barrier, see items]" => all_barrier_items(),
});

macro_rules! nominal_json {
    ($t:ident, $cmd:ident, $d:expr, $items:expr) => {
        json_msg!($t {
            tick: D_TICK,
            t: "simulation time of the state used [s]",
            valid: "1 if the controller ran on valid inputs, 0 otherwise [-]",
            phase: "index of the mission phase (0-based, scenario order) [-]",
            recv_ns: "stamp at which the state was received, host CLOCK_MONOTONIC [ns]",
            publish_ns: D_PUBLISH_NS,
            $cmd: $d => $items,
        });
    };
}
nominal_json!(
    NominalTranslational,
    f_h,
    "nominal force f_H, Hill frame F_H, unsaturated [N]",
    XYZ
);
nominal_json!(
    NominalAttitude,
    tau_b,
    "nominal torque τ_B, base frame F_B, unsaturated [N·m]",
    XYZ
);
nominal_json!(
    NominalRobotic,
    tau_m,
    "nominal joint torques τ_M, unsaturated [N·m]",
    JOINTS
);

macro_rules! safe_json {
    ($t:ident, $names:expr, $u:expr, $actuated:expr, $items:expr) => {
        json_msg!($t {
            tick: D_TICK,
            t: "simulation time of the state used [s]",
            recv_ns: "stamp at which the last input of this tick arrived, host CLOCK_MONOTONIC [ns]",
            publish_ns: D_PUBLISH_NS,
            active_mask: "bit i set = constraint i active (Φ_i ≈ 0) [-]",
            solve_ns: "wall time of the filter call [ns]",
            solve_cpu_ns: "CPU time of the filter call on its thread, saturating at u32::MAX [ns]",
            solver_status: "sc_cbf::FilterStatus: 0 skipped, 1 solved, 2 relaxed, 3 fallback [-]",
            iterations: "QP solver iterations [-]",
            fault_flags: "sc_cbf::faults bits (5 upstream_missing, 7 nominal_missing, docs/ICD.md) [-]",
            n_constraints: "number of constraints in h and phi [-]",
            phase: "mission phase of the nominal command filtered (0-based) [-]",
            slack: "slack of the relaxed QP (0 otherwise), normalised rows [-]",
            h: "barrier values h_i the filter evaluated; null = not evaluated [unit per constraint, see items]" => barrier_items(&$names),
            phi: "CBF conditions Φ_i at the safe command [units of h per s, see items]" => phi_items(&$names),
            u: $u => $items,
            actuated: $actuated => $items,
        });
    };
}
safe_json!(
    SafeTranslational,
    sc_cbf::names::TRANSLATIONAL,
    "safe force f_H, Hill frame F_H [N]",
    "safe force f_B = R_BH f_H, base frame F_B (what the thrusters apply) [N]",
    XYZ
);
safe_json!(
    SafeAttitude,
    sc_cbf::names::ATTITUDE,
    "safe torque τ_B, base frame F_B [N·m]",
    "actuated torque τ_B, base frame F_B (equals u) [N·m]",
    XYZ
);
safe_json!(
    SafeRobotic,
    sc_cbf::names::ROBOTIC,
    "safe joint torques τ_M [N·m]",
    "actuated joint torques τ_M (equals u) [N·m]",
    JOINTS
);
json_msg!(StepResult {
    tick: D_TICK,
    t: "simulation time at the start of the step [s]",
    end: "0 running, 1 captured, 2 timeout, 3 simulator failed [-]",
    fallback_mask: "subsystems (due bits 1 translational, 2 attitude, 4 robotic) whose command is the filter fallback computed by the simulator [-]",
    held_mask: "subsystems (due bits) whose command was held from an earlier tick (slower rate group) [-]",
    fault_flags: "partition fault flags, bits of sc_icd::fault (6 deadline miss, 8 rejected command) [-]",
    safe_recv_ns: "stamp at which the robotic safe command (the tick's last) was delivered, host CLOCK_MONOTONIC [ns]",
    publish_ns: D_PUBLISH_NS,
    force_b: "applied base force f_B, F_B [N]" => XYZ,
    torque_b: "applied base torque τ_B, F_B [N·m]" => XYZ,
    tau: "applied joint torques τ_M [N·m]" => JOINTS,
});

/// Topic of the frame transforms (Foxglove's 3D panel reads `foxglove.FrameTransform`).
pub const TF_TOPIC: &str = "/tf";
/// Frame id of the reference frame F_R (origin at the target's centre of mass).
pub const FRAME_REFERENCE: &str = "reference";
/// Frame id of the servicer body frame F_B (origin at the base origin).
pub const FRAME_SERVICER: &str = "servicer_body";
/// Frame id of the target body frame F_T (origin at the target's centre of mass).
pub const FRAME_TARGET: &str = "target_body";
/// Frame id of the end effector (its position only: see [`FrameTransform`]).
pub const FRAME_END_EFFECTOR: &str = "end_effector";
/// Frame id of the servicer system's centre of mass with the body's orientation: the
/// point the corridor, the zone and the line of sight constrain (`sc_cbf::monitor`).
pub const FRAME_SERVICER_COM: &str = "servicer_com";
/// Nanoseconds per second, for Foxglove's `{sec, nsec}` timestamps.
const NS_PER_S: u64 = 1_000_000_000;

/// One `foxglove.FrameTransform`: the pose of `child` in `parent`. `rotation` is
/// Foxglove's `[x, y, z, w]`, rotating child-frame vectors into the parent frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTransform {
    /// Mission time [ns].
    pub log_ns: u64,
    pub parent: &'static str,
    pub child: &'static str,
    /// Child origin in the parent frame [m].
    pub translation: [f64; 3],
    /// Unit quaternion `[x, y, z, w]` [-].
    pub rotation: [f64; 4],
}

/// A project quaternion q_AB (scalar first, rotates F_B vectors into F_A) as
/// Foxglove's rotation of child B in parent A: the same rotation, scalar last.
pub fn foxglove_rotation(q_ab: [f64; 4]) -> [f64; 4] {
    [q_ab[1], q_ab[2], q_ab[3], q_ab[0]]
}

impl FrameTransform {
    /// The frames a state message carries: reference → servicer body (`r_r`, `q_rb`),
    /// reference → target body (the target's centre of mass is F_R's origin; `q_rt`) and
    /// servicer body → end effector (`ee_b`; the state carries no end-effector
    /// attitude, so this frame keeps the body's orientation) and reference → servicer
    /// centre of mass (`com_r`, `q_rb`: the apex of the line of sight).
    pub fn of_state(s: &sc_icd::SimState, log_ns: u64) -> [Self; 4] {
        const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];
        [
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_SERVICER,
                translation: s.r_r,
                rotation: foxglove_rotation(s.q_rb),
            },
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_TARGET,
                translation: [0.0; 3],
                rotation: foxglove_rotation(s.q_rt),
            },
            Self {
                log_ns,
                parent: FRAME_SERVICER,
                child: FRAME_END_EFFECTOR,
                translation: s.ee_b,
                rotation: IDENTITY,
            },
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_SERVICER_COM,
                translation: s.com_r,
                rotation: foxglove_rotation(s.q_rb),
            },
        ]
    }
}

impl JsonMsg for FrameTransform {
    fn write_json(&self, out: &mut Vec<u8>) {
        let [x, y, z] = self.translation;
        let [qx, qy, qz, qw] = self.rotation;
        let _ = serde_json::to_writer(
            &mut *out,
            &json!({
                "timestamp": {"sec": self.log_ns / NS_PER_S, "nsec": self.log_ns % NS_PER_S},
                "parent_frame_id": self.parent,
                "child_frame_id": self.child,
                "translation": {"x": x, "y": y, "z": z},
                "rotation": {"x": qx, "y": qy, "z": qz, "w": qw},
            }),
        );
    }
    /// Foxglove's `foxglove.FrameTransform` JSON schema (docs.foxglove.dev).
    fn json_schema() -> Value {
        let num = |d: &str| json!({"type": "number", "description": d});
        let int = |d: &str| json!({"type": "integer", "minimum": 0, "description": d});
        let string = |d: &str| json!({"type": "string", "description": d});
        json!({
            "title": "foxglove.FrameTransform",
            "description": "A transform between two reference frames in 3D space",
            "type": "object",
            "properties": {
                "timestamp": {
                    "type": "object",
                    "title": "time",
                    "description": "Timestamp of transform (mission time)",
                    "properties": {"sec": int("seconds [s]"), "nsec": int("nanoseconds [ns]")}
                },
                "parent_frame_id": string("Name of the parent frame"),
                "child_frame_id": string("Name of the child frame"),
                "translation": {
                    "type": "object",
                    "title": "foxglove.Vector3",
                    "description": "Translation component of the transform [m]",
                    "properties": {"x": num("x [m]"), "y": num("y [m]"), "z": num("z [m]")}
                },
                "rotation": {
                    "type": "object",
                    "title": "foxglove.Quaternion",
                    "description": "Rotation component of the transform (rotates child-frame vectors into the parent frame)",
                    "properties": {"x": num("x [-]"), "y": num("y [-]"), "z": num("z [-]"), "w": num("w [-]")}
                }
            }
        })
    }
    fn name() -> &'static str {
        "foxglove.FrameTransform"
    }
}

/// Topic of the 3D scene's entities (`foxglove.SceneUpdate`).
pub const SCENE_TOPIC: &str = "/scene";
/// Entity id of the approach-corridor cone.
pub const ENTITY_CORRIDOR: &str = "approach_corridor";
/// Entity id of the collision-avoidance-zone sphere.
pub const ENTITY_ZONE: &str = "collision_avoidance_zone";
/// Entity id of the line-of-sight cone.
pub const ENTITY_LINE_OF_SIGHT: &str = "line_of_sight";
/// Entity id of the grasping point (a sphere of the capture tolerance).
pub const ENTITY_GRASP: &str = "grasp_point";

/// An RGBA colour, each component in [0, 1] (Foxglove's `foxglove.Color`).
type Rgba = [f64; 4];
/// Display colours of the scene (translucent, so the frames stay visible inside).
const COLOR_CORRIDOR: Rgba = [0.2, 0.6, 1.0, 0.25];
const COLOR_ZONE: Rgba = [1.0, 0.3, 0.2, 0.25];
const COLOR_LINE_OF_SIGHT: Rgba = [1.0, 0.85, 0.1, 0.25];
const COLOR_GRASP: Rgba = [0.2, 0.9, 0.3, 0.8];
const COLOR_LABEL: Rgba = [1.0, 1.0, 1.0, 1.0];
/// Label height on screen [px] (Foxglove's `scale_invariant` text).
const LABEL_FONT_PX: f64 = 14.0;

/// A cone with its apex at the origin of its frame, around the unit `axis`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cone {
    /// Unit axis from the apex into the cone, in the entity's frame [-].
    pub axis: [f64; 3],
    /// Half angle [rad].
    pub half_angle_rad: f64,
    /// Length along the axis [m].
    pub length_m: f64,
}

impl Cone {
    /// Foxglove's `CylinderPrimitive` of the cone: a cylinder whose local z is the
    /// axis, centred half a length along it, its bottom face (the apex) scaled to 0.
    fn cylinder(&self, color: Rgba) -> Value {
        let d = unit(self.axis);
        let l = self.length_m;
        let diameter = 2.0 * l * self.half_angle_rad.tan();
        json!({
            "pose": pose([d[0] * l / 2.0, d[1] * l / 2.0, d[2] * l / 2.0], z_onto(d)),
            "size": {"x": diameter, "y": diameter, "z": l},
            "bottom_scale": 0.0,
            "top_scale": 1.0,
            "color": color_json(color),
        })
    }
}

/// `v / ‖v‖`; `v` itself when it has no finite positive length (never NaN from here).
fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n.is_finite() && n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        v
    }
}

/// The rotation `[x, y, z, w]` that turns the local z axis onto the unit vector `d`
/// (the half-way quaternion; a half turn about x when `d` is −z).
fn z_onto(d: [f64; 3]) -> [f64; 4] {
    // q = (1 + z·d, z × d) normalised, z = (0, 0, 1): z × d = (−d_y, d_x, 0)
    let w = 1.0 + d[2];
    let (x, y) = (-d[1], d[0]);
    let n = (w * w + x * x + y * y).sqrt();
    if n > f64::EPSILON * 4.0 && n.is_finite() {
        [x / n, y / n, 0.0, w / n]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

fn pose(position: [f64; 3], orientation: [f64; 4]) -> Value {
    json!({
        "position": {"x": position[0], "y": position[1], "z": position[2]},
        "orientation": {"x": orientation[0], "y": orientation[1], "z": orientation[2], "w": orientation[3]},
    })
}

fn color_json(c: Rgba) -> Value {
    json!({"r": c[0], "g": c[1], "b": c[2], "a": c[3]})
}

fn stamp(ns: u64) -> Value {
    json!({"sec": ns / NS_PER_S, "nsec": ns % NS_PER_S})
}

/// The scenario's safety geometry as the 3D panel shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneGeometry {
    /// Approach corridor: apex at the target's CoM (F_R's origin), axis d_R fixed in
    /// F_R, half angle ψ_AC (`safety.translational`).
    pub corridor: Cone,
    /// Collision-avoidance zone R_CAZ about the target's CoM [m].
    pub zone_radius_m: f64,
    /// Line of sight: apex at the servicer's centre of mass, axis the boresight d_B
    /// (F_B), half angle β_ATT (`safety.attitude`).
    pub line_of_sight: Cone,
    /// Grasping point in F_T [m] (`target.grasp_point_m`).
    pub grasp_t: [f64; 3],
    /// Capture tolerance: the radius of the grasping point's sphere [m].
    pub capture_tolerance_m: f64,
}

impl SceneGeometry {
    /// From the scenario. Both cones reach the servicer's initial range ‖p_0‖ (at least
    /// the zone's radius), so that the corridor contains the start of the approach
    /// and the line of sight reaches the target from it.
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let tr = &s.safety.translational;
        let p0 = s.servicer.initial_position_m;
        let range = (p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]).sqrt();
        let range = if range.is_finite() {
            range.max(tr.caz_radius_m)
        } else {
            tr.caz_radius_m
        };
        Self {
            corridor: Cone {
                axis: unit(tr.corridor_axis),
                half_angle_rad: tr.corridor_half_angle_deg.to_radians(),
                length_m: range,
            },
            zone_radius_m: tr.caz_radius_m,
            line_of_sight: Cone {
                axis: unit(s.servicer.boresight_body),
                half_angle_rad: s.safety.attitude.los_half_angle_deg.to_radians(),
                length_m: range,
            },
            grasp_t: s.target.grasp_point_m,
            capture_tolerance_m: s.mission.capture_tolerance_m,
        }
    }
}

/// One `foxglove.SceneUpdate`: every entity of [`SceneGeometry`], with lifetime 0 (kept
/// until replaced) and `frame_locked` (each follows its frame on `/tf`).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneUpdate {
    /// Mission time [ns].
    pub log_ns: u64,
    pub geometry: SceneGeometry,
    /// The mission phase it was written for (entity metadata).
    pub phase: String,
}

impl SceneUpdate {
    fn entity(&self, frame: &str, id: &str, meta: &[(&str, String)], prims: Value) -> Value {
        let mut e = json!({
            "timestamp": stamp(self.log_ns),
            "frame_id": frame,
            "id": id,
            "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": true,
            "metadata": meta.iter().chain([("phase", self.phase.clone())].iter())
                .map(|(k, v)| json!({"key": k, "value": v})).collect::<Vec<_>>(),
            "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
            "lines": [], "triangles": [], "texts": [], "models": [],
        });
        if let (Some(e), Value::Object(p)) = (e.as_object_mut(), prims) {
            e.extend(p);
        }
        e
    }

    fn label(at: [f64; 3], text: String) -> Value {
        json!({
            "pose": pose(at, [0.0, 0.0, 0.0, 1.0]),
            "billboard": true,
            "font_size": LABEL_FONT_PX,
            "scale_invariant": true,
            "color": color_json(COLOR_LABEL),
            "text": text,
        })
    }

    /// The entities, as JSON.
    pub fn entities(&self) -> Vec<Value> {
        let g = &self.geometry;
        let deg = |r: f64| format!("{:.2}", r.to_degrees());
        let tip = |c: &Cone| {
            let d = unit(c.axis);
            [d[0] * c.length_m, d[1] * c.length_m, d[2] * c.length_m]
        };
        let sphere = |at: [f64; 3], r: f64, color: Rgba| {
            json!({"pose": pose(at, [0.0, 0.0, 0.0, 1.0]),
                   "size": {"x": 2.0 * r, "y": 2.0 * r, "z": 2.0 * r},
                   "color": color_json(color)})
        };
        vec![
            self.entity(
                FRAME_REFERENCE,
                ENTITY_CORRIDOR,
                &[
                    ("half_angle_deg", deg(g.corridor.half_angle_rad)),
                    ("length_m", g.corridor.length_m.to_string()),
                ],
                json!({
                    "cylinders": [g.corridor.cylinder(COLOR_CORRIDOR)],
                    "texts": [Self::label(tip(&g.corridor), format!("approach corridor ψ_AC = {}°", deg(g.corridor.half_angle_rad)))],
                }),
            ),
            self.entity(
                FRAME_REFERENCE,
                ENTITY_ZONE,
                &[("radius_m", g.zone_radius_m.to_string())],
                json!({
                    "spheres": [sphere([0.0; 3], g.zone_radius_m, COLOR_ZONE)],
                    "texts": [Self::label([0.0, 0.0, g.zone_radius_m], format!("collision-avoidance zone R = {} m", g.zone_radius_m))],
                }),
            ),
            self.entity(
                FRAME_SERVICER_COM,
                ENTITY_LINE_OF_SIGHT,
                &[
                    ("half_angle_deg", deg(g.line_of_sight.half_angle_rad)),
                    ("length_m", g.line_of_sight.length_m.to_string()),
                ],
                json!({
                    "cylinders": [g.line_of_sight.cylinder(COLOR_LINE_OF_SIGHT)],
                    "texts": [Self::label(tip(&g.line_of_sight), format!("line of sight β = {}°", deg(g.line_of_sight.half_angle_rad)))],
                }),
            ),
            self.entity(
                FRAME_TARGET,
                ENTITY_GRASP,
                &[("capture_tolerance_m", g.capture_tolerance_m.to_string())],
                json!({"spheres": [sphere(g.grasp_t, g.capture_tolerance_m, COLOR_GRASP)]}),
            ),
        ]
    }
}

/// JSON-schema builders of Foxglove's types, each with its description.
mod fx {
    use serde_json::{Value, json};

    pub fn num(d: &str) -> Value {
        json!({"type": "number", "description": d})
    }
    pub fn string(d: &str) -> Value {
        json!({"type": "string", "description": d})
    }
    pub fn boolean(d: &str) -> Value {
        json!({"type": "boolean", "description": d})
    }
    pub fn time(d: &str) -> Value {
        let int = |d: &str| json!({"type": "integer", "minimum": 0, "description": d});
        json!({"type": "object", "title": "time", "description": d,
               "properties": {"sec": int("seconds [s]"), "nsec": int("nanoseconds [ns]")}})
    }
    pub fn vector3(d: &str, unit: &str) -> Value {
        json!({"type": "object", "title": "foxglove.Vector3", "description": d,
               "properties": {"x": num(&format!("x [{unit}]")), "y": num(&format!("y [{unit}]")),
                              "z": num(&format!("z [{unit}]"))}})
    }
    pub fn quaternion(d: &str) -> Value {
        json!({"type": "object", "title": "foxglove.Quaternion", "description": d,
               "properties": {"x": num("x [-]"), "y": num("y [-]"), "z": num("z [-]"), "w": num("w [-]")}})
    }
    pub fn pose(d: &str) -> Value {
        json!({"type": "object", "title": "foxglove.Pose", "description": d,
        "properties": {
            "position": vector3("position in the entity's frame", "m"),
            "orientation": quaternion("orientation (rotates local vectors into the entity's frame)"),
        }})
    }
    pub fn color(d: &str) -> Value {
        json!({"type": "object", "title": "foxglove.Color", "description": d,
               "properties": {"r": num("red, 0-1 [-]"), "g": num("green, 0-1 [-]"),
                              "b": num("blue, 0-1 [-]"), "a": num("alpha, 0-1 [-]")}})
    }
    pub fn array(d: &str, items: Value) -> Value {
        json!({"type": "array", "description": d, "items": items})
    }
    /// A primitive type this recording does not use (its lists are empty).
    pub fn unused(d: &str, title: &str) -> Value {
        array(
            d,
            json!({"type": "object", "title": title,
                        "description": "not used by this recording (always empty)"}),
        )
    }
    pub fn sphere() -> Value {
        json!({"type": "object", "title": "foxglove.SpherePrimitive",
        "description": "A primitive representing a sphere or ellipsoid",
        "properties": {
            "pose": pose("position of the center of the sphere and orientation of the sphere"),
            "size": vector3("size (diameter) of the sphere along each axis", "m"),
            "color": color("color of the sphere"),
        }})
    }
    pub fn cylinder() -> Value {
        json!({"type": "object", "title": "foxglove.CylinderPrimitive",
        "description": "A primitive representing a cylinder, elliptic cylinder, or truncated cone",
        "properties": {
            "pose": pose("position of the center of the cylinder and orientation of the cylinder; the flat faces are perpendicular to its z axis"),
            "size": vector3("size of the cylinder's bounding box", "m"),
            "bottom_scale": num("ratio of the bottom face's (min z) diameter to the bounding box, 0-1 [-]"),
            "top_scale": num("ratio of the top face's (max z) diameter to the bounding box, 0-1 [-]"),
            "color": color("color of the cylinder"),
        }})
    }
    pub fn text() -> Value {
        json!({"type": "object", "title": "foxglove.TextPrimitive",
        "description": "A primitive representing a text label",
        "properties": {
            "pose": pose("position of the center of the text box and orientation of the text"),
            "billboard": boolean("whether the text always faces the camera (true) or respects pose.orientation (false)"),
            "font_size": num("font size: line height, in screen pixels when scale_invariant [px], else [m]"),
            "scale_invariant": boolean("whether font_size is in screen pixels (true) or in world units (false)"),
            "color": color("color of the text"),
            "text": string("text"),
        }})
    }
}

impl JsonMsg for SceneUpdate {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(
            &mut *out,
            &json!({"deletions": [], "entities": self.entities()}),
        );
    }
    /// Foxglove's `foxglove.SceneUpdate` JSON schema (docs.foxglove.dev, "SceneUpdate",
    /// "SceneEntity" and the primitives), with units in the descriptions.
    fn json_schema() -> Value {
        let kv = json!({"type": "object", "title": "foxglove.KeyValuePair",
                        "description": "a key with its value",
                        "properties": {"key": fx::string("key"), "value": fx::string("value")}});
        let deletion = json!({"type": "object", "title": "foxglove.SceneEntityDeletion",
        "description": "command to remove previously published entities",
        "properties": {
            "timestamp": fx::time("only matching entities earlier than this are deleted (mission time)"),
            "type": {"type": "integer", "description": "0 MATCHING_ID (the entity with `id`), 1 ALL [-]"},
            "id": fx::string("identifier that must match if type is MATCHING_ID"),
        }});
        let entity = json!({"type": "object", "title": "foxglove.SceneEntity",
        "description": "a visual element in a 3D scene; its primitives share its frame",
        "properties": {
            "timestamp": fx::time("timestamp of the entity (mission time)"),
            "frame_id": fx::string("frame of reference"),
            "id": fx::string("identifier; replaces any prior entity on the topic with the same id"),
            "lifetime": {"type": "object", "title": "duration",
                "description": "time after timestamp when the entity is removed; 0 = kept until replaced",
                "properties": {
                    "sec": {"type": "integer", "description": "seconds [s]"},
                    "nsec": {"type": "integer", "minimum": 0, "description": "nanoseconds [ns]"},
                }},
            "frame_locked": fx::boolean("whether the entity follows its frame as the frame moves (true) or stays where it was in the fixed frame (false)"),
            "metadata": fx::array("user metadata (scenario values behind the entity, and the phase)", kv),
            "arrows": fx::unused("arrow primitives", "foxglove.ArrowPrimitive"),
            "cubes": fx::unused("cube primitives", "foxglove.CubePrimitive"),
            "spheres": fx::array("sphere primitives", fx::sphere()),
            "cylinders": fx::array("cylinder primitives (the cones)", fx::cylinder()),
            "lines": fx::unused("line primitives", "foxglove.LinePrimitive"),
            "triangles": fx::unused("triangle list primitives", "foxglove.TriangleListPrimitive"),
            "texts": fx::array("text primitives (labels)", fx::text()),
            "models": fx::unused("model primitives", "foxglove.ModelPrimitive"),
        }});
        json!({
            "title": "foxglove.SceneUpdate",
            "description": "An update to the entities displayed in a 3D scene",
            "type": "object",
            "properties": {
                "deletions": fx::array("scene entities to delete", deletion),
                "entities": fx::array("scene entities to add or replace", entity),
            }
        })
    }
    fn name() -> &'static str {
        "foxglove.SceneUpdate"
    }
}

/// What the recorder writes for the 3D panel besides the frames: the scene of the
/// scenario, once at the first state and again at every change of mission phase (so
/// that a seek into any phase finds it in that phase; Foxglove keeps the newest
/// entity per id).
#[derive(Debug, Clone)]
pub struct Scene {
    geometry: SceneGeometry,
    scenario: sc_scenario::Scenario,
    /// Phase index of the last update written.
    written: Option<usize>,
}

impl Scene {
    pub fn new(scenario: &sc_scenario::Scenario) -> Self {
        Self {
            geometry: SceneGeometry::from_scenario(scenario),
            scenario: scenario.clone(),
            written: None,
        }
    }

    /// The update to write with a state at time `t` [s] (mission time `log_ns`), if due.
    fn due(&mut self, t: f64, log_ns: u64) -> Option<SceneUpdate> {
        let phase = self.scenario.phase_index(t);
        if self.written == Some(phase) {
            return None;
        }
        self.written = Some(phase);
        Some(SceneUpdate {
            log_ns,
            geometry: self.geometry.clone(),
            phase: self
                .scenario
                .mission
                .phases
                .get(phase)
                .map(|p| p.name.clone())
                .unwrap_or_default(),
        })
    }
}

/// The Foxglove layout shipped in `docs/foxglove/safe-capture-layout.json` (relative to the
/// repository; the test `layout_file_is_current` keeps the file equal to
/// [`foxglove_layout`], `SC_WRITE_FOXGLOVE_LAYOUT=1` rewrites it).
pub const LAYOUT_FILE: &str = "docs/foxglove/safe-capture-layout.json";

/// One plotted message path of a Plot panel, against mission time (the log time).
fn plot_path(topic: &str, field: &str, index: usize, label: String) -> Value {
    json!({
        "value": format!("{topic}.{field}[{index}]"),
        "enabled": true,
        "timestampMethod": "receiveTime",
        "label": label,
    })
}

fn plot_panel(title: &str, paths: Vec<Value>) -> Value {
    json!({
        "title": title,
        "paths": paths,
        "showXAxisLabels": true,
        "showYAxisLabels": true,
        "showLegend": true,
        "legendDisplay": "floating",
        "isSynced": true,
        "xAxisVal": "timestamp",
    })
}

/// Panels stacked in a column (Foxglove's mosaic tree), equal heights.
fn column(ids: &[String]) -> Value {
    match ids {
        [] => Value::Null,
        [one] => Value::String(one.clone()),
        [first, rest @ ..] => json!({
            "direction": "column",
            "first": first,
            "second": column(rest),
            "splitPercentage": 100.0 / ids.len() as f64,
        }),
    }
}

/// The Foxglove layout of a partition recording: the 3D panel in the reference frame
/// with the frames of `/tf` and the scene of `/scene`; plots of every barrier h the
/// three safety filters report (by subsystem and kind, units in the legend); and per
/// subsystem the nominal command against the safe one.
pub fn foxglove_layout() -> Value {
    use sc_icd::services as svc;
    let mut config = Map::new();
    let mut barrier_ids = Vec::new();
    // (panel id, title, service, index range in the filter's report, names)
    type BarrierPlot<'a> = (
        &'a str,
        &'a str,
        &'a str,
        std::ops::Range<usize>,
        &'a [&'a str],
    );
    let tr = &sc_cbf::names::TRANSLATIONAL;
    let at = &sc_cbf::names::ATTITUDE;
    let rb = &sc_cbf::names::ROBOTIC;
    let nj = sc_icd::N_JOINTS;
    let groups: [BarrierPlot; 5] = [
        (
            "barriers_translational",
            "Barriers h: translational (corridor, zone)",
            svc::SAFE_TRANSLATIONAL.as_str(),
            0..tr.len(),
            tr,
        ),
        (
            "barriers_attitude",
            "Barriers h: attitude (line of sight, rate limits)",
            svc::SAFE_ATTITUDE.as_str(),
            0..at.len(),
            at,
        ),
        (
            "barriers_joint_angles",
            "Barriers h: joint angles",
            svc::SAFE_ROBOTIC.as_str(),
            0..nj,
            rb,
        ),
        (
            "barriers_joint_rates",
            "Barriers h: joint rates",
            svc::SAFE_ROBOTIC.as_str(),
            nj..3 * nj,
            rb,
        ),
        (
            "barriers_link_base",
            "Barriers h: link-base spheres",
            svc::SAFE_ROBOTIC.as_str(),
            3 * nj..rb.len(),
            rb,
        ),
    ];
    for (id, title, topic, range, names) in groups {
        let paths = range
            .map(|i| {
                let unit = barrier_unit(names[i]).unwrap_or("?");
                plot_path(topic, "h", i, format!("{} [{unit}]", names[i]))
            })
            .collect();
        let id = format!("Plot!{id}");
        config.insert(id.clone(), plot_panel(title, paths));
        barrier_ids.push(id);
    }
    let mut command_ids = Vec::new();
    let xyz = ["x", "y", "z"];
    let commands: [(&str, &str, &str, &str, &str, &str, usize); 3] = [
        (
            "commands_translational",
            "Force f_H [N]: nominal vs safe",
            svc::NOMINAL_TRANSLATIONAL.as_str(),
            "f_h",
            svc::SAFE_TRANSLATIONAL.as_str(),
            "f_H",
            3,
        ),
        (
            "commands_attitude",
            "Torque τ_B [N·m]: nominal vs safe",
            svc::NOMINAL_ATTITUDE.as_str(),
            "tau_b",
            svc::SAFE_ATTITUDE.as_str(),
            "τ_B",
            3,
        ),
        (
            "commands_robotic",
            "Joint torques τ_M [N·m]: nominal vs safe",
            svc::NOMINAL_ROBOTIC.as_str(),
            "tau_m",
            svc::SAFE_ROBOTIC.as_str(),
            "τ_M",
            nj,
        ),
    ];
    for (id, title, nominal, field, safe, symbol, n) in commands {
        let component = |i: usize| {
            if n == 3 {
                xyz[i].to_string()
            } else {
                (i + 1).to_string()
            }
        };
        let mut paths = Vec::new();
        for i in 0..n {
            paths.push(plot_path(
                nominal,
                field,
                i,
                format!("{symbol} {} nominal", component(i)),
            ));
            paths.push(plot_path(
                safe,
                "u",
                i,
                format!("{symbol} {} safe", component(i)),
            ));
        }
        let id = format!("Plot!{id}");
        config.insert(id.clone(), plot_panel(title, paths));
        command_ids.push(id);
    }
    let three_d = "3D!scene".to_string();
    config.insert(
        three_d.clone(),
        json!({
            "followTf": FRAME_REFERENCE,
            "followMode": "follow-pose",
            "scene": {"transforms": {"showLabel": true}},
            "transforms": {},
            "topics": {
                TF_TOPIC: {"visible": true},
                SCENE_TOPIC: {"visible": true},
            },
            "layers": {"grid": {"visible": true, "layerId": "foxglove.Grid", "frameId": FRAME_REFERENCE}},
        }),
    );
    json!({
        "configById": Value::Object(config),
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1.0},
        "layout": {
            "direction": "row",
            "first": three_d,
            "second": {
                "direction": "row",
                "first": column(&barrier_ids),
                "second": column(&command_ids),
                "splitPercentage": 50.0,
            },
            "splitPercentage": 40.0,
        },
    })
}

/// The MCAP file being written.
pub struct McapOut {
    w: mcap::Writer<BufWriter<std::fs::File>>,
    channels: BTreeMap<String, u16>,
    seq: u32,
    /// The JSON of the message being written (reused).
    buf: Vec<u8>,
    /// Messages written per topic.
    pub written: BTreeMap<String, u64>,
    /// The scene written with the states ([`McapOut::write_3d`]), once set.
    scene: Option<Scene>,
}

impl McapOut {
    /// Creates `path`.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let f = std::fs::File::create(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        // LZ4 chunks on the recorder's own thread: zstd (the crate's default) took a
        // fifth of the recorder's CPU time and ran worker threads beside the
        // partition's processes on a 2-core machine; Foxglove reads both.
        let w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Lz4))
            .create(BufWriter::new(f))
            .context("mcap header")?;
        Ok(Self {
            w,
            channels: BTreeMap::new(),
            seq: 0,
            buf: Vec::with_capacity(4096),
            written: BTreeMap::new(),
            scene: None,
        })
    }

    /// From now on [`McapOut::write_3d`] also writes the scene of `scenario` on
    /// [`SCENE_TOPIC`] (see [`Scene`]).
    pub fn set_scene(&mut self, scenario: &sc_scenario::Scenario) {
        self.scene = Some(Scene::new(scenario));
    }

    /// Writes one message on topic `topic`: `log_ns` is its mission time [ns since the
    /// mission's start] (what Foxglove's timeline shows), `publish_ns` the host's monotonic
    /// clock when it was published (kept in the record's `publish_time`).
    pub fn write<T: JsonMsg>(
        &mut self,
        topic: &str,
        log_ns: u64,
        publish_ns: u64,
        msg: &T,
    ) -> anyhow::Result<()> {
        let id = match self.channels.get(topic) {
            Some(id) => *id,
            None => {
                let schema = serde_json::to_vec(&T::json_schema())?;
                let sid = self
                    .w
                    .add_schema(T::name(), "jsonschema", &schema)
                    .context("mcap schema")?;
                let cid = self
                    .w
                    .add_channel(sid, topic, "json", &BTreeMap::new())
                    .context("mcap channel")?;
                self.channels.insert(topic.to_string(), cid);
                cid
            }
        };
        self.seq = self.seq.wrapping_add(1);
        self.buf.clear();
        msg.write_json(&mut self.buf);
        self.w
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: self.seq,
                    log_time: log_ns,
                    publish_time: publish_ns,
                },
                &self.buf,
            )
            .context("mcap write")?;
        *self.written.entry(topic.to_string()).or_default() += 1;
        Ok(())
    }

    /// Writes what the 3D panel needs of state `s`: its frame transforms on
    /// [`TF_TOPIC`] ([`FrameTransform::of_state`]) and, when due, the scene on
    /// [`SCENE_TOPIC`] (after the frames it refers to; see [`Scene`]).
    pub fn write_3d(
        &mut self,
        log_ns: u64,
        publish_ns: u64,
        s: &sc_icd::SimState,
    ) -> anyhow::Result<()> {
        for f in FrameTransform::of_state(s, log_ns) {
            self.write(TF_TOPIC, log_ns, publish_ns, &f)?;
        }
        if let Some(update) = self.scene.as_mut().and_then(|sc| sc.due(s.t, log_ns)) {
            self.write(SCENE_TOPIC, log_ns, publish_ns, &update)?;
        }
        Ok(())
    }

    /// Writes an MCAP `Metadata` record `name` with the key/value pairs `entries`
    /// (Foxglove shows them in its "Metadata" panel of the file).
    pub fn write_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> anyhow::Result<()> {
        self.w
            .write_metadata(&mcap::records::Metadata {
                name: name.to_string(),
                metadata: entries,
            })
            .context("mcap metadata")?;
        Ok(())
    }

    /// Writes the summary section and closes the file.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        self.w.finish().context("mcap finish")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the recorder writes reads back as MCAP: one channel per topic with its
    /// JSON schema, every message valid JSON with all fields, NaN as null.
    #[test]
    fn messages_read_back_as_json_with_schemas() {
        let dir = std::env::temp_dir().join(format!("sc-mcap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.mcap");
        let mut state = sc_icd::SimState {
            tick: 7,
            t: 0.7,
            ..Default::default()
        };
        state.theta[6] = -1.25e-3;
        state.r_h = [1.0, f64::NAN, f64::INFINITY];
        let mut safe = sc_icd::SafeRobotic {
            tick: 7,
            ..Default::default()
        };
        safe.h[41] = 0.5;
        let mut out = McapOut::create(&path).unwrap();
        for k in 0..3u64 {
            state.tick = k;
            out.write("sim/state", 100 + k, 5000 + k, &state).unwrap();
        }
        out.write("safe/robotic", 200, 6000, &safe).unwrap();
        out.finish().unwrap();
        assert_eq!(out.written["sim/state"], 3);
        drop(out);

        let bytes = std::fs::read(&path).unwrap();
        let mut seen = Vec::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.encoding, "jsonschema");
            assert_eq!(m.channel.message_encoding, "json");
            let sch: Value = serde_json::from_slice(&schema.data).unwrap();
            let v: Value = serde_json::from_slice(&m.data).unwrap();
            // every schema property is in the message and nothing else
            let props = sch["properties"].as_object().unwrap();
            let obj = v.as_object().unwrap();
            assert_eq!(
                props.keys().collect::<Vec<_>>(),
                obj.keys().collect::<Vec<_>>()
            );
            seen.push((m.channel.topic.clone(), m.log_time, v));
            assert!(
                m.publish_time >= 5000,
                "publish_time keeps the host's clock"
            );
        }
        assert_eq!(seen.len(), 4);
        let (topic, log_time, v) = &seen[2];
        assert_eq!((topic.as_str(), *log_time), ("sim/state", 102));
        assert_eq!(v["tick"], 2);
        assert_eq!(v["t"], 0.7);
        assert_eq!(v["theta"][6], -1.25e-3);
        assert_eq!(v["r_h"], json!([1.0, null, null]));
        assert_eq!(v["theta"].as_array().unwrap().len(), sc_icd::N_JOINTS);
        let (topic, _, v) = &seen[3];
        assert_eq!(topic, "safe/robotic");
        assert_eq!(
            v["h"].as_array().unwrap().len(),
            sc_icd::N_CONSTRAINTS_ROBOTIC
        );
        assert_eq!(v["h"][41], 0.5);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A metadata record reads back by name with its key/value pairs, beside messages.
    #[test]
    fn metadata_record_reads_back() {
        let dir = std::env::temp_dir().join(format!("sc-mcap-meta-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.mcap");
        let entries = BTreeMap::from([
            ("version".to_string(), "1.2.3".to_string()),
            (
                "scenario".to_string(),
                "[mission]\nname = \"x\"\n".to_string(),
            ),
        ]);
        let mut out = McapOut::create(&path).unwrap();
        out.write_metadata("safe-capture", entries.clone()).unwrap();
        let state = sc_icd::SimState::default();
        out.write("sim/state", 0, 1, &state).unwrap();
        out.finish().unwrap();
        drop(out);

        let bytes = std::fs::read(&path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert_eq!(summary.metadata_indexes.len(), 1);
        let idx = &summary.metadata_indexes[0];
        assert_eq!(idx.name, "safe-capture");
        let m = mcap::read::metadata(&bytes, idx).unwrap();
        assert_eq!(m.name, "safe-capture");
        assert_eq!(m.metadata, entries);
        assert_eq!(mcap::MessageStream::new(&bytes).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Foxglove's rotation of a child frame, `[x, y, z, w]` applied as `v' = q v q*`
    /// (its convention: child-frame vectors into the parent frame).
    fn foxglove_rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
        let [x, y, z, w] = q;
        let u = nalgebra::Vector3::new(x, y, z);
        let v = nalgebra::Vector3::new(v[0], v[1], v[2]);
        let t = 2.0 * u.cross(&v);
        let r = v + w * t + u.cross(&t);
        [r[0], r[1], r[2]]
    }

    /// The frames of a state: the project's q_AB (scalar first) rotates a child (B)
    /// vector into the parent (A) exactly as Foxglove's rotation does; the positions are
    /// the state's; the channel reads back as `foxglove.FrameTransform` JSON.
    #[test]
    fn state_frames_follow_foxglove_convention_and_read_back() {
        let n = (0.3f64 * 0.3 + 0.5 * 0.5 + 0.1 * 0.1 + 0.8 * 0.8).sqrt();
        let q_rb = [0.8 / n, 0.3 / n, -0.5 / n, 0.1 / n];
        let q_rt = [0.6, 0.0, 0.8, 0.0];
        let state = sc_icd::SimState {
            tick: 12,
            r_r: [1.0, -2.0, 3.5],
            q_rb,
            q_rt,
            ee_b: [0.25, 0.5, -0.75],
            ..Default::default()
        };
        let log_ns = 1_200_000_123;
        let frames = FrameTransform::of_state(&state, log_ns);
        let v = [0.2, -1.0, 0.7];
        for (f, q) in [(&frames[0], q_rb), (&frames[1], q_rt)] {
            let ours = sc_models::quat::rotate(&q, &nalgebra::Vector3::new(v[0], v[1], v[2]));
            let theirs = foxglove_rotate(f.rotation, v);
            for k in 0..3 {
                assert!((ours[k] - theirs[k]).abs() < 1e-12, "{ours:?} {theirs:?}");
            }
        }
        assert_eq!(
            (frames[0].parent, frames[0].child),
            (FRAME_REFERENCE, FRAME_SERVICER)
        );
        assert_eq!(frames[0].translation, state.r_r);
        assert_eq!(
            (frames[1].parent, frames[1].child),
            (FRAME_REFERENCE, FRAME_TARGET)
        );
        assert_eq!(frames[1].translation, [0.0; 3]);
        assert_eq!(
            (frames[2].parent, frames[2].child),
            (FRAME_SERVICER, FRAME_END_EFFECTOR)
        );
        assert_eq!(frames[2].translation, state.ee_b);
        assert_eq!(
            (frames[3].parent, frames[3].child),
            (FRAME_REFERENCE, FRAME_SERVICER_COM)
        );
        assert_eq!(frames[3].translation, state.com_r);
        assert_eq!(frames[3].rotation, frames[0].rotation);

        let dir = std::env::temp_dir().join(format!("sc-mcap-tf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tf.mcap");
        let mut out = McapOut::create(&path).unwrap();
        out.write_3d(log_ns, 7, &state).unwrap();
        out.finish().unwrap();
        assert_eq!(out.written[TF_TOPIC], 4);
        assert!(!out.written.contains_key(SCENE_TOPIC), "no scene set");
        drop(out);
        let bytes = std::fs::read(&path).unwrap();
        let msgs: Vec<_> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(|m| m.unwrap())
            .collect();
        assert_eq!(msgs.len(), 4);
        let m = &msgs[0];
        assert_eq!(m.channel.topic, TF_TOPIC);
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.name, "foxglove.FrameTransform");
        let v: Value = serde_json::from_slice(&m.data).unwrap();
        assert_eq!(v["timestamp"], json!({"sec": 1, "nsec": 200_000_123}));
        assert_eq!(v["parent_frame_id"], FRAME_REFERENCE);
        assert_eq!(v["child_frame_id"], FRAME_SERVICER);
        assert_eq!(v["translation"], json!({"x": 1.0, "y": -2.0, "z": 3.5}));
        assert_eq!(v["rotation"]["w"], q_rb[0]);
        assert_eq!(v["rotation"]["x"], q_rb[1]);
        let sch: Value = serde_json::from_slice(&schema.data).unwrap();
        let props = sch["properties"].as_object().unwrap();
        assert_eq!(
            props.keys().collect::<Vec<_>>(),
            v.as_object().unwrap().keys().collect::<Vec<_>>()
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    /// The JSON schema of every message type the recorder writes.
    pub(crate) fn all_schemas() -> Vec<Value> {
        vec![
            sc_icd::Tick::json_schema(),
            sc_icd::SimState::json_schema(),
            sc_icd::NominalTranslational::json_schema(),
            sc_icd::NominalAttitude::json_schema(),
            sc_icd::NominalRobotic::json_schema(),
            sc_icd::SafeTranslational::json_schema(),
            sc_icd::SafeAttitude::json_schema(),
            sc_icd::SafeRobotic::json_schema(),
            sc_icd::StepResult::json_schema(),
            FrameTransform::json_schema(),
            SceneUpdate::json_schema(),
        ]
    }

    /// Every property of `schema` (recursively, through objects and array items) without
    /// a non-empty description, or (when `unit`) without a `[unit]` in it, as paths.
    fn undescribed(schema: &Value, path: &str, unit: bool, bad: &mut Vec<String>) {
        if let Some(props) = schema.get("properties").and_then(Value::as_object) {
            for (k, v) in props {
                let p = format!("{path}.{k}");
                let d = v.get("description").and_then(Value::as_str).unwrap_or("");
                let leaf = v.get("properties").is_none();
                // a number (or an array of numbers) has a unit whatever the schema
                let numeric = |s: &Value| {
                    let t = &s["type"];
                    t == "number"
                        || t == "integer"
                        || t.as_array().is_some_and(|a| a.contains(&json!("number")))
                };
                let needs_unit = leaf && (unit || numeric(v) || numeric(&v["items"]));
                if d.trim().is_empty() || (needs_unit && !(d.contains('[') && d.contains(']'))) {
                    bad.push(p.clone());
                }
                undescribed(v, &p, unit, bad);
            }
        }
        if let Some(items) = schema.get("items") {
            undescribed(items, &format!("{path}[]"), unit, bad);
        }
    }

    /// Every field of every channel's schema has a description; every ICD field (and
    /// every numeric field of the Foxglove types) names its unit in brackets.
    #[test]
    fn every_schema_field_has_a_description_with_its_unit() {
        let mut bad = Vec::new();
        for s in all_schemas() {
            let title = s["title"].as_str().unwrap_or("?").to_string();
            assert!(s.get("description").is_some(), "{title}: no description");
            let icd = title.starts_with("safe_capture::");
            undescribed(&s, &title, icd, &mut bad);
        }
        assert!(bad.is_empty(), "fields without description/unit: {bad:?}");
        // the check can fail: a field without one is found
        let mut s = sc_icd::Tick::json_schema();
        s["properties"]["t"]
            .as_object_mut()
            .unwrap()
            .remove("description");
        let mut bad = Vec::new();
        undescribed(&s, "Tick", true, &mut bad);
        assert_eq!(bad, ["Tick.t"]);
        // the units are those of the ICD
        let st = sc_icd::SafeTranslational::json_schema();
        assert!(
            st["properties"]["actuated"]["description"]
                .as_str()
                .unwrap()
                .contains("f_B")
        );
        assert!(
            st["properties"]["h"]["items"]["description"]
                .as_str()
                .unwrap()
                .contains("0 approach_corridor [m], 1 collision_avoidance_zone [m²]")
        );
    }

    /// Every barrier has a unit (a new constraint cannot appear without one).
    #[test]
    fn every_barrier_has_a_unit() {
        for n in sc_mission::constraint_names() {
            assert!(barrier_unit(n).is_some(), "{n}");
        }
        assert_eq!(barrier_unit("theta_dot_max_3"), Some("rad/s"));
        assert_eq!(barrier_unit("theta_3"), Some("rad²"));
        assert_eq!(barrier_unit("link_base_2_1"), Some("m²"));
        assert_eq!(barrier_unit("something_else"), None);
    }

    /// Every property of `schema` that `v` has, recursively, and `v` has nothing else:
    /// the schema describes the message completely.
    fn matches_schema(schema: &Value, v: &Value, path: &str) {
        match (schema.get("properties").and_then(Value::as_object), v) {
            (Some(props), Value::Object(o)) => {
                for k in o.keys() {
                    let sub = props
                        .get(k)
                        .unwrap_or_else(|| panic!("{path}.{k} not in schema"));
                    matches_schema(sub, &o[k], &format!("{path}.{k}"));
                }
                for k in props.keys() {
                    assert!(o.contains_key(k), "{path}.{k} missing from the message");
                }
            }
            (None, Value::Array(a)) => {
                assert_eq!(schema["type"], "array", "{path}");
                for x in a {
                    matches_schema(&schema["items"], x, &format!("{path}[]"));
                }
            }
            (None, Value::Number(_)) => assert!(
                schema["type"] == "number"
                    || schema["type"] == "integer"
                    || schema["type"]
                        .as_array()
                        .is_some_and(|t| t.contains(&json!("number"))),
                "{path}: {schema}"
            ),
            (None, Value::String(_)) => assert_eq!(schema["type"], "string", "{path}"),
            (None, Value::Bool(_)) => assert_eq!(schema["type"], "boolean", "{path}"),
            (s, v) => panic!("{path}: {v} against {s:?}"),
        }
    }

    fn scenario() -> sc_scenario::Scenario {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
        sc_scenario::Scenario::load(&path).unwrap()
    }

    /// The cylinder of a cone, as Foxglove draws it: its apex (bottom face, scale 0) at
    /// the frame's origin, its axis (local z turned by the pose) along the cone's,
    /// its top face's radius `L tan(half angle)`.
    fn assert_cone(cyl: &Value, axis: [f64; 3], half_angle_rad: f64, length: f64) {
        let p = &cyl["pose"]["position"];
        let o = &cyl["pose"]["orientation"];
        let q = [
            o["x"].as_f64().unwrap(),
            o["y"].as_f64().unwrap(),
            o["z"].as_f64().unwrap(),
            o["w"].as_f64().unwrap(),
        ];
        let z = foxglove_rotate(q, [0.0, 0.0, 1.0]);
        let size = &cyl["size"];
        let l = size["z"].as_f64().unwrap();
        assert!((l - length).abs() < 1e-12);
        let centre = [
            p["x"].as_f64().unwrap(),
            p["y"].as_f64().unwrap(),
            p["z"].as_f64().unwrap(),
        ];
        for k in 0..3 {
            assert!((z[k] - axis[k]).abs() < 1e-12, "axis {z:?} vs {axis:?}");
            assert!(
                (centre[k] - z[k] * l / 2.0).abs() < 1e-12,
                "apex not at the origin"
            );
        }
        assert_eq!(cyl["bottom_scale"], 0.0);
        assert_eq!(cyl["top_scale"], 1.0);
        let r = size["x"].as_f64().unwrap() / 2.0;
        assert!((r - l * half_angle_rad.tan()).abs() < 1e-12);
        assert_eq!(size["x"], size["y"]);
    }

    /// The scene is the scenario's geometry: the corridor cone (apex at the target's
    /// CoM, axis d_R, ψ_AC) and the zone sphere (R_CAZ) in the reference frame, the line
    /// of sight (boresight d_B, β) at the servicer's centre of mass, the grasping point
    /// (capture tolerance) on the target; each kept (lifetime 0) and frame-locked; its
    /// JSON is described completely by its schema.
    #[test]
    fn scene_is_the_scenario_geometry() {
        let sc = scenario();
        let upd = SceneUpdate {
            log_ns: 3 * NS_PER_S + 5,
            geometry: SceneGeometry::from_scenario(&sc),
            phase: "final_approach".into(),
        };
        let mut buf = Vec::new();
        upd.write_json(&mut buf);
        let v: Value = serde_json::from_slice(&buf).unwrap();
        matches_schema(&SceneUpdate::json_schema(), &v, "SceneUpdate");
        let ents = v["entities"].as_array().unwrap();
        let by_id = |id: &str| {
            ents.iter()
                .find(|e| e["id"] == id)
                .unwrap_or_else(|| panic!("{id}"))
        };
        for e in ents {
            assert_eq!(e["lifetime"], json!({"sec": 0, "nsec": 0}));
            assert_eq!(e["frame_locked"], true);
            assert_eq!(e["timestamp"], json!({"sec": 3, "nsec": 5}));
        }
        let tr = &sc.safety.translational;
        let p0 = nalgebra::Vector3::from(sc.servicer.initial_position_m).norm();
        let corridor = by_id(ENTITY_CORRIDOR);
        assert_eq!(corridor["frame_id"], FRAME_REFERENCE);
        assert_cone(
            &corridor["cylinders"][0],
            tr.corridor_axis,
            tr.corridor_half_angle_deg.to_radians(),
            p0,
        );
        let zone = by_id(ENTITY_ZONE);
        assert_eq!(zone["frame_id"], FRAME_REFERENCE);
        let sphere = &zone["spheres"][0];
        assert_eq!(
            sphere["size"],
            json!({"x": 2.0 * tr.caz_radius_m, "y": 2.0 * tr.caz_radius_m, "z": 2.0 * tr.caz_radius_m})
        );
        assert_eq!(
            sphere["pose"]["position"],
            json!({"x": 0.0, "y": 0.0, "z": 0.0})
        );
        let los = by_id(ENTITY_LINE_OF_SIGHT);
        assert_eq!(los["frame_id"], FRAME_SERVICER_COM);
        assert_cone(
            &los["cylinders"][0],
            sc.servicer.boresight_body,
            sc.safety.attitude.los_half_angle_deg.to_radians(),
            p0,
        );
        let grasp = by_id(ENTITY_GRASP);
        assert_eq!(grasp["frame_id"], FRAME_TARGET);
        let g = &grasp["spheres"][0];
        let gp = sc.target.grasp_point_m;
        assert_eq!(
            g["pose"]["position"],
            json!({"x": gp[0], "y": gp[1], "z": gp[2]})
        );
        assert_eq!(g["size"]["x"], 2.0 * sc.mission.capture_tolerance_m);
        assert!(
            corridor["metadata"]
                .as_array()
                .unwrap()
                .contains(&json!({"key": "phase", "value": "final_approach"}))
        );
        // another scenario, another scene: nothing is fixed in the code
        let mut other = sc.clone();
        other.safety.translational.corridor_axis = [0.0, 0.0, -1.0];
        other.safety.translational.corridor_half_angle_deg = 12.0;
        other.safety.attitude.los_half_angle_deg = 7.5;
        other.servicer.boresight_body = [0.0, 1.0, 0.0];
        let g = SceneGeometry::from_scenario(&other);
        let upd = SceneUpdate {
            log_ns: 0,
            geometry: g,
            phase: String::new(),
        };
        let ents = upd.entities();
        assert_cone(
            &ents[0]["cylinders"][0],
            [0.0, 0.0, -1.0],
            12f64.to_radians(),
            p0,
        );
        assert_cone(
            &ents[2]["cylinders"][0],
            [0.0, 1.0, 0.0],
            7.5f64.to_radians(),
            p0,
        );
    }

    /// The scene goes out with the first state and again at each phase change, nowhere
    /// else, after that state's frames; it reads back as foxglove.SceneUpdate.
    #[test]
    fn scene_written_at_start_and_at_each_phase() {
        let sc = scenario();
        let dir = std::env::temp_dir().join(format!("sc-mcap-scene-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.mcap");
        let mut out = McapOut::create(&path).unwrap();
        out.set_scene(&sc);
        let period = sc.mission.control_period_s;
        let end = sc.mission.phases.last().unwrap().start_s + 3.0 * period;
        let n = (end / period).round() as u64;
        for k in 0..n {
            let s = sc_icd::SimState {
                tick: k,
                t: k as f64 * period,
                ..Default::default()
            };
            out.write_3d(k * 100, k, &s).unwrap();
        }
        out.finish().unwrap();
        assert_eq!(out.written[SCENE_TOPIC], sc.mission.phases.len() as u64);
        assert_eq!(out.written[TF_TOPIC], 4 * n);
        drop(out);
        let bytes = std::fs::read(&path).unwrap();
        let mut phases = Vec::new();
        let mut last_topic = String::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            if m.channel.topic == SCENE_TOPIC {
                assert_eq!(last_topic, TF_TOPIC, "scene after the frames");
                let schema = m.channel.schema.as_ref().unwrap();
                assert_eq!(schema.name, "foxglove.SceneUpdate");
                assert_eq!(m.channel.message_encoding, "json");
                let v: Value = serde_json::from_slice(&m.data).unwrap();
                let sch: Value = serde_json::from_slice(&schema.data).unwrap();
                matches_schema(&sch, &v, "SceneUpdate");
                let meta = &v["entities"][0]["metadata"];
                let phase = meta
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|kv| kv["key"] == "phase")
                    .unwrap();
                phases.push((m.log_time, phase["value"].as_str().unwrap().to_string()));
            }
            last_topic = m.channel.topic.clone();
        }
        let want: Vec<(u64, String)> = sc
            .mission
            .phases
            .iter()
            .map(|p| ((p.start_s / period).round() as u64 * 100, p.name.clone()))
            .collect();
        assert_eq!(phases, want);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// The shipped layout is the one [`foxglove_layout`] builds (SC_WRITE_FOXGLOVE_LAYOUT=1
    /// rewrites it); every panel of its mosaic is configured and every configured panel
    /// is placed; it plots every barrier of the three filters.
    #[test]
    fn layout_file_is_current() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(LAYOUT_FILE);
        let want = foxglove_layout();
        let text = serde_json::to_string_pretty(&want).unwrap() + "\n";
        if std::env::var_os("SC_WRITE_FOXGLOVE_LAYOUT").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let got = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            got == text,
            "{} is stale: SC_WRITE_FOXGLOVE_LAYOUT=1 cargo test -p sc-ground layout_file_is_current",
            path.display()
        );
        fn placed(node: &Value, out: &mut Vec<String>) {
            match node {
                Value::String(s) => out.push(s.clone()),
                Value::Object(o) => {
                    placed(&o["first"], out);
                    placed(&o["second"], out);
                }
                _ => panic!("mosaic node {node}"),
            }
        }
        let mut ids = Vec::new();
        placed(&want["layout"], &mut ids);
        ids.sort();
        let configured: Vec<String> = want["configById"]
            .as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect();
        assert_eq!(ids, configured);
        let h_paths = want["configById"]
            .as_object()
            .unwrap()
            .values()
            .flat_map(|p| p["paths"].as_array().cloned().unwrap_or_default())
            .filter(|p| p["value"].as_str().unwrap().contains(".h["))
            .count();
        assert_eq!(h_paths, sc_icd::N_BARRIERS);
    }
}
