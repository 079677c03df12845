//! The role table `sc_icd::ROLES` is the only list of roles: every role is in every
//! generated artefact that names roles (the C header's defines, the Python module's
//! constants and name list, the role table of docs/ICD.md), with its id, and no
//! artefact names a role the table does not have.

use sc_icd::ROLES;
use sc_icd_gen::repo_root;

fn committed(path: &str) -> String {
    std::fs::read_to_string(repo_root().join(path)).unwrap()
}

/// What is missing or extra in `text` for the role table: each role's line
/// `want(role)` must be there, and (when `is_role_line` is given) exactly one line
/// per role is a role line.
fn problems(
    text: &str,
    is_role_line: Option<fn(&str) -> bool>,
    want: impl Fn(&sc_icd::Role) -> String,
) -> Vec<String> {
    let mut bad = Vec::new();
    for r in &ROLES {
        let line = want(r);
        if !text.lines().any(|l| l.starts_with(&line)) {
            bad.push(format!("missing: {line}"));
        }
    }
    if let Some(is_role) = is_role_line {
        let n = text.lines().filter(|l| is_role(l)).count();
        if n != ROLES.len() {
            bad.push(format!("{n} role lines, {} roles", ROLES.len()));
        }
    }
    bad
}

fn c_header(text: &str) -> Vec<String> {
    problems(text, Some(|l| l.starts_with("#define SC_ROLE_")), |r| {
        format!("#define SC_ROLE_{} {}u ", r.constant_name(), r.id())
    })
}

fn python(text: &str) -> Vec<String> {
    let is_role: fn(&str) -> bool = |l| l.starts_with("ROLE_") && !l.starts_with("ROLE_NAMES");
    let mut bad = problems(text, Some(is_role), |r| {
        format!("ROLE_{} = {}  #", r.constant_name(), r.id())
    });
    // ROLE_NAMES lists them in id order
    let names: Vec<String> = ROLES
        .iter()
        .map(|r| format!("    \"{}\",", r.name))
        .collect();
    let block = format!("ROLE_NAMES = (\n{}\n)", names.join("\n"));
    if !text.contains(&block) {
        bad.push("ROLE_NAMES is not the role table's names in id order".into());
    }
    bad
}

fn docs(text: &str) -> Vec<String> {
    // the rows of the role table: `| id | `name` | `SC_ROLE_…
    let is_role: fn(&str) -> bool = |l| l.starts_with("| ") && l.contains("| `SC_ROLE_");
    problems(text, Some(is_role), |r| {
        format!("| {} | `{}` | ", r.id(), r.name)
    })
}

#[test]
fn every_role_is_in_every_artefact() {
    let h = committed(sc_icd_gen::c_header::PATH);
    assert_eq!(c_header(&h), Vec::<String>::new(), "C header");
    let py = committed(sc_icd_gen::python::PATH);
    assert_eq!(python(&py), Vec::<String>::new(), "Python module");
    let md = committed(sc_icd_gen::docs::PATH);
    assert_eq!(docs(&md), Vec::<String>::new(), "docs/ICD.md");
}

/// The checks can fail: an artefact without one role, or with a role the table has
/// not, is found.
#[test]
fn a_missing_or_extra_role_is_found() {
    let last = ROLES.last().unwrap();
    let h = committed(sc_icd_gen::c_header::PATH);
    let without = h.replace(&format!("#define SC_ROLE_{} ", last.constant_name()), "");
    assert!(!c_header(&without).is_empty());
    let extra = h.replace(
        "#define SC_ROLE_SCHEDULER ",
        "#define SC_ROLE_NAVIGATOR 9u\n#define SC_ROLE_SCHEDULER ",
    );
    assert!(!c_header(&extra).is_empty());
    let py = committed(sc_icd_gen::python::PATH);
    let without = py.replace(&format!("    \"{}\",\n", last.name), "");
    assert!(!python(&without).is_empty());
    let md = committed(sc_icd_gen::docs::PATH);
    let without = md.replace(&format!("| {} | `{}` | ", last.id(), last.name), "| ");
    assert!(!docs(&without).is_empty());
}
