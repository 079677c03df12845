//! The ICD as a C header for C/C++ partners (`libs/icd/include/safe_capture_icd.h`),
//! generated from the Rust types: every message's fields with their Rust offsets
//! ([`structs`]), and the constants a partner needs ([`defines`]): array lengths,
//! service and type names, due bits, tick commands, roles, event ids.
//!
//! The committed header is [`render`]'s text (test `tests/c_header.rs`, which also
//! compiles a C program against it that checks every size, alignment and offset
//! against the Rust values; `SC_WRITE_C_HEADER=1 cargo test -p sc-icd --test c_header`
//! rewrites it after a change of the ICD).

use crate::*;
use core::mem::{align_of, offset_of, size_of};

/// A Rust field type that has a C spelling: the scalars of the ICD and arrays of them.
pub trait CType {
    /// The C scalar type (`<stdint.h>` names, `double`).
    const SCALAR: &'static str;
    /// Array length, `None` for a scalar.
    const LEN: Option<usize>;
}

impl CType for u64 {
    const SCALAR: &'static str = "uint64_t";
    const LEN: Option<usize> = None;
}
impl CType for u32 {
    const SCALAR: &'static str = "uint32_t";
    const LEN: Option<usize> = None;
}
impl CType for i32 {
    const SCALAR: &'static str = "int32_t";
    const LEN: Option<usize> = None;
}
impl CType for f64 {
    const SCALAR: &'static str = "double";
    const LEN: Option<usize> = None;
}
impl<const N: usize> CType for [f64; N] {
    const SCALAR: &'static str = "double";
    const LEN: Option<usize> = Some(N);
}

/// One field of a message: name, C type, array length, Rust offset and size.
#[derive(Debug, Clone, PartialEq)]
pub struct CField {
    /// Field name (the same in Rust, Python and C).
    pub name: &'static str,
    /// C scalar type.
    pub scalar: &'static str,
    /// Array length (`None`: scalar).
    pub len: Option<usize>,
    /// Offset in the Rust struct [B].
    pub offset: usize,
    /// Size in the Rust struct [B].
    pub size: usize,
}

/// One message: its Rust name, iceoryx2 type name, size, alignment and fields.
#[derive(Debug, Clone, PartialEq)]
pub struct CStruct {
    /// Rust name; the C type is `Sc<name>`.
    pub name: &'static str,
    /// iceoryx2 type name (must be given when a C/C++ process opens the service).
    pub type_name: &'static str,
    /// One line on what it is.
    pub doc: &'static str,
    /// `size_of` in Rust [B].
    pub size: usize,
    /// `align_of` in Rust [B].
    pub align: usize,
    /// Fields in declaration order.
    pub fields: Vec<CField>,
}

impl CStruct {
    /// The C type name.
    pub fn c_name(&self) -> String {
        format!("Sc{}", self.name)
    }
}

fn field<T, F: CType>(name: &'static str, offset: usize, _: fn(&T) -> &F) -> CField {
    CField {
        name,
        scalar: F::SCALAR,
        len: F::LEN,
        offset,
        size: size_of::<F>(),
    }
}

// The field types come from the Rust struct (the closure's return type), the offsets
// from `offset_of!`; only the names are listed, and `tests::fields_cover_every_byte`
// guarantees the list is complete.
macro_rules! c_struct {
    ($t:ident, $doc:literal { $($f:ident),* $(,)? }) => {
        CStruct {
            name: stringify!($t),
            type_name: type_name_of::<$t>(),
            doc: $doc,
            size: size_of::<$t>(),
            align: align_of::<$t>(),
            fields: vec![$(field(stringify!($f), offset_of!($t, $f), |s: &$t| &s.$f)),*],
        }
    };
}

macro_rules! nominal_fields {
    ($t:ident, $doc:literal, $cmd:ident) => {
        c_struct!(
            $t,
            $doc {
                tick,
                t,
                valid,
                phase,
                recv_ns,
                publish_ns,
                $cmd
            }
        )
    };
}

macro_rules! safe_fields {
    ($t:ident, $doc:literal) => {
        c_struct!(
            $t,
            $doc {
                tick,
                t,
                recv_ns,
                publish_ns,
                active_mask,
                solve_ns,
                solver_status,
                iterations,
                fault_flags,
                n_constraints,
                phase,
                solve_cpu_ns,
                slack,
                h,
                phi,
                u,
                actuated
            }
        )
    };
}

