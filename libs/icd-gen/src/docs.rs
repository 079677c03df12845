//! The generated sections of docs/ICD.md: the roles, the services, the constants and
//! the messages (every field with offset, type, unit, frame and meaning), each between
//! a `<!-- BEGIN GENERATED <name> … -->` and an `<!-- END GENERATED <name> -->` line.
//! The prose around them is the file's own and kept as it is.

use crate::GenError;
use crate::barriers::{barrier_unit, components_line, constraint_names};
use sc_core::Subsystem;
use sc_icd::spec::{Components, ConstGroup, FieldSpec, MessageSpec, ServiceSpec};
use sc_icd::{CONSTANT_GROUPS, MESSAGES, ROLES, Rate, Role, RoleKind, services::SERVICES};
use std::fmt::Write as _;

/// Where the document lives, relative to the repository's root.
pub const PATH: &str = "docs/ICD.md";

/// A generated section: its name (in the markers) and what renders its content.
pub type Section = (&'static str, fn() -> String);

/// The generated sections, in the order they appear in the document.
pub const SECTIONS: [Section; 5] = [
    ("services", services),
    ("roles", roles),
    ("constants", constants),
    ("messages", messages),
    ("barriers", barriers),
];

/// The line that opens section `name`.
pub fn begin_marker(name: &str) -> String {
    format!(
        "<!-- BEGIN GENERATED {name}: written by sc-icd-gen from libs/icd ({}); edit the source, not this -->",
        crate::REGENERATE
    )
}

/// The line that closes section `name`.
pub fn end_marker(name: &str) -> String {
    format!("<!-- END GENERATED {name} -->")
}

/// `text` safe inside a Markdown table cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

fn role_list<'a>(roles: impl Iterator<Item = &'a Role>) -> String {
    let names: Vec<String> = roles.map(|r| format!("`{}`", r.name)).collect();
    if names.is_empty() {
        "—".into()
    } else {
        names.join(", ")
    }
}

fn service_row(t: &mut String, s: &ServiceSpec) {
    let message = match s.message {
        Some(m) => format!("`{}` ({} B)", m.type_name, m.size),
        None => "— (event only)".into(),
    };
    let subs: Vec<String> = s.sub_services.iter().map(|x| format!("`/{x}`")).collect();
    let name = if subs.is_empty() {
        format!("`{}`", s.name)
    } else {
        format!("`{}` ({})", s.name, subs.join(", "))
    };
    let _ = writeln!(
        t,
        "| {name} | {message} | {} | {} | {} | {} |",
        s.qos.name(),
        role_list(s.publishers()),
        role_list(s.subscribers()),
        cell(s.doc)
    );
}

/// The services: name, message, QoS, publisher and subscribers (from the role table).
pub fn services() -> String {
    let mut t = String::from(
        "| service | message (type name, size) | QoS | publisher | subscribers | what it is for |\n\
         |---|---|---|---|---|---|\n",
    );
    for s in SERVICES {
        service_row(&mut t, s);
    }
    t
}

fn kind(k: RoleKind) -> String {
    match k {
        RoleKind::Scheduler => "scheduler".into(),
        RoleKind::Simulator => "simulator".into(),
        RoleKind::Navigation => "navigation".into(),
        RoleKind::Nominal(s) => format!("nominal controller ({s})"),
        RoleKind::Filter(s) => format!("safety filter ({s})"),
        RoleKind::Recorder => "recorder".into(),
    }
}

