//! Monte Carlo campaigns: dispersions, parallel runs, shards, merge, report.
//!
//! * [`config`] — `config/montecarlo.toml`, the dispersions (default: the paper's).
//! * [`sample`] — per-run seeds derived from (campaign seed, run index) and the sampled
//!   initial position (inside the approach corridor) and target tumbling rate.
//! * [`run`] — one run: dispersed scenario → mission → metrics, trace, timing; failures
//!   and panics become failed results. The mission runs through any
//!   [`sc_mission::Executor`]: in this process ([`sc_mission::InProcess`]) or through the
//!   process partition; the measurement is the same.
//! * [`campaign`] — run a campaign or a shard in parallel (rayon, `--jobs` threads, an
//!   indicatif progress bar).
//! * [`resume`] — complete an interrupted campaign in place.
//! * [`aggregate`] — the campaign's summary, tables and figures, from its run folders.
//! * [`merge`] — merge shards; rerun one run.
//! * [`report`] — the Markdown report beside the paper's numbers.
//! * [`interrupt`] — graceful stop on SIGINT/SIGTERM (the runs in flight finish, the
//!   completed ones are aggregated; `--resume` completes the campaign).
//! * [`host`] — the host's load at the start and end of a campaign (in the summary).
//! * [`trend`] — correlation of a result with a dispersed parameter (Pearson, Spearman).

pub mod aggregate;
pub mod campaign;
pub mod config;
pub mod hist;
pub mod host;
pub mod interrupt;
pub mod merge;
pub mod report;
pub mod resume;
pub mod run;
pub mod sample;
pub mod trend;

pub use aggregate::{
    CampaignSummary, Interruption, Sessions, WALL_CLOCK_FILES, WALL_CLOCK_KEYS, aggregate,
};
pub use campaign::{
    CampaignInfo, CampaignOptions, McError, ShardError, campaign_info, parse_shard, run_campaign,
    run_campaign_with, shard_runs,
};
pub use config::{ConfigError, DEFAULT_CONFIG, MonteCarloConfig};
pub use merge::{merge, rerun};
pub use run::RunResult;
