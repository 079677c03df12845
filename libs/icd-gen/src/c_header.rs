//! The ICD as a C header for C/C++ partners (`libs/icd/include/safe_capture_icd.h`):
//! every message as a `typedef struct Sc<Name>` with the Rust layout (each field with
//! its unit, frame and meaning; `_Static_assert`s of every size, alignment and offset),
//! and every constant a partner needs ([`defines`]): array lengths, service and type
//! names, event ids, due bits, tick commands, clock modes, end codes, fault bits,
//! health states and the role ids of the role table.
//!
//! `tests/c_header.rs` compiles a C program against the committed header that prints
//! every size, alignment, offset and constant and compares them with the Rust values,
//! and compiles the header as C++17.

use crate::{field_line, upper_snake};
use sc_icd::spec::{ConstGroup, MessageSpec, Scalar};
use sc_icd::{CONSTANT_GROUPS, MESSAGES, ROLES, services::SERVICES};
use std::fmt::Write as _;

/// Where the header lives, relative to the repository's root.
pub const PATH: &str = "libs/icd/include/safe_capture_icd.h";

/// A `#define` of the header.
#[derive(Debug, Clone, PartialEq)]
pub enum Define {
    /// A heading comment before the next defines.
    Section(String),
    /// An unsigned integer constant, with what it means (empty: nothing to add).
    Int(String, u64, String),
    /// A string constant, with what it means (empty: nothing to add).
    Str(String, String, String),
}

/// The C spelling of a scalar (`<stdint.h>` names, `double`).
pub fn c_scalar(s: Scalar) -> &'static str {
    match s {
        Scalar::F64 => "double",
        Scalar::U64 => "uint64_t",
        Scalar::U32 => "uint32_t",
        Scalar::I32 => "int32_t",
    }
}

/// The C type name of a message.
pub fn c_name(m: &MessageSpec) -> String {
    format!("Sc{}", m.name)
}

/// `text` safe inside a C comment.
fn comment(text: &str) -> String {
    text.replace("*/", "* /")
}

fn group(d: &mut Vec<Define>, g: &ConstGroup) {
    d.push(Define::Section(g.doc.to_string()));
    for c in g.items {
        d.push(Define::Int(
            format!("SC_{}", g.qualified(c)),
            c.value,
            c.doc.to_string(),
        ));
    }
}

fn services(d: &mut Vec<Define>) {
    d.push(Define::Section(
        "Service names (relative: a run's iceoryx2 global.prefix is \"sc_<SC_RUN_ID>_\"). Each pub/sub service has an event service of the same name.".into(),
    ));
    for s in SERVICES {
        let what = match s.message {
            Some(m) => format!("{}, QoS {}", m.name, s.qos.name()),
            None => s.qos.name().to_string(),
        };
        d.push(Define::Str(
            format!("SC_SERVICE_{}", s.constant),
            s.name.as_str().into(),
            what,
        ));
    }
    for s in SERVICES {
        for sub in s.sub_services {
            d.push(Define::Str(
                format!("SC_SERVICE_{}_{}", s.constant, sub.to_ascii_uppercase()),
                format!("{}/{sub}", s.name),
                format!("event service `{sub}` of SC_SERVICE_{}", s.constant),
            ));
        }
    }
}

fn type_names(d: &mut Vec<Define>) {
    d.push(Define::Section(
        "iceoryx2 type names: give them when opening a service (iceoryx2 matches types by name, size and alignment)".into(),
    ));
    for m in MESSAGES {
        d.push(Define::Str(
            format!("SC_TYPE_NAME_{}", upper_snake(m.name)),
            m.type_name.into(),
            String::new(),
        ));
    }
}

fn roles(d: &mut Vec<Define>) {
    d.push(Define::Section(
        "Role ids, from the role table (sc_icd::ROLES, start order): Health.role; the handshake id is SC_EVENT_HANDSHAKE_ID_OFFSET + role".into(),
    ));
    for r in &ROLES {
        d.push(Define::Int(
            format!("SC_ROLE_{}", r.constant_name()),
            r.id().into(),
            format!("{}: {}", r.name, r.doc),
        ));
    }
}

/// Every constant of the header, in order: array lengths, services, type names, the
/// other constant groups, the roles.
pub fn defines() -> Vec<Define> {
    let mut d = Vec::new();
    let (lengths, others) = CONSTANT_GROUPS.split_at(1);
    group(&mut d, lengths[0]);
    services(&mut d);
    type_names(&mut d);
    for g in others {
        group(&mut d, g);
    }
    roles(&mut d);
    d
}

