//! The ICD as a Python module of the partner SDK (`scripts/python/sc_partner/_icd.py`):
//! each message a `ctypes.Structure` with exactly the Rust layout and a static
//! `type_name()`, each field with its unit, frame and meaning; the constants with the
//! values and names of the C header without its `SC_` prefix (`DUE_ROBOTIC`,
//! `SERVICE_SIM_STATE`, `ROLE_RECORDER`). `sc_partner.icd` re-exports it with its
//! helpers; `libs/icd/tests/python_layout.rs` checks the layout and every constant
//! against Rust by running Python.

use crate::field_line;
use sc_icd::spec::{ConstGroup, MessageSpec, Scalar};
use sc_icd::{CONSTANT_GROUPS, MESSAGES, ROLES, services::SERVICES};
use std::fmt::Write as _;

/// Where the module lives, relative to the repository's root.
pub const PATH: &str = "scripts/python/sc_partner/_icd.py";

/// The `ctypes` spelling of a scalar.
pub fn ctype(s: Scalar) -> &'static str {
    match s {
        Scalar::F64 => "ctypes.c_double",
        Scalar::U64 => "ctypes.c_uint64",
        Scalar::U32 => "ctypes.c_uint32",
        Scalar::I32 => "ctypes.c_int32",
    }
}

/// `text` as a Python string literal (double quotes).
fn string(text: &str) -> String {
    format!("\"{}\"", text.replace('\\', "\\\\").replace('"', "\\\""))
}

/// `text` as the body of a one-paragraph docstring.
fn docstring(text: &str) -> String {
    text.replace('\\', "\\\\").replace("\"\"\"", "\\\"\\\"\\\"")
}

fn header(py: &mut String) {
    py.push_str(
        "\"\"\"The safe-capture ICD (docs/ICD.md): messages as ctypes structures, and constants.\n\
         \n\
         GENERATED from the Rust crate sc-icd by sc-icd-gen (libs/icd-gen/src/python.rs); do not\n\
         edit. Regenerate: SC_WRITE_ICD=1 cargo test -p sc-icd-gen\n\
         \n\
         Use it through :mod:`sc_partner.icd`, which re-exports every name and adds helpers.\n\
         Each field's comment gives its unit in brackets, its frame and its meaning.\n\
         \"\"\"\n\nimport ctypes\n",
    );
}

fn group(py: &mut String, names: &mut Vec<String>, g: &ConstGroup) {
    let _ = write!(py, "\n# {}\n", g.doc);
    for c in g.items {
        let name = g.qualified(c);
        let _ = writeln!(py, "{name} = {}  # {}", c.value, c.doc);
        names.push(name);
    }
}

fn services(py: &mut String, names: &mut Vec<String>) {
    py.push_str(
        "\n# Service names (relative: a run's iceoryx2 global.prefix is \"sc_<SC_RUN_ID>_\").\n\
         # Each pub/sub service has an event service of the same name.\n",
    );
    for s in SERVICES {
        let what = match s.message {
            Some(m) => format!("{}, QoS {}", m.name, s.qos.name()),
            None => s.qos.name().to_string(),
        };
        let name = format!("SERVICE_{}", s.constant);
        let _ = writeln!(py, "{name} = {}  # {what}", string(s.name.as_str()));
        names.push(name.clone());
        for sub in s.sub_services {
            let sub_name = format!("{name}_{}", sub.to_ascii_uppercase());
            let value = format!("{}/{sub}", s.name);
            let _ = writeln!(py, "{sub_name} = {}", string(&value));
            names.push(sub_name);
        }
    }
    py.push_str(
        "# QoS class of each service: \"flight\" (sc_bus.PARTITION), \"partner\" (sc_bus.NOMINAL, newest wins),\n\
         # \"event only\".\nSERVICE_QOS = {\n",
    );
    for s in SERVICES {
        let _ = writeln!(py, "    SERVICE_{}: {},", s.constant, string(s.qos.name()));
    }
    py.push_str("}\n");
    names.push("SERVICE_QOS".into());
}

fn roles(py: &mut String, names: &mut Vec<String>) {
    py.push_str(
        "\n# Role ids, from the role table (sc_icd::ROLES, start order): Health.role; a participant\n\
         # announces EVENT_HANDSHAKE_ID_OFFSET + role in the handshake.\n",
    );
    for r in &ROLES {
        let name = format!("ROLE_{}", r.constant_name());
        let _ = writeln!(py, "{name} = {}  # {}", r.id(), r.doc);
        names.push(name);
    }
    py.push_str(
        "# The role names (config keys, node names), indexed by role id.\nROLE_NAMES = (\n",
    );
    for r in &ROLES {
        let _ = writeln!(py, "    {},", string(r.name));
    }
    py.push_str(")\n");
    names.push("ROLE_NAMES".into());
}

fn message(py: &mut String, m: &MessageSpec) {
    let _ = write!(
        py,
        "\n\nclass {}(ctypes.Structure):\n    \"\"\"{}\"\"\"\n\n    _fields_ = [\n",
        m.name,
        docstring(m.doc)
    );
    for f in m.fields {
        let ty = match f.len {
            None => ctype(f.scalar).to_string(),
            Some(n) => format!("{} * {n}", ctype(f.scalar)),
        };
        let _ = writeln!(
            py,
            "        ({}, {ty}),  # {}",
            string(f.name),
            field_line(f)
        );
    }
    let _ = write!(
        py,
        "    ]\n\n    @staticmethod\n    def type_name():\n        return {}\n",
        string(m.type_name)
    );
}

/// The module's text.
pub fn render() -> String {
    let mut py = String::new();
    let mut names = Vec::new();
    header(&mut py);
    let (lengths, others) = CONSTANT_GROUPS.split_at(1);
    group(&mut py, &mut names, lengths[0]);
    services(&mut py, &mut names);
    for g in others {
        group(&mut py, &mut names, g);
    }
    roles(&mut py, &mut names);
    for m in MESSAGES {
        message(&mut py, m);
        names.push(m.name.to_string());
    }
    py.push_str("\n\n# Every message type, in the order of docs/ICD.md.\nALL_TYPES = [\n");
    for m in MESSAGES {
        let _ = writeln!(py, "    {},", m.name);
    }
    py.push_str("]\n\n__all__ = [\n");
    names.push("ALL_TYPES".into());
    for n in names {
        let _ = writeln!(py, "    {},", string(&n));
    }
    py.push_str("]\n");
    py
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_escaped() {
        assert_eq!(string("a\"b\\c"), "\"a\\\"b\\\\c\"");
        assert_eq!(docstring("x \"\"\" y"), "x \\\"\\\"\\\" y");
    }

    #[test]
    fn module_names_every_role_and_message() {
        let py = render();
        for r in &ROLES {
            assert!(py.contains(&format!("\nROLE_{} = {}  #", r.constant_name(), r.id())));
        }
        for m in MESSAGES {
            assert!(py.contains(&format!("\nclass {}(ctypes.Structure):", m.name)));
        }
        assert!(py.contains("\nDUE_ALL = 7  #"));
    }
}
