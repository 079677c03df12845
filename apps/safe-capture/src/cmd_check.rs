//! `safe-capture check FILE…`: configuration files validated before anything runs.

use sc_ground::PartitionConfig;
use sc_mission::{Setup, SetupError};
use sc_montecarlo::MonteCarloConfig;
use sc_scenario::{Scenario, ScenarioError};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Validates configuration files before anything runs, with the loaders the commands
/// use: scenarios (`run`, `--scenario`), partition configs (`launch`, `--partition-config`)
/// and Monte Carlo configs (`montecarlo --config`). A partition config is checked as
/// `launch` checks it before starting any process: the scenario it names, every role's
/// program (found as the launcher finds it: a path relative to the config's directory,
/// a bare name next to safe-capture, in $SC_PARTITION_BIN_DIR or on PATH), the partner
/// script a role's arguments name and the simulator's plant program. A Monte Carlo
/// config is also checked against the scenario it disperses (--scenario).
///
/// The kind of each file is told by its keys (`roles`/`rate_groups`: partition;
/// `initial_position`/`target_rate`: Monte Carlo; `servicer`/`target`/`mission`:
/// scenario); --kind overrides. Prints one line per file, `FILE: ok (…)` on stdout or
/// `FILE: <the problem, naming the key or role, the cause and the fix>` on stderr.
///
/// Exit codes: 0 every file valid, 2 a file invalid or unreadable, or bad arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Files to check.
    #[arg(value_name = "FILE", required = true)]
    files: Vec<PathBuf>,
    /// The kind of every file, instead of telling it by its keys.
    #[arg(long, value_enum)]
    kind: Option<Kind>,
    /// The scenario a Monte Carlo config is checked against.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Kind {
    /// A mission scenario (config/scenario.toml).
    Scenario,
    /// A partition config (config/partition.toml).
    Partition,
    /// A Monte Carlo dispersion config (config/montecarlo.toml).
    Montecarlo,
}

/// Top-level keys that tell a file's kind (each one belongs to that kind only).
const KIND_KEYS: [(Kind, &[&str]); 3] = [
    (Kind::Partition, &["roles", "rate_groups"]),
    (Kind::Montecarlo, &["initial_position", "target_rate"]),
    (Kind::Scenario, &["servicer", "target", "mission"]),
];

/// The problem with a file, one line (without the file's name).
type Problem = String;

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let mut all_ok = true;
    for f in &a.files {
        match check_file(f, a.kind, &a.scenario) {
            Ok(what) => outln!("{}: ok ({what})", f.display()),
            Err(p) => {
                all_ok = false;
                errln!("{}: {}", f.display(), p.replace('\n', " "));
            }
        }
    }
    Ok(if all_ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    })
}

/// Validates one file; returns what it is.
fn check_file(path: &Path, kind: Option<Kind>, mc_scenario: &Path) -> Result<String, Problem> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read: {e}"))?;
    let kind = match kind {
        Some(k) => k,
        None => kind_of(&text)?,
    };
    let in_file = |msg: String| without_prefix(path, msg);
    match kind {
        Kind::Scenario => {
            let setup = Setup::load(path).map_err(|e| setup_problem(&e))?;
            setup
                .check_before_run(path)
                .map_err(|e| setup_problem(&e))?;
            let (s, robot) = (&setup.scenario, &setup.robot);
            let env = s.line_of_sight_envelope();
            Ok(format!(
                "scenario: {} phases, {} s at most, control period {} s; tumble {:.4} rad/s, the certified envelope's limit {:.4} rad/s{}",
                s.mission.phases.len(),
                s.mission.duration_s,
                s.mission.control_period_s,
                env.spin_rad_s,
                (env.max_spin_rad_s() - s.watch_margin_rad_s()).max(0.0),
                uncertified_note(s, robot) + &world_note(s, robot)
            ))
        }
        Kind::Partition => {
            let cfg = PartitionConfig::load(path).map_err(|e| in_file(e.to_string()))?;
            let p = sc_ground::preflight::preflight(&cfg, &None).map_err(|e| e.to_string())?;
            Ok(format!(
                "partition: {} roles, scenario {}",
                p.roles,
                p.scenario.display()
            ))
        }
        Kind::Montecarlo => {
            let c = MonteCarloConfig::load(path).map_err(|e| in_file(e.to_string()))?;
            let s = Scenario::load(mc_scenario).map_err(|e| {
                format!(
                    "cannot be checked against the scenario {} (--scenario): {}",
                    mc_scenario.display(),
                    e.root()
                )
            })?;
            c.check_against(&s).map_err(|e| {
                format!(
                    "{e} (with the scenario {}, --scenario)",
                    mc_scenario.display()
                )
            })?;
            Ok(format!(
                "montecarlo: distance {}–{} m, tumbling rate {}–{} rad/s; fits the scenario {}",
                c.initial_position.distance_min_m,
                c.initial_position.distance_max_m,
                c.target_rate.rate_min_rad_s,
                c.target_rate.rate_max_rad_s,
                mc_scenario.display()
            ))
        }
    }
}

