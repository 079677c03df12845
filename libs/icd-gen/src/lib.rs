//! The ICD's artefacts, generated from its one declaration in `sc-icd` (messages with
//! units, frames and meaning of every field, constant groups, services) and the role
//! table `sc_icd::ROLES`:
//!
//! * [`c_header`]: `libs/icd/include/safe_capture_icd.h`, for C and C++ partners;
//! * [`python`]: `scripts/python/sc_partner/_icd.py`, the messages and constants of the
//!   partner SDK (re-exported by `sc_partner.icd`);
//! * [`docs`]: the generated sections of `docs/ICD.md` (roles, services, constants,
//!   messages), between markers, the prose around them kept;
//! * [`json_schema`]: the JSON schema of each message, as the recorder writes it into
//!   its MCAP channels (at run time, not a file).
//!
//! The files are checked in; `tests/generated.rs` fails when one differs from what
//! [`ARTEFACTS`] render now, and `SC_WRITE_ICD=1 cargo test -p sc-icd-gen` rewrites them.
//! A ground crate: the flight software never links it.

pub mod barriers;
pub mod c_header;
pub mod docs;
pub mod json_schema;
pub mod python;

use std::path::{Path, PathBuf};

/// The environment variable that makes the freshness tests rewrite the artefacts.
pub const WRITE_ENV: &str = "SC_WRITE_ICD";
/// The command that rewrites every artefact after a change of the ICD.
pub const REGENERATE: &str = "SC_WRITE_ICD=1 cargo test -p sc-icd-gen";

/// What can go wrong while generating.
#[derive(Debug, thiserror::Error)]
pub enum GenError {
    /// A generated section's markers are missing or out of order in a hand-kept file.
    #[error("{file}: generated section `{section}`: {problem}")]
    Markers {
        file: String,
        section: &'static str,
        problem: &'static str,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// One generated file: where it lives and how its text is made.
#[derive(Debug, Clone, Copy)]
pub struct Artefact {
    /// Path relative to the repository's root.
    pub path: &'static str,
    /// The text the file must hold, given the text it holds now (files with generated
    /// sections keep their prose; wholly generated files ignore it).
    pub render: fn(&str) -> Result<String, GenError>,
}

/// Every generated file.
pub const ARTEFACTS: [Artefact; 3] = [
    Artefact {
        path: c_header::PATH,
        render: |_| Ok(c_header::render()),
    },
    Artefact {
        path: python::PATH,
        render: |_| Ok(python::render()),
    },
    Artefact {
        path: docs::PATH,
        render: docs::render,
    },
];

/// The repository's root (this crate lives in `libs/icd-gen`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The committed text of `a` and the text it must hold now.
pub fn committed_and_wanted(a: &Artefact) -> Result<(String, String), GenError> {
    let path = repo_root().join(a.path);
    let committed = std::fs::read_to_string(&path).map_err(|source| GenError::Io {
        path: path.clone(),
        source,
    })?;
    let wanted = (a.render)(&committed)?;
    Ok((committed, wanted))
}

/// Writes what `a` must hold now.
pub fn write(a: &Artefact) -> Result<(), GenError> {
    let path = repo_root().join(a.path);
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    let text = (a.render)(&current)?;
    std::fs::write(&path, text).map_err(|source| GenError::Io { path, source })
}

/// `SimState` → `SIM_STATE` (C and Python constant names of a message).
pub fn upper_snake(name: &str) -> String {
    let mut s = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_uppercase());
    }
    s
}

/// A field's frame as text after its meaning (`, frame F_H`; empty without one).
pub fn frame_suffix(f: &sc_icd::spec::FieldSpec) -> String {
    match f.frame {
        sc_icd::spec::Frame::None => String::new(),
        fr => format!(", frame {}", fr.symbol()),
    }
}

/// A field's meaning with the values of its constant group, if it has one
/// (`…, bits of `due` (1 translational, 2 attitude, 4 robotic, 7 all)`).
pub fn meaning(f: &sc_icd::spec::FieldSpec) -> String {
    let Some(g) = f.values else {
        return f.meaning.to_string();
    };
    let values: Vec<String> = g
        .items
        .iter()
        .map(|c| {
            format!(
                "{} {}",
                c.value,
                c.name.to_ascii_lowercase().replace('_', " ")
            )
        })
        .collect();
    format!("{} ({})", f.meaning, values.join(", "))
}

/// The one-line description of a field: meaning (with its values), frame, unit in brackets.
pub fn field_line(f: &sc_icd::spec::FieldSpec) -> String {
    format!("{}{} [{}]", meaning(f), frame_suffix(f), f.unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upper_snake_names() {
        assert_eq!(upper_snake("SimState"), "SIM_STATE");
        assert_eq!(upper_snake("Tick"), "TICK");
    }

    #[test]
    fn field_lines_carry_values() {
        use sc_icd::Message;
        let f = sc_icd::StepResult::SPEC.field("held_mask").unwrap();
        assert!(
            field_line(f).ends_with("(1 translational, 2 attitude, 4 robotic, 7 all) [-]"),
            "{}",
            field_line(f)
        );
    }

    #[test]
    fn field_lines_carry_frame_and_unit() {
        use sc_icd::Message;
        let f = sc_icd::SimState::SPEC.field("r_h").unwrap();
        assert_eq!(
            field_line(f),
            "Servicer base origin relative to the target CoM, r_H, frame F_H [m]"
        );
    }
}
