//! `safe-capture redteam`: the red-team campaign against the safety layer.

use crate::redteam_partition::{check_case, default_python, hostile_partners};
use anyhow::Context;
use sc_ground::ClockMode;
use sc_ground::executor::Partition;
use sc_mission::{Executor, InProcess, Setup};
use sc_redteam::partners::{parse_partition_case, partition_cases};
use sc_redteam::{
    Adversaries, Campaign, Case, CaseError, CaseLabel, CaseResult, HostilePartners, Target, report,
};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

/// Attacks the safety layer with adversarial nominal controllers and measures the result
/// from the simulator's true state.
///
/// Every case replaces the nominal controller of one subsystem (or all three) by an
/// adversary for the whole mission: bang-bang towards each of the subsystem's barriers
/// (`toward:<barrier>`), towards whichever is nearest (`greedy`), random saturating
/// (`random:<seed>`), non-finite (`nonfinite`), 1e300 and 1000× the bound (`huge`), the
/// first command for ever (`frozen`), commands for a 10-step-old state (`stale`), or nothing
/// (`silent`). Each case runs to capture or the end of the mission; every barrier is
/// evaluated from the true state at every physics step, every applied command is checked
/// for finiteness and bounds.
///
/// With --partition the cases run through the process partition instead: a hostile
/// partner process (scripts/python/hostile_nominal.py, Python with iceoryx2) replaces the
/// nominal controller process(es) of the target, and besides bad values it misbehaves as
/// a process: it crashes or hangs mid-run, stays silent, sends bursts of 40 messages per
/// state, answers late, labels its commands with old or future ticks, sends garbage
/// fields (`--list` shows the cases; the script's docstring defines them). Every run is
/// lock-step (or, with --real-time, paced at 10 Hz on the wall clock, one at a time) and
/// measured from its recorded telemetry in the same way; each run's outputs stay in
/// OUT/cases/<case>/.
///
/// Isolation: in every case, a subsystem the case does not attack (a bystander) must not
/// lose or refuse an input nor run its backup law on any step — in real time this is the
/// measurement that a misbehaving partner costs no other subsystem a deadline.
///
/// Writes to OUT: cases.csv (one line per case), min_h.csv (each case's smallest value of
/// every barrier), summary.json, report.md, figures/redteam_margins.svg.
///
/// Exit codes: 0 every case safe and no bystander disturbed, 1 a case unsafe or a
/// bystander disturbed, 2 bad arguments or configuration.
///
/// Shards: `--shard i/N` runs every N-th case from i; `redteam merge` merges the shards'
/// folders into the campaign (the same outputs as unsharded but for the wall-clock
/// columns); `--resume --out DIR` completes a campaign or shard that was stopped, keeping
/// every case that finished (each case's result is recorded in OUT/cases/<case>/ as it
/// finishes). On a Slurm cluster: scripts/slurm/submit.sh redteam (docs/MONTECARLO.md).
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    action: Option<Action>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Subcommand)]
enum Action {
    /// Merge shard folders (`redteam --shard i/N`) into one campaign: the same cases.csv,
    /// min_h.csv, summary.json, report.md and figure as the campaign unsharded, but for
    /// the wall-clock columns (the wall time is the shards' sum).
    ///
    /// Exit codes: 0 every case safe and no bystander disturbed, 1 a case unsafe or a
    /// bystander disturbed, 2 bad arguments, cases missing or shards that do not fit
    /// together (the message names the missing cases and the command for each shard).
    Merge(crate::cmd_montecarlo::MergeArgs),
}

