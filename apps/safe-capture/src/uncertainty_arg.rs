//! `--uncertainty PROFILE` and `--uncertainty-seed N`: the declared model, actuator and
//! navigation errors of a run, replacing the scenario's `[uncertainty]` section.

use sc_scenario::UncertaintySpec;
use std::path::Path;

#[derive(clap::Args, Debug, Clone, Default)]
pub struct UncertaintyArg {
    /// The declared uncertainty (docs/UNCERTAINTY.md): `exact` (none), `realistic`, or a
    /// profile file like config/uncertainty/custom_example.toml. Replaces the scenario's
    /// `[uncertainty]` section; the simulator then propagates a plant with the drawn
    /// errors while the controllers and filters see the declared model through the
    /// navigation's estimate.
    #[arg(long, value_name = "PROFILE")]
    pub uncertainty: Option<String>,
    /// Seed of the realisation of the uncertainty (default: the scenario's, else 0).
    #[arg(long, value_name = "N", requires = "uncertainty")]
    pub uncertainty_seed: Option<u64>,
    /// Draw the simulated truth from this profile instead of the declared one (same
    /// forms as --uncertainty): errors outside what the filters were told, to see that
    /// the run says so.
    #[arg(long, value_name = "PROFILE", requires = "uncertainty")]
    pub uncertainty_truth: Option<String>,
}

/// A profile name as given on the command line: a file relative to the working
/// directory is made absolute (the scenario's directory is not where it was named).
fn profile_arg(profile: &str) -> anyhow::Result<String> {
    let named = [
        sc_scenario::uncertainty::EXACT,
        sc_scenario::uncertainty::REALISTIC_NAME,
    ];
    Ok(if named.contains(&profile) {
        profile.to_string()
    } else {
        std::path::absolute(Path::new(profile))?
            .display()
            .to_string()
    })
}

impl UncertaintyArg {
    /// The chosen profile as a scenario section (`None` without `--uncertainty`); a
    /// profile file is read relative to the working directory. The seed is
    /// `--uncertainty-seed`, else `default_seed`.
    pub fn spec(&self, default_seed: u64) -> anyhow::Result<Option<UncertaintySpec>> {
        let Some(profile) = &self.uncertainty else {
            return Ok(None);
        };
        let truth = self
            .uncertainty_truth
            .as_deref()
            .map(|t| {
                sc_scenario::Uncertainty::profile(&profile_arg(t)?, Path::new("."))
                    .map_err(|e| anyhow::anyhow!("--uncertainty-truth: {e}"))
            })
            .transpose()?;
        Ok(Some(UncertaintySpec {
            profile: profile_arg(profile)?,
            truth,
            seed: self.uncertainty_seed.unwrap_or(default_seed),
            model: None,
            actuators: None,
            navigation: None,
        }))
    }

    /// The chosen profile for a campaign whose runs draw their own seeds: an explicit
    /// `--uncertainty-seed` is refused rather than ignored.
    pub fn spec_per_run(&self) -> anyhow::Result<Option<UncertaintySpec>> {
        self.refuse_truth("montecarlo")?;
        if self.uncertainty_seed.is_some() {
            anyhow::bail!(
                "--uncertainty-seed: every run draws its own realisation from its run seed; change the campaign's --seed instead"
            );
        }
        self.spec(0)
    }

    /// `--uncertainty-truth` is for one run, whose summary checks the realised errors
    /// against the declared bounds; a campaign (`cmd`) does not check them per run, so it
    /// refuses the flag rather than report such runs as covered.
    pub fn refuse_truth(&self, cmd: &str) -> anyhow::Result<()> {
        if self.uncertainty_truth.is_some() {
            anyhow::bail!(
                "--uncertainty-truth: only `run` checks the realised errors against the declared bounds; `{cmd}` would not say that its runs left them"
            );
        }
        Ok(())
    }

    /// Declares the chosen profile in `scenario` (nothing without `--uncertainty`); the
    /// seed defaults to the scenario's own.
    pub fn apply(&self, scenario: &mut sc_scenario::Scenario) -> anyhow::Result<()> {
        let own_seed = scenario.uncertainty.as_ref().map_or(0, |u| u.seed);
        let Some(spec) = self.spec(own_seed)? else {
            return Ok(());
        };
        scenario
            .set_uncertainty(spec)
            .and_then(|()| scenario.validate())
            .map_err(|e| anyhow::anyhow!("--uncertainty: {e}"))
    }
}