fn rate(r: Rate) -> String {
    match r {
        Rate::Base => "every tick".into(),
        Rate::Group(s) => format!("{s} rate group"),
    }
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The role table: id, name, C and Python constants, executable, kind, rate, flight,
/// partner-replaceable, what it is.
pub fn roles() -> String {
    let mut t = String::from(
        "| id | role | C / Python constant | executable | kind | rate | flight | partner may replace | what it is |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &ROLES {
        let c = r.constant_name();
        let _ = writeln!(
            t,
            "| {} | `{}` | `SC_ROLE_{c}` / `ROLE_{c}` | `{}` | {} | {} | {} | {} | {} |",
            r.id(),
            r.name,
            r.exec,
            kind(r.kind),
            rate(r.rate),
            yes_no(r.flight),
            yes_no(r.partner),
            cell(r.doc)
        );
    }
    t
}

fn constant_group(t: &mut String, g: &ConstGroup) {
    let _ = write!(
        t,
        "### `sc_icd::{}`\n\n{}\n\n| value | Rust | C | Python | meaning |\n|---|---|---|---|---|\n",
        g.module,
        cell(g.doc)
    );
    for c in g.items {
        let q = g.qualified(c);
        let _ = writeln!(
            t,
            "| {} | `{}::{}` | `SC_{q}` | `{q}` | {} |",
            c.value,
            g.module,
            c.name,
            cell(c.doc)
        );
    }
}

/// Every constant group: value and name in Rust, C and Python, meaning.
pub fn constants() -> String {
    let mut t = String::new();
    for (i, g) in CONSTANT_GROUPS.iter().enumerate() {
        if i > 0 {
            t.push('\n');
        }
        constant_group(&mut t, g);
    }
    t
}

/// A field's type as Rust writes it (`f64`, `[f64; 3]`).
fn rust_type(f: &FieldSpec) -> String {
    match f.len {
        None => f.scalar.rust_name().into(),
        Some(n) => format!("[{}; {n}]", f.scalar.rust_name()),
    }
}

/// The meaning (with its values) and what an array's entries are (barriers: see the
/// barrier table).
fn meaning(f: &FieldSpec) -> String {
    let entries = match f.components {
        Components::Barriers => Some("entries: every barrier, table “Barriers”".into()),
        Components::Constraints { subsystem, .. } => Some(format!(
            "entries: the {subsystem} filter's constraints, table “Barriers”"
        )),
        c => components_line(c).map(|l| format!("entries: {l}")),
    };
    let m = crate::meaning(f);
    match entries {
        Some(e) => cell(&format!("{m} ({e})")),
        None => cell(&m),
    }
}

fn message(t: &mut String, m: &MessageSpec) {
    let _ = write!(
        t,
        "### {} — `{}`, {} B, align {}\n\n{}\n\n\
         | offset | field | type | unit | frame | meaning |\n|---|---|---|---|---|---|\n",
        m.name, m.type_name, m.size, m.align, m.doc
    );
    for f in m.fields {
        let _ = writeln!(
            t,
            "| {} | `{}` | `{}` | {} | {} | {} |",
            f.offset,
            f.name,
            rust_type(f),
            cell(f.unit),
            f.frame.symbol(),
            meaning(f)
        );
    }
}

/// Every message: heading with type name, size and alignment, its doc, its fields.
pub fn messages() -> String {
    let mut t = String::new();
    for (i, m) in MESSAGES.iter().enumerate() {
        if i > 0 {
            t.push('\n');
        }
        message(&mut t, m);
    }
    t
}

/// Every barrier: its index in telemetry (`SimState.barriers`), its filter and index
/// in that filter's report (`h`, `phi`, `active_mask`) — none for the barriers only the
/// monitor evaluates —, its name and unit.
pub fn barriers() -> String {
    let mut t = String::from(
        "| telemetry index | filter | report index | name | unit of h |\n|---|---|---|---|---|\n",
    );
    let mut k = 0;
    for s in Subsystem::ALL {
        for (i, n) in constraint_names(s).iter().enumerate() {
            let unit = barrier_unit(n).unwrap_or("?");
            let _ = writeln!(t, "| {k} | {s} | {i} | `{n}` | {} |", cell(unit));
            k += 1;
        }
    }
    for n in sc_cbf::names::ARM_TARGET {
        let unit = barrier_unit(n).unwrap_or("?");
        let _ = writeln!(t, "| {k} | (monitor only) | — | `{n}` | {} |", cell(unit));
        k += 1;
    }
    t
}

/// `current` (docs/ICD.md) with every generated section rewritten.
pub fn render(current: &str) -> Result<String, GenError> {
    let mut text = current.to_string();
    for (name, content) in SECTIONS {
        let missing = |problem| GenError::Markers {
            file: PATH.into(),
            section: name,
            problem,
        };
        let begin_prefix = format!("<!-- BEGIN GENERATED {name}:");
        let start = text
            .find(&begin_prefix)
            .ok_or_else(|| missing("no BEGIN marker"))?;
        let end = end_marker(name);
        let stop = text[start..]
            .find(&end)
            .map(|i| start + i + end.len())
            .ok_or_else(|| missing("no END marker after the BEGIN marker"))?;
        let block = format!("{}\n\n{}\n{end}", begin_marker(name), content());
        text.replace_range(start..stop, &block);
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_replaced_and_prose_kept() {
        let mut doc = String::from("# Title\n\nprose before\n\n");
        for (name, _) in SECTIONS {
            doc.push_str(&format!(
                "<!-- BEGIN GENERATED {name}: old -->\nOLD CONTENT\n{}\n\nPROSE BETWEEN\n\n",
                end_marker(name)
            ));
        }
        let out = render(&doc).unwrap();
        assert!(out.starts_with("# Title\n\nprose before\n\n"));
        assert!(!out.contains("OLD CONTENT"));
        assert_eq!(out.matches("PROSE BETWEEN").count(), SECTIONS.len());
        assert!(out.contains("| 8 | `recorder` |"));
        // idempotent
        assert_eq!(render(&out).unwrap(), out);
        // a missing marker is an error, not a silent skip
        let cut = out.replace(&end_marker("roles"), "");
        assert!(matches!(
            render(&cut),
            Err(GenError::Markers {
                section: "roles",
                ..
            })
        ));
    }

    #[test]
    fn cells_escape_pipes() {
        assert_eq!(cell("|ω_H|"), "\\|ω_H\\|");
    }
}