/// `safe-capture redteam` with its options (the parser of a shard's recorded options).
#[derive(clap::Parser)]
#[command(name = "redteam")]
struct Recorded {
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Args)]
struct RunArgs {
    /// Run only shard i of N (0-based): the cases at positions k with k mod N = i of the
    /// campaign's list (`--list` shows the shard's).
    #[arg(long, value_name = "i/N")]
    shard: Option<String>,
    /// Complete the campaign (or shard) in --out that was stopped: its finished cases are
    /// kept, the others run; every other option is the campaign's own (campaign.json).
    #[arg(long, conflicts_with = "force")]
    resume: bool,
    /// Scenario file.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    #[arg(long, value_name = "DIR", default_value = "out/redteam", help = crate::out_help!())]
    out: PathBuf,
    #[arg(long, help = crate::out_folder::FORCE_HELP)]
    force: bool,
    #[command(flatten)]
    figures: crate::figure_format::FigureFormatArg,
    /// Every case runs under one realisation of the profile (`--uncertainty-seed`).
    #[command(flatten)]
    uncertainty: crate::uncertainty_arg::UncertaintyArg,
    /// Random strategies per target (`random:1` … `random:N`).
    #[arg(long, value_name = "N", default_value_t = 5)]
    seeds: u64,
    /// Only these targets (translational, attitude, robotic, all; comma-separated).
    #[arg(long, value_name = "T", value_delimiter = ',')]
    target: Vec<String>,
    /// Only these cases, `<target>/<strategy>` (comma-separated), e.g.
    /// `robotic/toward:theta_dot_max_7,all/random:3`; with --partition e.g.
    /// `attitude/spin:-y+burst:40,all/hang:300`.
    #[arg(long, value_name = "CASE", value_delimiter = ',')]
    cases: Vec<String>,
    /// Run the cases through the process partition, with hostile partner processes.
    #[arg(long)]
    partition: bool,
    /// --partition: the partition config (schedule, deadlines, the other executables).
    #[arg(long, value_name = "FILE", default_value_os_t = crate::home::shipped("config/partition.toml"))]
    partition_config: PathBuf,
    /// --partition: Python interpreter with the iceoryx2 package (default: $SC_PYTHON,
    /// else scripts/.venv/bin/python).
    #[arg(long, value_name = "PY", default_value_os_t = default_python())]
    python: PathBuf,
    /// --partition: the hostile partner script.
    #[arg(
        long,
        value_name = "FILE",
        default_value_os_t = crate::home::shipped("scripts/python/hostile_nominal.py")
    )]
    partner: PathBuf,
    /// --partition: stop each run after N ticks (0: the whole mission).
    #[arg(long, value_name = "N", default_value_t = 0)]
    max_ticks: u64,
    /// --partition: lock-step deadlines as this multiple of the real-time ones (a hung
    /// partner costs every tick this much; the config's value is for healthy runs).
    #[arg(long, value_name = "X", default_value_t = 5.0)]
    deadline_scale: f64,
    /// --partition: run each case in real time (10 Hz on the wall clock, the config's
    /// deadlines) instead of lock-step, one case at a time unless --jobs says otherwise.
    /// Combine with --max-ticks: a whole mission takes its 240 s of wall time.
    #[arg(long, requires = "partition")]
    real_time: bool,
    /// Parallel runs (default: the machine's cores).
    #[arg(long, short, value_name = "N")]
    jobs: Option<usize>,
    /// Print nothing but the final line.
    #[arg(long, short)]
    quiet: bool,
    /// List the cases and exit.
    #[arg(long)]
    list: bool,
    /// In process: also write each case's telemetry.csv and timing.csv to
    /// OUT/cases/<case>/ (the partition always does), to look at a case step by step.
    #[arg(long, conflicts_with = "partition")]
    telemetry: bool,
}

