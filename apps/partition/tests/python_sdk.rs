//! The partner SDK (`scripts/python`, docs/PARTNER.md):
//! - installed with `pip install ./scripts/python` into a fresh venv, without
//!   Pinocchio, its worked example replaces the Rust nominal translational controller
//!   and the mission runs through the partition to capture, every barrier kept; the
//!   offline harness then gives, from that run's recording.mcap and telemetry.csv, the
//!   very commands the controller sent in the partition;
//! - the offline harness gives one command per due step on the telemetry of the
//!   in-process mission, equal to the law evaluated on the true states, and reports
//!   steps without a valid command.
//!
//! The fresh venv needs `python3 -m venv` and PyPI (for iceoryx2, numpy, hatchling).
//! When either is missing the test is skipped with the reason printed, unless
//! `SC_PYTHON` is set (scripts/test.sh sets it): then it fails.

mod common;
use common::*;
use sc_mission::{Mission, RunOptions, Setup, TelemetryWriter};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Runs `cmd`; its output if it succeeded. Otherwise fails the test when `SC_PYTHON`
/// is set, else prints why the test is skipped and returns None.
fn required_step(what: &str, cmd: &mut Command) -> Option<Output> {
    let required = std::env::var_os("SC_PYTHON").is_some();
    let why = match cmd.output() {
        Ok(o) if o.status.success() => return Some(o),
        Ok(o) => format!("{what} failed ({}): {}", o.status, text(&o)),
        Err(e) => format!("{what}: cannot start: {e}"),
    };
    assert!(!required, "{why}");
    eprintln!("SKIPPED: {why}");
    None
}

/// A fresh venv in `dir` with the partner package installed from the checkout.
fn sdk_venv(dir: &Path) -> Option<PathBuf> {
    let venv = dir.join("venv");
    required_step(
        "python3 -m venv",
        Command::new("python3").args(["-m", "venv"]).arg(&venv),
    )?;
    required_step(
        "pip install ./scripts/python",
        Command::new(venv.join("bin/python"))
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "--no-input",
            ])
            .arg(repo().join("scripts/python"))
            .current_dir(dir)
            .env_remove("PYTHONPATH"),
    )?;
    Some(venv)
}

/// The CSV at `path` as (header, rows of fields).
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let s = std::fs::read_to_string(path).unwrap();
    let mut lines = s.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

const F_H: [&str; 3] = ["f_h_nom_x_n", "f_h_nom_y_n", "f_h_nom_z_n"];

/// The harness's commands CSV: step -> (phase, valid, f_H).
fn commands(path: &Path) -> Vec<(u64, usize, u32, [f64; 3])> {
    let (h, rows) = read_csv(path);
    let (step, phase, valid) = (col(&h, "step"), col(&h, "phase"), col(&h, "valid"));
    let f: Vec<usize> = F_H.iter().map(|c| col(&h, c)).collect();
    rows.iter()
        .map(|r| {
            (
                r[step].parse().unwrap(),
                r[phase].parse().unwrap(),
                r[valid].parse().unwrap(),
                [0, 1, 2].map(|i| r[f[i]].parse::<f64>().unwrap()),
            )
        })
        .collect()
}