/// Every message of the ICD, in the order of docs/ICD.md.
pub fn structs() -> Vec<CStruct> {
    vec![
        c_struct!(Tick, "Scheduler -> simulator, recorder (step); -> every process on the control service (stop)." {
            tick, due_mask, clock_mode, t, send_ns, command, _pad0
        }),
        c_struct!(SimState, "Simulator -> nominal controllers (partner/state), safety filters, recorder: the observation at the start of the step." {
            tick, t, due_mask, _pad0, tick_send_ns, recv_ns, publish_ns, step, r_h, v_h, r_r,
            v_r, q_hr, omega_h, omega_dot_h, mean_motion, q_rb, omega_b, theta, theta_dot, q_rt,
            omega_t, omega_dot_t, grasp_r, grasp_v_r, grasp_a_r, grasp_b, ee_b, ee_r, ee_v_r,
            com_h, com_v_h, com_r, com_v_r, barriers, barriers_between
        }),
        nominal_fields!(
            NominalTranslational,
            "Nominal translational controller -> translational safety filter: f_h, Hill frame [N].",
            f_h
        ),
        nominal_fields!(
            NominalAttitude,
            "Nominal attitude controller -> attitude safety filter: tau_b, base frame [N m].",
            tau_b
        ),
        nominal_fields!(
            NominalRobotic,
            "Nominal robotic controller -> robotic safety filter: tau_m, joints [N m].",
            tau_m
        ),
        safe_fields!(
            SafeTranslational,
            "Translational safety filter -> attitude/robotic filters, simulator, recorder."
        ),
        safe_fields!(
            SafeAttitude,
            "Attitude safety filter -> robotic filter, simulator, recorder."
        ),
        safe_fields!(SafeRobotic, "Robotic safety filter -> simulator, recorder."),
        c_struct!(StepResult, "Simulator -> scheduler, recorder: the applied command and how the step ended." {
            tick, t, end, fallback_mask, held_mask, fault_flags, safe_recv_ns, publish_ns,
            force_b, torque_b, tau
        }),
        c_struct!(Health, "Recorder -> scheduler: progress (lock-step flow control)." {
            role, pid, state, last_fault_flags, ticks_handled, deadline_misses, cycle_slips,
            last_tick, publish_ns
        }),
    ]
}

/// Event ids of the partition's event services (`sc_bus::pubsub`, `sc_bus::handshake`;
/// `libs/bus/tests/icd_constants.rs` checks them against sc-bus).
pub mod events {
    /// A publisher notifies this after each send.
    pub const SAMPLE: u32 = 0;
    /// iceoryx2 emits it when dead-node clean-up removes a crashed publisher's notifier.
    pub const NOTIFIER_DEAD: u32 = 1;
    /// iceoryx2 emits it when a publisher's notifier is dropped (it left).
    pub const NOTIFIER_DROPPED: u32 = 2;
    /// Largest event id on a data service.
    pub const ID_MAX: u32 = 7;
    /// The coordinator's `go` on `<HANDSHAKE>/go`.
    pub const GO: u32 = 3;
    /// A participant notifies `<HANDSHAKE>/ready` with this + its role id.
    pub const HANDSHAKE_ID_OFFSET: u32 = 8;
}