/// The cases the arguments select (`ticks`: a partition run's length).
fn selected(a: &RunArgs, ticks: u64) -> anyhow::Result<Vec<CaseLabel>> {
    if !a.cases.is_empty() {
        return a
            .cases
            .iter()
            .map(|c| {
                if a.partition {
                    parse_partition_case(c)
                } else {
                    Case::parse(c).map(|c| c.label())
                }
                .map_err(anyhow::Error::msg)
            })
            .collect();
    }
    let targets: Vec<Target> = a
        .target
        .iter()
        .map(|t| {
            Target::parse(t).with_context(|| {
                format!("--target `{t}`: expected translational, attitude, robotic or all")
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let all: Vec<CaseLabel> = if a.partition {
        partition_cases(a.seeds, ticks)
    } else {
        Case::all(a.seeds).iter().map(Case::label).collect()
    };
    Ok(all
        .into_iter()
        .filter(|c| targets.is_empty() || targets.contains(&c.target))
        .collect())
}

/// The ticks of a partition run: `--max-ticks`, at most the mission's.
fn run_ticks(a: &RunArgs, setup: &Setup) -> u64 {
    let mission_ticks = setup.scenario.control_steps() as u64;
    if a.max_ticks > 0 {
        a.max_ticks.min(mission_ticks)
    } else {
        mission_ticks
    }
}

/// `--partition`: the hostile partners, after checking the deadline scale, every role's
/// program and that the partner script understands every case.
fn partition_partners(
    a: &RunArgs,
    scenario: &sc_scenario::Scenario,
    cases: &[CaseLabel],
) -> anyhow::Result<HostilePartners> {
    if !(a.deadline_scale.is_finite() && a.deadline_scale >= 1.0) {
        anyhow::bail!("--deadline-scale {}: must be >= 1", a.deadline_scale);
    }
    let cfg = sc_ground::PartitionConfig::load(&a.partition_config)?;
    // the tumble inside the envelope at the attitude group's hold, as `launch` checks
    sc_ground::preflight::held_envelope(&cfg, scenario)
        .map_err(|e| anyhow::anyhow!("--partition-config {}: {e}", a.partition_config.display()))?;
    let p = hostile_partners(&a.python, &a.partner)?;
    // every role's program, as the launcher will find it, before any case runs
    sc_ground::preflight::check_programs(&cfg, &None)
        .map_err(|e| anyhow::anyhow!("--partition-config {}: {e}", a.partition_config.display()))?;
    for c in cases {
        check_case(&p, &a.partition_config, c)?;
    }
    Ok(p)
}

/// The partition's executor of `--partition`: lock-step (scaled deadlines) or real
/// time, every run's recordings kept in its case folder.
fn partition_executor(a: &RunArgs) -> Partition {
    Partition::new(&a.partition_config)
        .clock(if a.real_time {
            ClockMode::RealTime
        } else {
            ClockMode::LockStep
        })
        .max_ticks(a.max_ticks)
        .deadline_scale(Some(a.deadline_scale))
        .keep_recordings(true)
        .run_tag(std::process::id().to_string())
}

/// Runs the campaign's cases, showing the progress on stderr (a bar on a terminal, a
/// line every 10 cases — every case through the partition — in a log).
fn run_cases(
    a: &RunArgs,
    campaign: &Campaign,
    cases: &[CaseLabel],
) -> Vec<Result<CaseResult, CaseError>> {
    let tty = std::io::stderr().is_terminal();
    let bar = (!a.quiet && tty).then(|| {
        let b = indicatif::ProgressBar::new(cases.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} cases, {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let unsafe_count = Mutex::new(0usize);
    let progress = |done: usize, total: usize, r: &Result<CaseResult, CaseError>| {
        let bad = match r {
            Ok(r) => !r.safe(),
            Err(_) => true,
        };
        let mut u = unsafe_count.lock().unwrap_or_else(|p| p.into_inner());
        if bad {
            *u += 1;
        }
        if let Some(b) = &bar {
            b.set_position(done as u64);
            b.set_message(format!("{} unsafe or failed", *u));
        } else if !a.quiet && (a.partition || done.is_multiple_of(10) || done == total) {
            errln!("redteam: {done}/{total} cases, {} unsafe or failed", *u);
        }
    };
    let results = campaign.run(cases, &progress);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    results
}

/// The report's paragraph on how the cases ran.
fn how(a: &RunArgs) -> &'static str {
    if a.real_time {
        "Each case runs the mission through the process partition in real time (10 Hz on the wall clock, one case at a time), the hostile partner process `scripts/python/hostile_nominal.py` in place of the nominal controller process of its target (`all`: all three); the barriers come from the simulator's state as the recorder logged it (`cases/<case>/telemetry.csv`)."
    } else if a.partition {
        "Each case runs the mission through the process partition (lock-step), the hostile partner process `scripts/python/hostile_nominal.py` in place of the nominal controller process of its target (`all`: all three); the barriers come from the simulator's state as the recorder logged it (`cases/<case>/telemetry.csv`)."
    } else {
        report::IN_PROCESS
    }
}

/// The declared uncertainty the cases ran under, as ` (uncertainty P, seed N)`, or
/// nothing under `exact`.
fn under(scenario: &sc_scenario::Scenario) -> String {
    scenario
        .uncertainty
        .as_ref()
        .map(|u| format!(" (uncertainty {}, seed {})", u.profile, u.seed))
        .unwrap_or_default()
}

/// The report's paragraph on how the cases ran, with the declared uncertainty if any.
fn how_with_uncertainty(a: &RunArgs, scenario: &sc_scenario::Scenario) -> String {
    match &scenario.uncertainty {
        None => how(a).to_string(),
        Some(u) => format!(
            "{} Every case ran under the declared uncertainty profile `{}` (seed {}, docs/UNCERTAINTY.md): the simulator propagates a plant, actuators and navigation errors drawn from it while the controllers and filters act on the declared model and the navigation's estimate; \"safe\" is on the simulated truth.{}",
            how(a),
            u.profile,
            u.seed,
            not_covered_sentence(scenario)
        ),
    }
}

/// The declared error sources no filter margin covers, as a sentence (nothing if none).
fn not_covered_sentence(scenario: &sc_scenario::Scenario) -> String {
    let open = sc_cbf::coverage::not_covered_in(scenario, true);
    if open.is_empty() {
        return String::new();
    }
    format!(
        " The filters' margins do not cover the declared {}: for those the promise does not hold (docs/SAFETY.md, \"Margins for the declared errors\").",
        open.join(", ")
    )
}

/// `" (<items>)"`-like text of a list, or nothing when it is empty.
fn listed(items: &[String], before: &str, sep: &str, after: &str) -> String {
    if items.is_empty() {
        String::new()
    } else {
        format!("{before}{}{after}", items.join(sep))
    }
}

/// `; safe mode in N cases (M of the unsafe announced at risk when it began)`, or nothing.
fn safe_mode_part(s: &report::CampaignSummary) -> String {
    if s.safe_mode_cases.is_empty() {
        return String::new();
    }
    format!(
        "; safe mode in {} cases ({} of the unsafe announced the line of sight at risk when it began)",
        s.safe_mode_cases.len(),
        s.announced_unsafe.len()
    )
}

/// The final line.
fn verdict_line(a: &RunArgs, s: &report::CampaignSummary, wall: f64, under: &str) {
    outln!(
        "redteam{}{under}: {} of {} cases safe{}{}{}; non-finite applied {}, out-of-bound applied {}; bystanders disturbed in {} cases{}; solve time geomean (worst case) {:.1} us, max {:.0} us; wall {:.1} s -> {}",
        match (a.partition, a.real_time) {
            (true, true) => " (partition, real time)",
            (true, false) => " (partition)",
            _ => "",
        },
        s.safe,
        s.cases,
        listed(&s.unsafe_cases, " (unsafe: ", ", ", ")"),
        if s.errors.is_empty() {
            String::new()
        } else {
            format!(", {} could not run", s.errors.len())
        },
        safe_mode_part(s),
        s.nonfinite_applied,
        s.out_of_bounds_applied,
        s.bystanders_disturbed.len(),
        listed(&s.bystanders_disturbed, " (", ", ", ")"),
        s.solve_time_geomean_max_us,
        s.solve_time_max_us,
        wall,
        a.out.display()
    );
}

/// The scenario with its model, checked before any case runs, under the campaign's
/// declared uncertainty (a partition campaign only under the file's own).
fn load(a: &RunArgs) -> anyhow::Result<Setup> {
    let mut setup = Setup::load(&a.scenario)?;
    setup
        .check_before_run(&a.scenario)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.scenario.display()))?;
    a.uncertainty.refuse_truth("redteam")?;
    let declared_in_file = setup.scenario.uncertainty.clone();
    a.uncertainty.apply(&mut setup.scenario)?;
    // the base's clearance from the target, for the mass errors now declared
    setup.check_target_geometry()?;
    if a.partition && setup.scenario.uncertainty != declared_in_file {
        // the partition's processes read the scenario file: a profile given on the
        // command line would be reported but not run
        anyhow::bail!(
            "--partition: the processes read the scenario file, so --uncertainty cannot change its profile; declare it in the scenario's [uncertainty] section (docs/UNCERTAINTY.md), or drop --partition to run the cases in process"
        );
    }
    Ok(setup)
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    match a.action {
        Some(Action::Merge(m)) => merge(m),
        None => run_campaign(a.run),
    }
}

/// `redteam merge`.
fn merge(m: crate::cmd_montecarlo::MergeArgs) -> anyhow::Result<ExitCode> {
    m.figures.check()?;
    let inputs: Vec<&std::path::Path> = m.dirs.iter().map(PathBuf::as_path).collect();
    let merged = sc_redteam::shard::merge(&m.dirs, &m.out)?;
    let staged = crate::out_folder::stage_reading(&m.out, "redteam merge", m.force, &inputs)?;
    let out = staged.path().to_path_buf();
    let info = &merged.info;
    let scales: sc_cbf::monitor::Barriers =
        info.scales.as_slice().try_into().map_err(|_| {
            anyhow::anyhow!("{}: barrier scales of another build", m.dirs[0].display())
        })?;
    let s = report::write(
        &out,
        &scales,
        &info.how,
        &merged.cases,
        &merged.results,
        merged.wall_s,
    )?;
    sc_redteam::shard::write_info(&out, info)?;
    // the merged campaign records its cases too: it can be merged and resumed like any
    for (case, r) in merged.cases.iter().zip(&merged.results) {
        sc_redteam::shard::record(&out, case, r)?;
    }
    m.figures.export_dir(&out.join("figures"))?;
    staged.commit()?;
    let partition = if info.partition { " (partition)" } else { "" };
    outln!(
        "redteam merge{partition}: {} of {} cases safe{}; bystanders disturbed in {} cases; from {} shards -> {}",
        s.safe,
        s.cases,
        listed(&s.unsafe_cases, " (unsafe: ", ", ", ")"),
        s.bystanders_disturbed.len(),
        m.dirs.len(),
        m.out.display()
    );
    Ok(verdict_code(&s))
}

/// The exit code of a campaign's summary.
fn verdict_code(s: &report::CampaignSummary) -> ExitCode {
    if s.safe == s.cases && s.errors.is_empty() && s.bystanders_disturbed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// With `--resume`: the stopped campaign's own options (from its campaign.json, run in
/// the folder it ran in), `--out` the campaign's absolute path; otherwise `a`.
fn resumed(a: RunArgs) -> anyhow::Result<RunArgs> {
    if !a.resume {
        return Ok(a);
    }
    let given = sc_redteam::shard::campaign_options(&command_args()?);
    if !given.is_empty() {
        anyhow::bail!(
            "--resume completes the campaign with its own options: give only --out, --jobs and --quiet (not {})",
            given.join(" ")
        );
    }
    crate::out_folder::adopt_staging(&a.out, "redteam")?;
    let out = std::path::absolute(&a.out)?;
    let info = sc_redteam::shard::read_info(&out).map_err(|e| {
        anyhow::anyhow!(
            "--resume: {} holds no red-team campaign: {e}",
            a.out.display()
        )
    })?;
    std::env::set_current_dir(&info.cwd)
        .with_context(|| format!("--resume: the campaign's folder {}", info.cwd.display()))?;
    let mut argv = vec!["redteam".to_string()];
    argv.extend(info.options.iter().cloned());
    if let Some([i, n]) = info.shard {
        argv.push(format!("--shard={i}/{n}"));
    }
    argv.push(format!("--out={}", out.display()));
    argv.push("--resume".into());
    let mut r = <Recorded as clap::Parser>::try_parse_from(argv)
        .map_err(|e| {
            let first = e.to_string().lines().next().unwrap_or_default().to_string();
            anyhow::anyhow!("--resume: the campaign's recorded options: {first}")
        })?
        .run;
    (r.quiet, r.jobs) = (a.quiet, a.jobs);
    Ok(r)
}

/// This command's arguments after `redteam`.
fn command_args() -> anyhow::Result<Vec<String>> {
    let args = std::env::args_os()
        .map(|a| {
            a.into_string()
                .map_err(|a| anyhow::anyhow!("the argument {a:?} is not UTF-8"))
        })
        .collect::<anyhow::Result<Vec<String>>>()?;
    Ok(args
        .into_iter()
        .skip_while(|x| x != "redteam")
        .skip(1)
        .collect())
}

/// The campaign's description (campaign.json) for the cases `all` of this build.
fn campaign_info(
    a: &RunArgs,
    setup: &Setup,
    all: &[CaseLabel],
    shard: Shard,
) -> anyhow::Result<sc_redteam::shard::CampaignInfo> {
    let args = command_args()?;
    Ok(sc_redteam::shard::CampaignInfo {
        build: sc_mission::build::current(),
        shard: shard.map(|(i, n)| [i, n]),
        cases: all.iter().map(CaseLabel::name).collect(),
        options: sc_redteam::shard::campaign_options(&args),
        cwd: std::env::current_dir()?,
        partition: a.partition,
        how: how_with_uncertainty(a, &setup.scenario),
        scenario: setup.scenario.to_toml_string(),
        scales: sc_redteam::scales::barrier_scales(&setup.scenario, &setup.robot).to_vec(),
    })
}

fn run_campaign(a: RunArgs) -> anyhow::Result<ExitCode> {
    let a = resumed(a)?;
    let setup = load(&a)?;
    let all = selected(&a, run_ticks(&a, &setup))?;
    let (shard, cases) = shard_cases(&a, &all)?;
    if a.list {
        for c in &cases {
            outln!("{}", c.name());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let info = campaign_info(&a, &setup, &all, shard)?;
    if a.resume {
        check_resumable(&a.out, &info)?;
    }
    let partners = a
        .partition
        .then(|| partition_partners(&a, &setup.scenario, &cases))
        .transpose()?;
    // real-time runs side by side would measure each other
    if let Some(j) = a.jobs.or(a.real_time.then_some(1)) {
        rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global()
            .context("--jobs")?;
    }
    a.figures.check()?;
    // a new campaign is written apart and replaces --out when done; --resume completes
    // the campaign in place
    let staged = if a.resume {
        None
    } else {
        Some(crate::out_folder::stage(&a.out, "redteam", a.force)?)
    };
    let out = staged
        .as_ref()
        .map_or(a.out.clone(), |s| s.path().to_path_buf());
    if !a.resume {
        sc_redteam::shard::write_info(&out, &info)?;
    }
    let started = std::time::Instant::now();
    let partition = partition_executor(&a);
    let scenario_file = std::path::absolute(&a.scenario).unwrap_or_else(|_| a.scenario.clone());
    let (executor, adversaries): (&dyn Executor, _) = match partners {
        Some(p) => (&partition, Adversaries::Partners(p)),
        None => (&InProcess, Adversaries::InProcess),
    };
    let campaign = Campaign {
        setup: &setup,
        scenario_file: &scenario_file,
        executor,
        adversaries,
        out: Some(&out),
        telemetry: a.telemetry,
    };
    let results = run_remaining(&a, &campaign, &cases, &out);
    let wall = started.elapsed().as_secs_f64();
    let scales = sc_redteam::scales::barrier_scales(&setup.scenario, &setup.robot);
    let s = report::write(&out, &scales, &info.how, &cases, &results, wall)?;
    a.figures.export_dir(&out.join("figures"))?;
    if let Some(staged) = staged {
        staged.commit()?;
    }
    for (c, r) in cases.iter().zip(&results) {
        if let Err(e) = r {
            errln!("redteam: {}: {e}", c.name());
        }
    }
    let open = not_covered_sentence(&setup.scenario);
    if !open.is_empty() {
        outln!("redteam:{open}");
    }
    verdict_line(&a, &s, wall, &under(&setup.scenario));
    Ok(verdict_code(&s))
}

/// `i` and `N` of `--shard i/N`.
type Shard = Option<(usize, usize)>;

/// `--shard i/N` parsed, and the cases it runs of the campaign's `all`.
fn shard_cases(a: &RunArgs, all: &[CaseLabel]) -> anyhow::Result<(Shard, Vec<CaseLabel>)> {
    let shard = a
        .shard
        .as_deref()
        .map(sc_montecarlo::parse_shard)
        .transpose()?;
    let cases = match shard {
        Some(_) => sc_montecarlo::shard_runs(all.len(), shard)
            .into_iter()
            .map(|k| all[k].clone())
            .collect(),
        None => all.to_vec(),
    };
    Ok((shard, cases))
}

/// `--resume` only completes the campaign `out` holds: the same build, scenario, cases
/// and shard as `info` (its options as recorded).
fn check_resumable(
    out: &std::path::Path,
    info: &sc_redteam::shard::CampaignInfo,
) -> anyhow::Result<()> {
    let saved = sc_redteam::shard::read_info(out)?;
    let same = sc_redteam::shard::CampaignInfo {
        options: info.options.clone(),
        cwd: info.cwd.clone(),
        ..saved
    } == *info;
    if !same {
        anyhow::bail!(
            "--resume: {} holds a campaign of another build, scenario or case list; resume it with that build, or choose another --out",
            out.display()
        );
    }
    Ok(())
}

/// Runs the cases that have no recorded outcome in `out` yet (all of them unless
/// resuming); every case's outcome, in the order of `cases`.
fn run_remaining(
    a: &RunArgs,
    campaign: &Campaign,
    cases: &[CaseLabel],
    out: &std::path::Path,
) -> Vec<Result<CaseResult, CaseError>> {
    let done: Vec<Option<Result<CaseResult, CaseError>>> = cases
        .iter()
        .map(|c| {
            a.resume
                .then(|| sc_redteam::shard::recorded(out, c))
                .flatten()
        })
        .collect();
    let todo: Vec<CaseLabel> = cases
        .iter()
        .zip(&done)
        .filter(|(_, d)| d.is_none())
        .map(|(c, _)| c.clone())
        .collect();
    if a.resume {
        // what a case stopped mid-run left (a partition run's files) goes before it runs
        for c in &todo {
            let _ = std::fs::remove_dir_all(out.join("cases").join(c.dir_name()));
        }
    }
    if a.resume {
        errln!(
            "redteam: resuming: {} of {} cases finished before, {} to run",
            cases.len() - todo.len(),
            cases.len(),
            todo.len()
        );
    }
    let mut fresh = run_cases(a, campaign, &todo).into_iter();
    done.into_iter()
        .map(|d| d.unwrap_or_else(|| fresh.next().expect("one result per case to run")))
        .collect()
}
