//! The Python mirror (`scripts/python/sc_partner/icd.py`) must have exactly the Rust layout:
//! same size, alignment, field names, offsets and sizes, and the same iceoryx2 type name.

use core::mem::{align_of, offset_of, size_of};
use sc_icd::*;
use std::path::PathBuf;
use std::process::Command;

struct Layout {
    name: &'static str,
    type_name: &'static str,
    size: usize,
    align: usize,
    fields: Vec<(&'static str, usize, usize)>,
}

fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
    size_of::<F>()
}

macro_rules! layout {
    ($t:ident { $($f:ident),* $(,)? }) => {
        Layout {
            name: stringify!($t),
            type_name: type_name_of::<$t>(),
            size: size_of::<$t>(),
            align: align_of::<$t>(),
            fields: vec![$((stringify!($f), offset_of!($t, $f), field_size(|s: &$t| &s.$f))),*],
        }
    };
}

fn rust_layouts() -> Vec<Layout> {
    vec![
        layout!(Tick {
            tick,
            due_mask,
            clock_mode,
            t,
            send_ns,
            command,
            _pad0
        }),
        layout!(SimState {
            tick,
            t,
            due_mask,
            _pad0,
            tick_send_ns,
            recv_ns,
            publish_ns,
            step,
            r_h,
            v_h,
            r_r,
            v_r,
            q_hr,
            omega_h,
            omega_dot_h,
            mean_motion,
            q_rb,
            omega_b,
            theta,
            theta_dot,
            q_rt,
            omega_t,
            omega_dot_t,
            grasp_r,
            grasp_v_r,
            grasp_a_r,
            grasp_b,
            ee_b,
            ee_r,
            ee_v_r,
            com_h,
            com_v_h,
            com_r,
            com_v_r,
            barriers,
            barriers_between
        }),
        layout!(NominalTranslational {
            tick,
            t,
            valid,
            phase,
            recv_ns,
            publish_ns,
            f_h
        }),
        layout!(NominalAttitude {
            tick,
            t,
            valid,
            phase,
            recv_ns,
            publish_ns,
            tau_b
        }),
        layout!(NominalRobotic {
            tick,
            t,
            valid,
            phase,
            recv_ns,
            publish_ns,
            tau_m
        }),
        layout!(SafeTranslational {
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
        }),
        layout!(SafeAttitude {
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
        }),
        layout!(SafeRobotic {
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
        }),
        layout!(StepResult {
            tick,
            t,
            end,
            fallback_mask,
            held_mask,
            fault_flags,
            safe_recv_ns,
            publish_ns,
            force_b,
            torque_b,
            tau
        }),
        layout!(Health {
            role,
            pid,
            state,
            last_fault_flags,
            ticks_handled,
            deadline_misses,
            cycle_slips,
            last_tick,
            publish_ns
        }),
    ]
}

#[test]
fn rust_field_lists_cover_every_byte() {
    // Guards the lists above: fields are contiguous and fill the struct, so no
    // field can be missing from the comparison and no implicit padding exists.
    for l in rust_layouts() {
        let mut end = 0;
        for (name, off, size) in &l.fields {
            assert_eq!(*off, end, "{}.{name}: gap or overlap before it", l.name);
            end = off + size;
        }
        assert_eq!(
            end, l.size,
            "{}: trailing padding or missing fields",
            l.name
        );
    }
}

#[test]
fn python_mirror_matches_rust_layout() {
    // the module of the partner package, run from its source tree (standard library only)
    let package = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scripts/python");
    let out = Command::new("python3")
        .current_dir(&package)
        .args(["-m", "sc_partner.icd", "--layout-json"])
        .output()
        .expect("python3 must be installed to check the Python ICD mirror");
    assert!(
        out.status.success(),
        "sc_partner.icd failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let py: serde_json::Value = serde_json::from_slice(&out.stdout).expect("layout JSON");
    let py = py.as_object().expect("object of types");
    let rust = rust_layouts();
    assert_eq!(
        py.len(),
        rust.len(),
        "Python and Rust define different message sets"
    );
    for l in rust {
        let p = py
            .get(l.name)
            .unwrap_or_else(|| panic!("{} missing in sc_partner.icd", l.name));
        assert_eq!(
            p["type_name"].as_str(),
            Some(l.type_name),
            "{} type_name",
            l.name
        );
        assert_eq!(p["size"].as_u64(), Some(l.size as u64), "{} size", l.name);
        assert_eq!(
            p["align"].as_u64(),
            Some(l.align as u64),
            "{} align",
            l.name
        );
        let pf = p["fields"].as_array().expect("fields");
        let py_fields: Vec<(String, u64, u64)> = pf
            .iter()
            .map(|f| {
                (
                    f["name"].as_str().unwrap_or_default().to_string(),
                    f["offset"].as_u64().unwrap_or(u64::MAX),
                    f["size"].as_u64().unwrap_or(u64::MAX),
                )
            })
            .collect();
        let rs_fields: Vec<(String, u64, u64)> = l
            .fields
            .iter()
            .map(|(n, o, s)| (n.to_string(), *o as u64, *s as u64))
            .collect();
        assert_eq!(
            py_fields, rs_fields,
            "{} fields (name, offset, size)",
            l.name
        );
    }
}

#[test]
fn service_table_matches_type_names() {
    let names: Vec<&str> = services::ALL.iter().map(|(_, t)| *t).collect();
    for l in rust_layouts() {
        assert!(
            names.contains(&l.type_name),
            "{} has no service",
            l.type_name
        );
    }
}
