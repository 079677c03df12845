//! A C compiler lays every message of the committed C header
//! (`libs/icd/include/safe_capture_icd.h`, checked against the generator by
//! `generated.rs`) out as Rust does: a C program compiled against the header prints
//! every size, alignment, field offset and size and every constant, and the test
//! compares them with the Rust values (the analogue of sc-icd's `python_layout.rs` for
//! C). The header also compiles as C++17.

use sc_icd::MESSAGES;
use sc_icd_gen::c_header::{Define, c_name, defines};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

fn header_path() -> PathBuf {
    sc_icd_gen::repo_root().join(sc_icd_gen::c_header::PATH)
}

/// A scratch directory, removed when the test ends (passed or failed).
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!(
            "sc-icd-{tag}-{}-{}",
            std::process::id(),
            sc_icd::monotonic_ns()
        ));
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The C program: prints what the C compiler made of the header, one fact per line.
fn program() -> String {
    let mut c = String::from(
        "#include <stdio.h>\n#include \"safe_capture_icd.h\"\n\n\
         #define FIELD(T, f) printf(\"field %s.%s %zu %zu\\n\", #T, #f, offsetof(T, f), sizeof(((T *)0)->f))\n\n\
         int main(void) {\n",
    );
    for s in MESSAGES {
        let t = c_name(s);
        writeln!(
            c,
            "    printf(\"struct %s %zu %zu\\n\", \"{t}\", sizeof({t}), (size_t)_Alignof({t}));"
        )
        .unwrap();
        for f in s.fields {
            writeln!(c, "    FIELD({t}, {});", f.name).unwrap();
        }
    }
    for d in defines() {
        match d {
            Define::Section(_) => {}
            Define::Int(n, _, _) => writeln!(
                c,
                "    printf(\"int {n} %llu\\n\", (unsigned long long){n});"
            )
            .unwrap(),
            Define::Str(n, _, _) => writeln!(c, "    printf(\"str {n} %s\\n\", {n});").unwrap(),
        }
    }
    c.push_str("    return 0;\n}\n");
    c
}

/// What the program must print: the Rust layout and the Rust constants.
fn expected() -> String {
    let mut e = String::new();
    for s in MESSAGES {
        let t = c_name(s);
        writeln!(e, "struct {t} {} {}", s.size, s.align).unwrap();
        for f in s.fields {
            writeln!(e, "field {t}.{} {} {}", f.name, f.offset, f.size()).unwrap();
        }
    }
    for d in defines() {
        match d {
            Define::Section(_) => {}
            Define::Int(n, v, _) => writeln!(e, "int {n} {v}").unwrap(),
            Define::Str(n, v, _) => writeln!(e, "str {n} {v}").unwrap(),
        }
    }
    e
}

fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run: {e}"));
    assert!(
        out.status.success(),
        "{what} failed: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn include_dir() -> PathBuf {
    header_path().parent().unwrap().to_path_buf()
}

#[test]
fn c_compiler_lays_out_every_message_as_rust_does() {
    let dir = Scratch::new("c");
    let src = dir.0.join("layout.c");
    let exe = dir.0.join("layout");
    std::fs::write(&src, program()).unwrap();
    run(
        Command::new("cc")
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
            .arg(include_dir())
            .arg(&src)
            .arg("-o")
            .arg(&exe),
        "cc",
    );
    let printed = run(&mut Command::new(&exe), "the layout program");
    let want = expected();
    for (i, (p, w)) in printed.lines().zip(want.lines()).enumerate() {
        assert_eq!(p, w, "line {i}: C says `{p}`, Rust `{w}`");
    }
    assert_eq!(printed.lines().count(), want.lines().count());
    // every message, every field and every constant was compared
    assert!(want.contains("field ScSimState.barriers_between 1336 584"));
    assert!(want.contains("str SC_SERVICE_PARTNER_STATE safe_capture/partner/state"));
    assert!(want.contains("int SC_DUE_ROBOTIC 4"));
}

#[test]
fn header_compiles_as_cpp17() {
    let dir = Scratch::new("cpp");
    let src: &Path = &dir.0.join("use.cpp");
    std::fs::write(
        src,
        "#include \"safe_capture_icd.h\"\n#include <cstring>\n\
         static_assert(sizeof(ScSimState) == 1968, \"size\");\n\
         int main() { ScNominalTranslational m{}; m.tick = 1; m.f_h[2] = 1.0;\n\
         if (m.f_h[2] != 1.0 || m.tick != 1) return 2;\n\
         return std::strcmp(ScNominalTranslational::IOX2_TYPE_NAME, SC_TYPE_NAME_NOMINAL_TRANSLATIONAL); }\n",
    )
    .unwrap();
    let exe = dir.0.join("use");
    run(
        Command::new("c++")
            .args([
                "-std=c++17",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
                "-I",
            ])
            .arg(include_dir())
            .arg(src)
            .arg("-o")
            .arg(&exe),
        "c++",
    );
    run(&mut Command::new(&exe), "the C++ program");
}
