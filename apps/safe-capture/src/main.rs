//! `safe-capture`: the command-line front door of the safety layer.

// printing that survives a closed pipe (`outln!`, `errln!`), used by every module below
#[macro_use]
mod print;
// One module per subcommand; add a subcommand with one `mod` line, one enum variant
// and one match arm.
mod cmd_bench;
mod cmd_bench_filters;
mod cmd_bench_latency;
mod cmd_bounds;
mod cmd_check;
mod cmd_compare;
mod cmd_launch;
mod cmd_model;
mod cmd_montecarlo;
mod cmd_redteam;
mod cmd_run;
mod cmd_simulate;
mod cmd_verify_qp;
// --figure-format, the same in every command that draws figures
mod figure_format;
// where the shipped config/ and scripts/ are (SAFE_CAPTURE_HOME, the executable's place)
mod home;
// the output-folder policy's --out/--force, the same in every command
mod out_folder;
// the hostile partner processes of `redteam --partition` and `launch --hostile`
mod redteam_partition;
mod uncertainty_arg;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Safety layer for a free-flying robotic servicer capturing a tumbling target:
/// three coupling-aware CBF safety filters (translational → attitude → robotic) over a
/// high-fidelity simulator.
///
/// Runs from any folder: the shipped files the defaults name (config/, scripts/) are
/// taken from the installation, $SAFE_CAPTURE_HOME if set, else the checkout the
/// executable was built in (target/release/ below it); a path given on the command line
/// is relative to the working directory, a path inside a config file to that file's
/// folder. Outputs go to --out, relative to the working directory.
#[derive(Parser)]
#[command(name = "safe-capture", version = VERSION, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the whole mission in one process (simulator + nominal controllers + filters).
    Run(cmd_run::Args),
    /// Open-loop simulation of a command profile.
    Simulate(cmd_simulate::Args),
    /// Evaluate the servicer model at a state (JSON in, JSON out) for cross-checks.
    Model(cmd_model::Args),
    /// Run the mission as a process partition (one process per module, iceoryx2).
    Launch(cmd_launch::Args),
    /// Benchmarks: simulator speed, safety-layer solve times, partition latency.
    Bench(cmd_bench::Args),
    /// Monte Carlo campaigns: dispersed runs in parallel (in-process or through the
    /// process partition), shards, merge, rerun.
    Montecarlo(cmd_montecarlo::Args),
    /// Red team: adversarial nominal controllers against the safety layer, measured from
    /// the simulator's true state.
    Redteam(cmd_redteam::Args),
    /// The envelope bounds of the sampled-data rows: sampled from the model, compared
    /// with the scenario's.
    Bounds(cmd_bounds::Args),
    /// Check every QP a run dumped (`run --dump-qp`) independently: KKT conditions and
    /// Clarabel's solution of the same data.
    VerifyQp(cmd_verify_qp::Args),
    /// Compare two runs of the same mission step by step (e.g. Basilisk as the plant
    /// against our simulator): position, attitude and joint differences, CSV and figure.
    Compare(cmd_compare::Args),
    /// Validate scenario, partition and Monte Carlo configs before anything runs (a
    /// partition config with its scenario and every role's program).
    Check(cmd_check::Args),
}

/// `--version`: the crate version and the git commit of the build (`build.rs`).
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (", env!("SC_GIT_COMMIT"), ")");

/// Default scenario: the installation's config/scenario.toml ([`home::shipped`]).
pub fn default_scenario() -> PathBuf {
    home::shipped(sc_scenario::DEFAULT_SCENARIO)
}

/// The command line with each subcommand's whole description in its `--help`: the
/// enum's doc comments give the one-line summaries of `safe-capture --help`, and would
/// otherwise replace the long descriptions (outputs, columns, exit codes) the commands'
/// `Args` carry.
fn command() -> clap::Command {
    use clap::CommandFactory;
    fn args<A: clap::Args>(name: &'static str) -> clap::Command {
        A::augment_args(clap::Command::new(name))
    }
    let mut c = Cli::command();
    for (path, args) in [
        (&["run"][..], args::<cmd_run::Args>("run")),
        (&["simulate"], args::<cmd_simulate::Args>("simulate")),
        (&["model"], args::<cmd_model::Args>("model")),
        (&["launch"], args::<cmd_launch::Args>("launch")),
        (&["bench"], args::<cmd_bench::Args>("bench")),
        (
            &["bench", "filters"],
            args::<cmd_bench_filters::Args>("filters"),
        ),
        (
            &["bench", "latency"],
            args::<cmd_bench_latency::Args>("latency"),
        ),
        (&["montecarlo"], args::<cmd_montecarlo::Args>("montecarlo")),
        (&["redteam"], args::<cmd_redteam::Args>("redteam")),
        (&["bounds"], args::<cmd_bounds::Args>("bounds")),
        (&["verify-qp"], args::<cmd_verify_qp::Args>("verify-qp")),
        (&["compare"], args::<cmd_compare::Args>("compare")),
        (&["check"], args::<cmd_check::Args>("check")),
    ] {
        if let Some(l) = args.get_long_about().or(args.get_about()).cloned() {
            c = with_long_about(c, path, l);
        }
    }
    c
}

/// `c` with the long description of its subcommand at `path` (e.g. `bench filters`).
fn with_long_about(
    c: clap::Command,
    path: &[&str],
    long: clap::builder::StyledStr,
) -> clap::Command {
    match path {
        [] => c.long_about(long),
        [name, rest @ ..] => c.mut_subcommand(*name, |s| with_long_about(s, rest, long)),
    }
}

fn main() -> ExitCode {
    use clap::FromArgMatches;
    // every summary.json names the build that wrote it
    sc_mission::build::register(env!("CARGO_PKG_VERSION"), env!("SC_GIT_COMMIT"));
    let cli = Cli::from_arg_matches(&command().get_matches()).unwrap_or_else(|e| e.exit());
    let result = match cli.command {
        Command::Run(a) => cmd_run::run(a),
        Command::Simulate(a) => cmd_simulate::run(a),
        Command::Model(a) => cmd_model::run(a),
        Command::Launch(a) => cmd_launch::run(a),
        Command::Bench(a) => cmd_bench::run(a),
        Command::Montecarlo(a) => cmd_montecarlo::run(a),
        Command::Redteam(a) => cmd_redteam::run(a),
        Command::Bounds(a) => cmd_bounds::run(a),
        Command::VerifyQp(a) => cmd_verify_qp::run(a),
        Command::Compare(a) => cmd_compare::run(a),
        Command::Check(a) => cmd_check::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            // one line naming the problem
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            errln!("error: {}", chain.join(": ").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
