//! Every generated file of the ICD is what the generator writes now: the C header, the
//! Python module and the generated sections of docs/ICD.md. With `SC_WRITE_ICD=1` the
//! test rewrites them first (after a change of the ICD in libs/icd).

use sc_icd_gen::{ARTEFACTS, Artefact, REGENERATE, WRITE_ENV, committed_and_wanted, write};

fn check(a: &Artefact) {
    if std::env::var_os(WRITE_ENV).is_some() {
        write(a).unwrap_or_else(|e| panic!("{e}"));
    }
    let (committed, wanted) = committed_and_wanted(a).unwrap_or_else(|e| panic!("{e}"));
    if committed != wanted {
        let line = committed
            .lines()
            .zip(wanted.lines())
            .position(|(c, w)| c != w)
            .unwrap_or_else(|| committed.lines().count().min(wanted.lines().count()));
        panic!(
            "{} is not what sc-icd-gen writes (first difference at line {}); rewrite it with: {REGENERATE}",
            a.path,
            line + 1
        );
    }
}

fn artefact(path: &str) -> &'static Artefact {
    ARTEFACTS.iter().find(|a| a.path == path).unwrap()
}

#[test]
fn c_header_is_current() {
    check(artefact(sc_icd_gen::c_header::PATH));
}

#[test]
fn python_module_is_current() {
    check(artefact(sc_icd_gen::python::PATH));
}

#[test]
fn icd_doc_tables_are_current() {
    check(artefact(sc_icd_gen::docs::PATH));
}

#[test]
fn every_artefact_is_checked() {
    let mut paths: Vec<&str> = ARTEFACTS.iter().map(|a| a.path).collect();
    paths.sort_unstable();
    assert_eq!(
        paths,
        [
            sc_icd_gen::docs::PATH,
            sc_icd_gen::c_header::PATH,
            sc_icd_gen::python::PATH
        ]
    );
}