#[test]
fn installed_sdk_example_runs_the_mission_without_pinocchio() {
    let dir = scratch("sdk");
    let Some(venv) = sdk_venv(&dir) else {
        return;
    };
    let py = venv.join("bin/python");
    // the venv has what the SDK needs, and not Pinocchio; the package is the installed
    // copy, not the checkout's
    let o = Command::new(&py)
        .args(["-c", "import pinocchio"])
        .current_dir(&*dir)
        .output()
        .unwrap();
    assert!(
        !o.status.success(),
        "Pinocchio is installed in the fresh venv"
    );
    let o = Command::new(&py)
        .args([
            "-c",
            "import iceoryx2, numpy, sc_partner; print(sc_partner.__file__)",
        ])
        .current_dir(&*dir)
        .env_remove("PYTHONPATH")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let at = String::from_utf8_lossy(&o.stdout).trim().to_string();
    assert!(at.starts_with(&venv.display().to_string()), "{at}");

    let out = dir.join("out");
    let config = repo().join("config/partition.toml");
    let mut opts = options(&config, &out, "sdk");
    let example = venv.join("bin/sc-partner-nominal-translational");
    assert!(example.exists(), "the example's command is installed");
    opts.role_override.push((
        "nominal_translational".into(),
        example.display().to_string(),
        vec![],
    ));
    let rep = sc_ground::launch(&opts).unwrap();
    assert_clean(&rep, &out);
    let log = std::fs::read_to_string(out.join("logs/nominal_translational.log")).unwrap();
    assert_eq!(
        rep.code,
        0,
        "{rep:?}\nsummary: {}\nthe example's log: {log}",
        std::fs::read_to_string(out.join("summary.json")).unwrap_or_default()
    );
    assert_no_lost_wakeups(&out);
    let s = summary(&out);
    assert_eq!(s["end"], "captured", "{s}");
    assert!(
        s["violated_constraints"].as_array().unwrap().is_empty(),
        "{s}"
    );
    assert!(
        log.contains("nominal_translational.py: handled") && log.contains("(0 without a valid"),
        "{log}"
    );
    let eff = std::fs::read_to_string(out.join("partition.effective.toml")).unwrap();
    assert!(eff.contains("sc-partner-nominal-translational"), "{eff}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("recorder.json")).unwrap()).unwrap();
    assert_eq!(r["missing"]["safe_capture/nominal/translational"], 0, "{r}");

    // offline, on the run's own recordings, the installed harness gives back what the
    // controller sent in the partition: from the MCAP (every state field the law uses,
    // exactly) bit for bit; from telemetry.csv, whose states lack q_hr (the harness
    // reconstructs it from two recorded vectors, to ~1e-14), to 1e-9
    let harness = |source: &str, recording: &str, tag: &str| {
        let cmds = dir.join(format!("commands-{tag}.csv"));
        let o = Command::new(venv.join("bin/sc-partner-harness"))
            .arg("sc_partner.examples.nominal_translational")
            .arg(source)
            .arg(out.join(recording))
            .arg("--config")
            .arg(&config)
            .arg("--out")
            .arg(&cmds)
            .arg("--strict")
            .current_dir(&*dir)
            .env_remove("PYTHONPATH")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o));
        commands(&cmds)
    };
    let (h, rows) = read_csv(&out.join("telemetry.csv"));
    let f: Vec<usize> = F_H.iter().map(|c| col(&h, c)).collect();
    for (source, recording, tol) in [
        ("--mcap", "recording.mcap", 0.0),
        ("--telemetry", "telemetry.csv", 1e-9),
    ] {
        let got = harness(source, recording, &source[2..]);
        assert_eq!(got.len(), rows.len(), "{source}: one command per step");
        for ((step, _, valid, cmd), row) in got.iter().zip(&rows) {
            assert_eq!(step.to_string(), row[0]);
            assert_eq!(*valid, 1);
            for i in 0..3 {
                let sent: f64 = row[f[i]].parse().unwrap();
                assert!(
                    (cmd[i] - sent).abs() <= tol * sent.abs().max(1.0),
                    "{source}, step {step}: harness {cmd:?}, sent in the partition {sent} (axis {i})"
                );
            }
        }
    }
}

/// The worked example's law (scripts/python/sc_partner/examples/nominal_translational.py)
/// on a state of the in-process mission.
fn example_law(setup: &Setup, q_hr: [f64; 4], r_h: [f64; 3], v_h: [f64; 3]) -> [f64; 3] {
    let (omega, zeta, mass) = (0.06, 1.0, 269.0);
    let axis = setup.scenario.safety.translational.corridor_axis;
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let d = setup.scenario.nominal.translational.gfc_distance_m;
    let g = axis.map(|a| a / n * d);
    // v' = v + 2 w (u x v) + 2 u x (u x v), q = (w, u)
    let [w, x, y, z] = q_hr;
    let ux = [
        y * g[2] - z * g[1],
        z * g[0] - x * g[2],
        x * g[1] - y * g[0],
    ];
    let uux = [
        y * ux[2] - z * ux[1],
        z * ux[0] - x * ux[2],
        x * ux[1] - y * ux[0],
    ];
    let gfc_h: Vec<f64> = (0..3)
        .map(|i| g[i] + 2.0 * w * ux[i] + 2.0 * uux[i])
        .collect();
    let (kp, kd) = (omega * omega, 2.0 * zeta * omega);
    [0, 1, 2].map(|i| mass * (-kp * (r_h[i] - gfc_h[i]) - kd * v_h[i]))
}