/// What the declared uncertainty leaves without a certified command, said before
/// anything runs (docs/SAFETY.md, "Translational: what the declared errors cost"); empty
/// when everything is certifiable or nothing is declared.
fn uncertified_note(s: &Scenario, robot: &sc_multibody::Robot) -> String {
    if s.uncertainty.is_none() {
        return String::new();
    }
    match sc_cbf::translational_margins::wall_uncertifiable_below(s, robot) {
        Some(r) => format!(
            "; NOTE: under the declared uncertainty the translational rows cannot certify \
                 a state on the approach corridor's wall at ranges up to {r:.2} m (there the \
                 filter keeps the largest share of the margins it can, flagged \
                 margins_degraded; \
                 docs/SAFETY.md)"
        ),
        None => String::new(),
    }
}

/// What the scenario's `[world]` does to the certified envelope (the filters never read
/// it; the run then tests the safe mode, docs/SAFETY.md "Safe mode"); empty without one.
fn world_note(s: &Scenario, robot: &sc_multibody::Robot) -> String {
    spin_change_note(s) + &fixture_note(s) + &fixture_reach_note(s, robot)
}

/// When the world's fixture stands off a keep-out sphere by less than the gripper's spheres
/// stick out beyond the grasping point (the rule the start applies to the declared one):
/// the arm–target barriers then keep the gripper off it, so the run cannot capture; empty
/// otherwise.
fn fixture_reach_note(s: &Scenario, robot: &sc_multibody::Robot) -> String {
    let Some(p) = s.world.as_ref().and_then(|w| w.grasp_point_m) else {
        return String::new();
    };
    let overhang = sc_cbf::arm_target::gripper_overhang(robot);
    let standoff = s
        .target
        .collision_spheres
        .iter()
        .map(|sp| sp.standoff_m(&p))
        .fold(f64::INFINITY, f64::min);
    if standoff >= overhang {
        return String::new();
    }
    format!(
        "; NOTE: the world's fixture stands {standoff:.3} m off the target's keep-out spheres, the gripper's spheres stick out {overhang:.3} m beyond the grasping point: the arm–target barriers keep the gripper off it, so the run cannot capture"
    )
}