/// A `#define` of the header.
#[derive(Debug, Clone, PartialEq)]
pub enum Define {
    /// A heading comment before the next defines.
    Section(&'static str),
    /// An unsigned integer constant.
    Int(String, u64),
    /// A string constant.
    Str(String, String),
}

fn ints(out: &mut Vec<Define>, prefix: &str, items: &[(&str, u32)]) {
    for (n, v) in items {
        out.push(Define::Int(format!("{prefix}{n}"), u64::from(*v)));
    }
}

/// Every constant of the header, in order.
pub fn defines() -> Vec<Define> {
    use Define::*;
    let mut d = vec![
        Section("Array lengths"),
        Int("SC_N_JOINTS".into(), N_JOINTS as u64),
        Int(
            "SC_N_CONSTRAINTS_TRANSLATIONAL".into(),
            N_CONSTRAINTS_TRANSLATIONAL as u64,
        ),
        Int(
            "SC_N_CONSTRAINTS_ATTITUDE".into(),
            N_CONSTRAINTS_ATTITUDE as u64,
        ),
        Int(
            "SC_N_CONSTRAINTS_ROBOTIC".into(),
            N_CONSTRAINTS_ROBOTIC as u64,
        ),
        Int("SC_N_BARRIERS".into(), N_BARRIERS as u64),
        Section(
            "Service names (relative: a run's iceoryx2 global.prefix is \"sc_<SC_RUN_ID>_\"). Each pub/sub service has an event service of the same name.",
        ),
    ];
    let named = [
        ("TICK", services::TICK),
        ("CONTROL", services::CONTROL),
        ("SIM_STATE", services::SIM_STATE),
        ("PARTNER_STATE", services::PARTNER_STATE),
        ("NOMINAL_TRANSLATIONAL", services::NOMINAL_TRANSLATIONAL),
        ("NOMINAL_ATTITUDE", services::NOMINAL_ATTITUDE),
        ("NOMINAL_ROBOTIC", services::NOMINAL_ROBOTIC),
        ("SAFE_TRANSLATIONAL", services::SAFE_TRANSLATIONAL),
        ("SAFE_ATTITUDE", services::SAFE_ATTITUDE),
        ("SAFE_ROBOTIC", services::SAFE_ROBOTIC),
        ("STEP_RESULT", services::STEP_RESULT),
        ("HEALTH", services::HEALTH),
        ("STAGE_DEADLINE", services::STAGE_DEADLINE),
        ("PREPARE", services::PREPARE),
        ("HANDSHAKE", services::HANDSHAKE),
    ];
    for (n, s) in named {
        d.push(Str(format!("SC_SERVICE_{n}"), s.as_str().into()));
    }
    d.push(Str(
        "SC_SERVICE_HANDSHAKE_READY".into(),
        format!("{}/ready", services::HANDSHAKE),
    ));
    d.push(Str(
        "SC_SERVICE_HANDSHAKE_GO".into(),
        format!("{}/go", services::HANDSHAKE),
    ));
    d.push(Section(
        "iceoryx2 type names: give them when opening a service (iceoryx2 matches types by name, size and alignment)",
    ));
    for s in structs() {
        d.push(Str(
            format!("SC_TYPE_NAME_{}", upper_snake(s.name)),
            s.type_name.into(),
        ));
    }
    d.push(Section("Event ids"));
    ints(
        &mut d,
        "SC_EVENT_",
        &[
            ("SAMPLE", events::SAMPLE),
            ("NOTIFIER_DEAD", events::NOTIFIER_DEAD),
            ("NOTIFIER_DROPPED", events::NOTIFIER_DROPPED),
            ("ID_MAX", events::ID_MAX),
            ("GO", events::GO),
            ("HANDSHAKE_ID_OFFSET", events::HANDSHAKE_ID_OFFSET),
        ],
    );
    d.push(Section(
        "due_mask bits (Tick, SimState): the subsystems due in a tick",
    ));
    ints(
        &mut d,
        "SC_DUE_",
        &[
            ("TRANSLATIONAL", due::TRANSLATIONAL),
            ("ATTITUDE", due::ATTITUDE),
            ("ROBOTIC", due::ROBOTIC),
            ("ALL", due::ALL),
        ],
    );
    d.push(Section("Tick.command"));
    ints(
        &mut d,
        "SC_TICK_",
        &[("STEP", tick_command::STEP), ("STOP", tick_command::STOP)],
    );
    d.push(Section("Tick.clock_mode"));
    ints(
        &mut d,
        "SC_CLOCK_",
        &[
            ("LOCK_STEP", clock_mode::LOCK_STEP),
            ("REAL_TIME", clock_mode::REAL_TIME),
            ("SCALED", clock_mode::SCALED),
        ],
    );
    d.push(Section("StepResult.end"));
    ints(
        &mut d,
        "SC_END_",
        &[
            ("RUNNING", end::RUNNING),
            ("CAPTURED", end::CAPTURED),
            ("TIMEOUT", end::TIMEOUT),
            ("SIMULATOR_FAILED", end::SIMULATOR_FAILED),
        ],
    );
    d.push(Section(
        "StepResult.fault_flags, Health.last_fault_flags bits",
    ));
    ints(
        &mut d,
        "SC_FAULT_",
        &[
            ("STALE_INPUT", fault::STALE_INPUT),
            ("NON_FINITE_INPUT", fault::NON_FINITE_INPUT),
            ("SOLVER_FAILED", fault::SOLVER_FAILED),
            ("INFEASIBLE", fault::INFEASIBLE),
            ("SATURATED", fault::SATURATED),
            ("NOMINAL_MISSING", fault::NOMINAL_MISSING),
            ("DEADLINE_MISS", fault::DEADLINE_MISS),
            ("PEER_DEAD", fault::PEER_DEAD),
            ("REJECTED_COMMAND", fault::REJECTED_COMMAND),
        ],
    );
    d.push(Section(
        "Role ids (Health.role; the handshake id is SC_EVENT_HANDSHAKE_ID_OFFSET + role)",
    ));
    for r in &ROLES {
        d.push(Define::Int(
            format!("SC_ROLE_{}", r.constant_name()),
            r.id().into(),
        ));
    }
    d.push(Section("Health.state"));
    ints(
        &mut d,
        "SC_HEALTH_",
        &[
            ("STARTING", health_state::STARTING),
            ("READY", health_state::READY),
            ("RUNNING", health_state::RUNNING),
            ("FAULTED", health_state::FAULTED),
            ("STOPPING", health_state::STOPPING),
        ],
    );
    d
}

/// `SimState` -> `SIM_STATE`.
fn upper_snake(name: &str) -> String {
    let mut s = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_uppercase());
    }
    s
}