/// The header's opening: what it is, how it is made, the portability macros.
fn preamble() -> String {
    let mut h = String::new();
    for line in [
        "/* safe_capture_icd.h -- the safe-capture ICD (docs/ICD.md) for C and C++ partners.",
        " *",
        " * GENERATED from the Rust crate sc-icd by sc-icd-gen (libs/icd-gen/src/c_header.rs);",
        " * do not edit. Regenerate: SC_WRITE_ICD=1 cargo test -p sc-icd-gen",
        " *",
        " * Every message is the #[repr(C)] Rust struct of the same name: fixed size, 8-byte",
        " * aligned, no implicit padding (explicit _pad* fields are 0). Units and frames of",
        " * every field: the comment after it ([unit], frame, meaning), docs/ICD.md and",
        " * `cargo doc -p sc-icd`. Transport: iceoryx2 0.10.",
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
    h
}

/// One message: the struct with a comment per field, its C++ type name, the asserts.
fn message(h: &mut String, m: &MessageSpec) {
    let c = c_name(m);
    let _ = write!(
        h,
        "\n/* {} -- {}, {} B. {} */\ntypedef struct {c} {{\n",
        m.name,
        m.type_name,
        m.size,
        comment(m.doc)
    );
    for f in m.fields {
        let decl = match f.len {
            None => format!("{} {};", c_scalar(f.scalar), f.name),
            Some(n) => format!("{} {}[{n}];", c_scalar(f.scalar), f.name),
        };
        let _ = writeln!(h, "    {decl} /* {} */", comment(&field_line(f)));
    }
    let _ = write!(
        h,
        "#if defined(__cplusplus) && __cplusplus >= 201703L\n    \
         /* the name iceoryx2's C++ API matches the payload type by */\n    \
         static constexpr const char* IOX2_TYPE_NAME = \"{}\";\n\
         #endif\n}} {c};\n",
        m.type_name
    );
    let _ = write!(
        h,
        "SC_ICD_STATIC_ASSERT(sizeof({c}) == {}, \"{c}: size\");\n\
         SC_ICD_STATIC_ASSERT(SC_ICD_ALIGNOF({c}) == {}, \"{c}: alignment\");\n",
        m.size, m.align
    );
    for f in m.fields {
        let _ = writeln!(
            h,
            "SC_ICD_STATIC_ASSERT(offsetof({c}, {}) == {}, \"{c}.{}: offset\");",
            f.name, f.offset, f.name
        );
    }
}

/// ` /* doc */` after a define, or nothing without a doc.
fn trailing(doc: &str) -> String {
    if doc.is_empty() {
        String::new()
    } else {
        format!(" /* {} */", comment(doc))
    }
}

/// The header's text.
pub fn render() -> String {
    let mut h = preamble();
    for d in defines() {
        let _ = match d {
            Define::Section(s) => write!(h, "\n/* {} */\n", comment(&s)),
            Define::Int(n, v, doc) => writeln!(h, "#define {n} {v}u{}", trailing(&doc)),
            Define::Str(n, v, doc) => writeln!(h, "#define {n} \"{v}\"{}", trailing(&doc)),
        };
    }
    for m in MESSAGES {
        message(&mut h, m);
    }
    h.push_str("\n#ifdef __cplusplus\n}\n#endif\n\n#endif /* SAFE_CAPTURE_ICD_H */\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_cannot_close_early() {
        assert_eq!(comment("a */ b"), "a * / b");
    }

    /// The constants' names and values are the Rust ones.
    #[test]
    fn defines_name_the_rust_constants() {
        let d = defines();
        let int = |name: &str| {
            d.iter().find_map(|x| match x {
                Define::Int(n, v, _) if n == name => Some(*v),
                _ => None,
            })
        };
        assert_eq!(int("SC_DUE_ROBOTIC"), Some(sc_icd::due::ROBOTIC.into()));
        assert_eq!(int("SC_N_BARRIERS"), Some(sc_icd::N_BARRIERS as u64));
        assert_eq!(int("SC_EVENT_HANDSHAKE_ID_OFFSET"), Some(8));
        assert_eq!(int("SC_ROLE_RECORDER"), Some(8));
        assert!(d.contains(&Define::Str(
            "SC_SERVICE_HANDSHAKE_GO".into(),
            "safe_capture/handshake/go".into(),
            "event service `go` of SC_SERVICE_HANDSHAKE".into()
        )));
    }
}
