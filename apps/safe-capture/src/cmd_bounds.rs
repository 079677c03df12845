//! `safe-capture bounds`: the envelope bounds the sampled-data rows rest on, sampled
//! from the model and compared with the scenario's (docs/SAFETY.md, "The envelope
//! bounds").

use sc_cbf::envelope::{self, SAFETY_FACTOR};
use sc_mission::Setup;
use std::path::PathBuf;
use std::process::ExitCode;

/// Samples the certified envelope (states, inputs and accelerations the safety layer
/// admits) with the scenario's servicer model and prints, for every envelope bound of
/// the scenario, the sampled maximum, the configured value and their ratio. More
/// samples find larger maxima (sampling is not a proof): the tests use 20 000, the
/// configured values were checked with 500 000. With --search-rounds N a targeted search
/// follows: from the sampled worst point of every quantity, N proposals of a random local
/// ascent inside the envelope; the maxima it finds are what the bounds are checked
/// against (still not a proof: a local search, different seeds find different maxima).
///
/// The column "rests on it" says what a bound too small would cost: `certificate` (the
/// attitude rows' in-sample bounds take it as it is; every command refuses it below what
/// the model reaches) or `verified per step` (the robotic filter verifies every
/// command on the servicer model's sample; a bound the arm exceeds costs a verification
/// round, not the certificate).
///
/// Exit codes: 0 every bound a certificate rests on keeps the factor 1.5 over its sampled
/// (or searched) maximum, 1 a bound a certificate rests on keeps less, 2 bad arguments or
/// scenario, or fewer than 90 % of the samples usable (nothing measured is no evidence).
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file.
    #[arg(long, value_name = "FILE", default_value_os_t = crate::default_scenario())]
    scenario: PathBuf,
    /// States drawn from the envelope.
    #[arg(long, default_value_t = 20_000)]
    samples: usize,
    /// Seed of the sampling (deterministic).
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Proposals of the targeted search per quantity after the sampling (0: none).
    #[arg(long, default_value_t = 0)]
    search_rounds: usize,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let setup = Setup::load(&a.scenario)?;
    let started = std::time::Instant::now();
    let m = if a.search_rounds > 0 {
        envelope::search(
            &setup.scenario,
            &setup.robot,
            a.samples,
            a.seed,
            a.search_rounds,
        )
    } else {
        envelope::sample(&setup.scenario, &setup.robot, a.samples, a.seed)
    };
    let found = if a.search_rounds > 0 {
        "searched max"
    } else {
        "sampled max"
    };
    if !envelope::enough_samples(m.samples, a.samples) {
        errln!(
            "bounds: only {} of {} samples usable: no evidence for the bounds (--samples)",
            m.samples,
            a.samples
        );
        return Ok(ExitCode::from(2));
    }
    let checks = envelope::checks(&setup.scenario, &m);
    print_table(&checks, found);
    let certificate = |c: &&envelope::BoundCheck| c.reliance == envelope::Reliance::Certificate;
    let load_bearing: Vec<_> = checks.iter().filter(certificate).collect();
    let short = load_bearing.iter().filter(|c| !c.holds()).count();
    // the verified ones whose quantity moves at all (link 1's spheres lie on joint 1's axis)
    let verified: Vec<_> = checks
        .iter()
        .filter(|c| !certificate(c) && c.sampled > 0.0)
        .collect();
    outln!(
        "{} of {} samples usable{}, {:.1} s; {} of {} bounds a certificate rests on keep the factor {SAFETY_FACTOR}; of the {} verified per step, {} keep it (they only make the cheap certificate succeed)",
        m.samples,
        a.samples,
        if a.search_rounds > 0 {
            format!(", then {} search rounds per quantity", a.search_rounds)
        } else {
            String::new()
        },
        started.elapsed().as_secs_f64(),
        load_bearing.len() - short,
        load_bearing.len(),
        verified.len(),
        verified.iter().filter(|c| c.holds()).count()
    );
    Ok(if short == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// One line per bound: its maximum (`found`: sampled or searched), the configured value,
/// their ratio, what rests on it, and `< 1.5` for a load-bearing one short of the factor.
fn print_table(checks: &[envelope::BoundCheck], found: &str) {
    outln!(
        "{:<52} {:>12} {:>12} {:>8}  {}",
        "bound",
        found,
        "configured",
        "ratio",
        "rests on it"
    );
    for c in checks {
        let ratio = if c.sampled > 0.0 {
            format!("{:.2}", c.configured / c.sampled)
        } else {
            "-".into() // nothing moves there (link 1's spheres lie on joint 1's axis)
        };
        let short = c.reliance == envelope::Reliance::Certificate && !c.holds();
        outln!(
            "{:<52} {:>12.4} {:>12.4} {:>8}  {:<18}{}",
            c.key,
            c.sampled,
            c.configured,
            ratio,
            c.reliance.name(),
            if short { "  < 1.5" } else { "" }
        );
    }
}