#[test]
fn offline_harness_gives_one_command_per_due_step() {
    let Some(py) = python() else {
        return;
    };
    let dir = scratch("harness");
    // translational every second tick, the others every tick
    let groups = "[[rate_groups]]\nname = \"slow\"\nperiod_s = 0.2\nmembers = [\"translational\"]\n\n[[rate_groups]]\nname = \"fast\"\nperiod_s = 0.1\nmembers = [\"attitude\", \"robotic\"]\n\n";
    let config = write_config(&dir, Some(20.0), Some(groups), 20.0);
    let setup = Setup::load(&dir.join("scenario.toml")).unwrap();
    let telemetry = dir.join("telemetry.csv");
    let mut records = Vec::new();
    {
        let mut tel = std::fs::File::create(&telemetry).unwrap();
        let mut tim = std::fs::File::create(dir.join("timing.csv")).unwrap();
        let mut w = TelemetryWriter::new(&mut tel, &mut tim).unwrap();
        let mut m = Mission::new(setup.clone(), RunOptions::default()).unwrap();
        m.run(|_, r| {
            w.write(r).unwrap();
            records.push(*r);
        });
        w.flush().unwrap();
    }
    let n = records.len();
    assert!(n >= 150, "{n} steps recorded");
    let harness = |args: &[&str]| {
        Command::new(&py)
            .args(["-m", "sc_partner.harness"])
            .args(args)
            .current_dir(&*dir)
            .env("PYTHONPATH", repo().join("scripts/python"))
            // no __pycache__ left in the checkout
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .output()
            .unwrap()
    };
    let tel = telemetry.display().to_string();
    let cmds = dir.join("commands.csv").display().to_string();
    let cfg = config.display().to_string();
    let o = harness(&[
        "sc_partner.examples.nominal_translational",
        "--telemetry",
        &tel,
        "--config",
        &cfg,
        "--out",
        &cmds,
        "--strict",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let due = n.div_ceil(2);
    assert!(
        text(&o).contains(&format!(
            "on {n} states: {due} commands, 0 without a valid one"
        )),
        "{}",
        text(&o)
    );
    let got = commands(Path::new(&cmds));
    assert_eq!(got.len(), due, "one command per due step");
    for (k, (step, phase, valid, f)) in got.iter().enumerate() {
        assert_eq!(
            *step,
            2 * k as u64,
            "only the steps the subsystem is due in"
        );
        let rec = &records[*step as usize];
        assert_eq!(*phase, rec.phase);
        assert_eq!(*valid, 1);
        assert!(f.iter().all(|x| x.is_finite()), "{f:?}");
        let o = &rec.obs;
        let want = example_law(
            &setup,
            o.q_hr,
            [o.r_h[0], o.r_h[1], o.r_h[2]],
            [o.v_h[0], o.v_h[1], o.v_h[2]],
        );
        for i in 0..3 {
            assert!(
                (f[i] - want[i]).abs() <= 1e-9 * want[i].abs().max(1.0),
                "step {step}: harness {f:?}, the law on the true state {want:?}"
            );
        }
    }

    // a controller file that raises on every third state and returns None on the next:
    // those steps come back invalid; --strict turns them into exit code 1
    let faulty = dir.join("faulty.py");
    std::fs::write(
        &faulty,
        "from sc_partner import NominalController\n\n\
         class Faulty(NominalController):\n    subsystem = \"robotic\"\n\n    \
         def step(self, state):\n        if state.tick % 3 == 0:\n            \
         raise ValueError(\"deliberate\")\n        if state.tick % 3 == 1:\n            \
         return None\n        return [0.5] * 7\n",
    )
    .unwrap();
    let spec = format!("{}:Faulty", faulty.display());
    let sc = dir.join("scenario.toml").display().to_string();
    let faulty_cmds = dir.join("faulty.csv");
    let fc = faulty_cmds.display().to_string();
    let o = harness(&[&spec, "--telemetry", &tel, "--scenario", &sc, "--out", &fc]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("ValueError: deliberate"), "{}", text(&o));
    let (h, rows) = read_csv(&faulty_cmds);
    assert_eq!(rows.len(), n, "without a config every step is due");
    let (step, valid) = (col(&h, "step"), col(&h, "valid"));
    let joint = col(&h, "tau_m_nom_7_nm");
    for r in &rows {
        let k: u64 = r[step].parse().unwrap();
        let ok = k % 3 == 2;
        assert_eq!(r[valid], if ok { "1" } else { "0" }, "step {k}");
        assert_eq!(r[joint].parse::<f64>().unwrap(), if ok { 0.5 } else { 0.0 });
    }
    let o = harness(&[&spec, "--telemetry", &tel, "--scenario", &sc, "--strict"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
}

/// The SDK's Python unit tests (scripts/python/tests: rotations, the base class's
/// validity rules, config helpers, the LZ4 decoder of the MCAP reader).
#[test]
fn python_unit_tests_pass() {
    let Some(py) = python() else {
        return;
    };
    let o = Command::new(&py)
        .args(["-m", "unittest", "discover", "-s", "tests"])
        .current_dir(repo().join("scripts/python"))
        .env("PYTHONPATH", repo().join("scripts/python"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .unwrap();
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let ran: usize = t
        .split("Ran ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(ran >= 10, "{t}");
}
