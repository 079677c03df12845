//! The Python module of the partner SDK (`scripts/python/sc_partner/icd.py`, which
//! re-exports the generated `_icd.py`) must have exactly the Rust layout — same size,
//! alignment, field names, offsets and sizes, and the same iceoryx2 type name — and
//! every constant of the ICD with the Rust value: array lengths, services, event ids,
//! due bits, tick commands, clock modes, end codes, fault bits, health states and the
//! role ids of the role table. Checked by running Python (standard library only).

use sc_icd::{CONSTANT_GROUPS, MESSAGES, ROLES, services::SERVICES};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

/// `python3 -m sc_partner.icd <flag>`, run from the package's source tree, as JSON.
fn python_json(flag: &str) -> Value {
    let package = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scripts/python");
    let out = Command::new("python3")
        .current_dir(&package)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .args(["-m", "sc_partner.icd", flag])
        .output()
        .expect("python3 must be installed to check the Python ICD module");
    assert!(
        out.status.success(),
        "sc_partner.icd {flag} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

#[test]
fn python_module_matches_rust_layout() {
    let py = python_json("--layout-json");
    let py = py.as_object().expect("object of types");
    assert_eq!(
        py.len(),
        MESSAGES.len(),
        "Python and Rust define different message sets"
    );
    for m in MESSAGES {
        let p = py
            .get(m.name)
            .unwrap_or_else(|| panic!("{} missing in sc_partner.icd", m.name));
        assert_eq!(p["type_name"].as_str(), Some(m.type_name), "{}", m.name);
        assert_eq!(p["size"].as_u64(), Some(m.size as u64), "{} size", m.name);
        assert_eq!(
            p["align"].as_u64(),
            Some(m.align as u64),
            "{} align",
            m.name
        );
        let py_fields: Vec<(String, u64, u64)> = p["fields"]
            .as_array()
            .expect("fields")
            .iter()
            .map(|f| {
                (
                    f["name"].as_str().unwrap_or_default().to_string(),
                    f["offset"].as_u64().unwrap_or(u64::MAX),
                    f["size"].as_u64().unwrap_or(u64::MAX),
                )
            })
            .collect();
        let rs_fields: Vec<(String, u64, u64)> = m
            .fields
            .iter()
            .map(|f| (f.name.to_string(), f.offset as u64, f.size() as u64))
            .collect();
        assert_eq!(
            py_fields, rs_fields,
            "{} fields (name, offset, size)",
            m.name
        );
    }
}

/// Every constant the Python module must have, by its Python name.
fn rust_constants() -> BTreeMap<String, Value> {
    let mut c = BTreeMap::new();
    for g in CONSTANT_GROUPS {
        for item in g.items {
            c.insert(g.qualified(item), item.value.into());
        }
    }
    for s in SERVICES {
        let name = format!("SERVICE_{}", s.constant);
        for sub in s.sub_services {
            let sub_name = format!("{name}_{}", sub.to_ascii_uppercase());
            c.insert(sub_name, format!("{}/{sub}", s.name).into());
        }
        c.insert(name, s.name.as_str().into());
    }
    for r in &ROLES {
        c.insert(format!("ROLE_{}", r.constant_name()), r.id().into());
    }
    c
}

#[test]
fn python_constants_are_the_rust_ones() {
    let py = python_json("--constants-json");
    let py = py.as_object().expect("object of constants");
    let rust = rust_constants();
    let mut bad = Vec::new();
    for (name, value) in &rust {
        if py.get(name) != Some(value) {
            bad.push(format!("{name}: Rust {value}, Python {:?}", py.get(name)));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
    // the role names, in id order, are the role table's
    let names: Vec<&str> = ROLES.iter().map(|r| r.name).collect();
    assert_eq!(py["ROLE_NAMES"], serde_json::json!(names));
    // the comparison covers every group, every service and every role
    assert!(rust.contains_key("DUE_ALL") && rust.contains_key("HEALTH_STOPPING"));
    assert!(rust.contains_key("SERVICE_HANDSHAKE_GO") && rust.contains_key("ROLE_RECORDER"));
}