/// What the world's fixture (`[world] grasp_point_m`) does to the envelope, as the
/// run-time watch judges an exact estimate of it: at the declared tumble and, when the
/// world changes it too, at the changed one; empty without one.
fn fixture_note(s: &Scenario) -> String {
    let Some(p) = s.world.as_ref().and_then(|w| w.grasp_point_m) else {
        return String::new();
    };
    let watch = sc_cbf::safe_mode::EnvelopeWatch::from_scenario(s);
    let judge = |omega: &[f64; 3]| match watch.check_known(omega, &p) {
        Some(rule) => format!(
            "outside the certified envelope ({}): the run tests the safe mode",
            rule.name()
        ),
        None if watch.known_fixture(&p).is_none() => {
            "within the declared grasp point error of the declared one".into()
        }
        None => "inside the certified envelope".into(),
    };
    let mut after = judge(&s.target.initial_omega_rad_s);
    if let Some(c) = s.world.as_ref().and_then(|w| w.target_spin_change) {
        after.push_str(&format!(
            "; with the rate changed at t = {} s: {}",
            c.t_s,
            judge(&c.omega_rad_s)
        ));
    }
    format!(
        "; NOTE: [world] puts the grasping fixture at {p:?} m in F_T (declared {:?}), undeclared to the filters: {after}",
        s.target.grasp_point_m
    )
}

/// What the world's change of the target's rate does to the envelope; empty without one.
fn spin_change_note(s: &Scenario) -> String {
    let Some(c) = s.world.as_ref().and_then(|w| w.target_spin_change) else {
        return String::new();
    };
    // as the run-time watch may take it (the estimate's error twice)
    let after = match s.watched_envelope_for(&c.omega_rad_s).broken_tumble_rule() {
        Some(rule) => format!(
            "outside the certified envelope ({}): the run tests the safe mode",
            rule.name()
        ),
        None => "inside the certified envelope".into(),
    };
    format!(
        "; NOTE: [world] changes the target's rate to {:?} rad/s at t = {} s, undeclared to the filters: {after}",
        c.omega_rad_s, c.t_s
    )
}

/// A scenario error without the file's name (the line starts with it).
fn scenario_problem(e: &ScenarioError) -> Problem {
    match e {
        ScenarioError::Io { message, .. } => format!("cannot read: {message}"),
        e => e.root().to_string(),
    }
}

/// A setup error (the scenario's, or its cross-checks with the servicer model) without
/// the file's name.
fn setup_problem(e: &SetupError) -> Problem {
    match e {
        SetupError::Scenario(e) => scenario_problem(e),
        e => e.to_string(),
    }
}

/// A loader's message without the `FILE: ` it starts with (the line starts with it).
fn without_prefix(path: &Path, msg: String) -> Problem {
    let prefix = format!("{}: ", path.display());
    match msg.strip_prefix(&prefix) {
        Some(rest) => rest.to_string(),
        None => msg,
    }
}

/// The kind of a file, told by its top-level keys.
fn kind_of(text: &str) -> Result<Kind, Problem> {
    let table: toml::Table = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
            .unwrap_or(0);
        format!(
            "parse error at line {line}: {}",
            e.message().replace('\n', " ").trim()
        )
    })?;
    let kinds: Vec<Kind> = KIND_KEYS
        .iter()
        .filter(|(_, keys)| keys.iter().any(|k| table.contains_key(*k)))
        .map(|(k, _)| *k)
        .collect();
    match kinds[..] {
        [k] => Ok(k),
        _ => {
            let keys: Vec<&str> = table.keys().map(String::as_str).collect();
            Err(format!(
                "cannot tell whether this is a scenario, a partition config or a Monte Carlo config from its keys ({}); give --kind",
                if keys.is_empty() {
                    "none".to_string()
                } else {
                    keys.join(", ")
                }
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kind_is_told_by_the_keys() {
        assert_eq!(kind_of("[roles.x]\nexec = \"a\"\n"), Ok(Kind::Partition));
        assert_eq!(kind_of("[target_rate]\n"), Ok(Kind::Montecarlo));
        assert_eq!(kind_of("[mission]\n[servicer]\n"), Ok(Kind::Scenario));
        let e = kind_of("[roles.x]\n[mission]\n").unwrap_err();
        assert!(e.contains("mission, roles") && e.contains("--kind"), "{e}");
        let e = kind_of("a = \n").unwrap_err();
        assert!(e.starts_with("parse error at line 1"), "{e}");
    }
}