/// The header's text.
pub fn render() -> String {
    let mut h = String::new();
    for line in [
        "/* safe_capture_icd.h -- the safe-capture ICD (docs/ICD.md) for C and C++ partners.",
        " *",
        " * GENERATED from the Rust crate sc-icd (libs/icd/src/c_header.rs); do not edit.",
        " * Regenerate: SC_WRITE_C_HEADER=1 cargo test -p sc-icd --test c_header",
        " *",
        " * Every message is the #[repr(C)] Rust struct of the same name: fixed size, 8-byte",
        " * aligned, no implicit padding (explicit _pad* fields are 0). Units and frames of",
        " * every field: docs/ICD.md and `cargo doc -p sc-icd`. Transport: iceoryx2 0.10.",
        " */",
        "#ifndef SAFE_CAPTURE_ICD_H",
        "#define SAFE_CAPTURE_ICD_H",
        "",
        "#include <stddef.h>",
        "#include <stdint.h>",
        "",
        "#ifdef __cplusplus",
        "#define SC_ICD_STATIC_ASSERT(cond, msg) static_assert(cond, msg)",
        "#define SC_ICD_ALIGNOF(t) alignof(t)",
        "extern \"C\" {",
        "#else",
        "#define SC_ICD_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)",
        "#define SC_ICD_ALIGNOF(t) _Alignof(t)",
        "#endif",
    ] {
        h.push_str(line);
        h.push('\n');
    }
    for d in defines() {
        match d {
            Define::Section(s) => h.push_str(&format!("\n/* {s} */\n")),
            Define::Int(n, v) => h.push_str(&format!("#define {n} {v}u\n")),
            Define::Str(n, v) => h.push_str(&format!("#define {n} \"{v}\"\n")),
        }
    }
    for s in structs() {
        let c = s.c_name();
        h.push_str(&format!(
            "\n/* {} -- {}, {} B. {} */\ntypedef struct {c} {{\n",
            s.name, s.type_name, s.size, s.doc
        ));
        for f in &s.fields {
            match f.len {
                None => h.push_str(&format!("    {} {};\n", f.scalar, f.name)),
                Some(n) => h.push_str(&format!("    {} {}[{n}];\n", f.scalar, f.name)),
            }
        }
        h.push_str(&format!(
            "#if defined(__cplusplus) && __cplusplus >= 201703L\n    \
             /* the name iceoryx2's C++ API matches the payload type by */\n    \
             static constexpr const char* IOX2_TYPE_NAME = \"{}\";\n\
             #endif\n}} {c};\n",
            s.type_name
        ));
        h.push_str(&format!(
            "SC_ICD_STATIC_ASSERT(sizeof({c}) == {}, \"{c}: size\");\n\
             SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF({c}) == {}, \"{c}: alignment\");\n",
            s.size, s.align
        ));
        for f in &s.fields {
            h.push_str(&format!(
                "SC_ICD_STATIC_ASSERT(offsetof({c}, {}) == {}, \"{c}.{}: offset\");\n",
                f.name, f.offset, f.name
            ));
        }
    }
    h.push_str("\n#ifdef __cplusplus\n}\n#endif\n\n#endif /* SAFE_CAPTURE_ICD_H */\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_cover_every_byte() {
        // the name lists of `structs` are complete: fields contiguous, filling the struct
        let all = structs();
        assert_eq!(all.len(), services::ALL.len() - 2, "one per message type");
        for s in all {
            let mut end = 0;
            for f in &s.fields {
                assert_eq!(
                    f.offset, end,
                    "{}.{}: gap or overlap before it",
                    s.name, f.name
                );
                let scalar = if f.scalar == "double" || f.scalar == "uint64_t" {
                    8
                } else {
                    4
                };
                assert_eq!(f.size, scalar * f.len.unwrap_or(1), "{}.{}", s.name, f.name);
                end = f.offset + f.size;
            }
            assert_eq!(
                end, s.size,
                "{}: trailing padding or missing fields",
                s.name
            );
        }
    }

    #[test]
    fn upper_snake_names() {
        assert_eq!(upper_snake("SimState"), "SIM_STATE");
        assert_eq!(upper_snake("Tick"), "TICK");
    }
}
