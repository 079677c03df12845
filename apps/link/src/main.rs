//! `sc-link`: one host's end of the partition across hosts (docs/PARTITION.md,
//! "Across hosts").
//!
//! It runs iceoryx2's own link — `iceoryx2_link::Link` over the tunnel backend and
//! the Zenoh carrier (iceoryx2 0.10), not a bridge of ours — scoped to one run:
//! its node lives under the run's iceoryx2 prefix (`SC_RUN_ID`), so it sees that
//! run's services and no other. Two rules of ours on top:
//!
//! - **Only services that exist on this host are bridged.** The tunnel would
//!   otherwise mirror a service offered by the other host with iceoryx2's default
//!   settings, and the partition's own process opening it afterwards with the ICD's
//!   settings (one publisher, a 16-sample queue) would be refused. Every process
//!   creates the services it uses, so each service that crosses exists on both
//!   hosts with the ICD's settings and is bridged as it is.
//! - **Zenoh reaches only the named peers**: no multicast scouting, no gossip; the
//!   endpoints are `--listen`/`--connect` (or a Zenoh config file).
//!
//! The tunnel trusts its peer (iceoryx2-link-tunnel, "Trust"): a sample's bytes arrive
//! as a local publisher would have written them. The flight side's checks of every
//! message (docs/ICD.md) apply to them unchanged.

mod doorbell;

use anyhow::{Context, Result, bail};
use clap::Parser;
use doorbell::Doorbells;
use iceoryx2::prelude::*;
use iceoryx2::service::messaging_pattern::MessagingPattern;
use iceoryx2::waitset::WaitSetRunResult;
use iceoryx2_integrations_zenoh_link_carrier::ZenohCarrier;
use iceoryx2_link::Link;
use iceoryx2_link_backend::AllowList;
use iceoryx2_link_tunnel::Tunnel;
use sc_bus::{RUN_ID_ENV, RunScope};
use std::path::PathBuf;
use std::time::{Duration, Instant};

type ZenohLink = Link<ipc::Service, Tunnel<ZenohCarrier>>;

/// One host's end of a partition split across hosts: iceoryx2's Zenoh link for one run.
#[derive(Debug, Parser)]
#[command(name = "sc-link", version)]
struct Cli {
    /// The run whose services cross (its iceoryx2 prefix); default: $SC_RUN_ID.
    #[arg(long)]
    run_id: Option<String>,
    /// Zenoh endpoint this host listens on, e.g. `tcp/10.0.0.2:7447` (repeatable).
    #[arg(long = "listen", value_name = "ENDPOINT")]
    listen: Vec<String>,
    /// Zenoh endpoint of the other host, e.g. `tcp/10.0.0.1:7447` (repeatable).
    #[arg(long = "connect", value_name = "ENDPOINT")]
    connect: Vec<String>,
    /// A Zenoh configuration file (JSON5) instead of --listen/--connect.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["listen", "connect"])]
    zenoh_config: Option<PathBuf>,
    /// Bridge only services whose name matches this pattern ('*' any run of
    /// characters, '?' one); repeatable; default: every service of the run.
    #[arg(long = "allow", value_name = "PATTERN")]
    allow: Vec<String>,
    /// How often pending samples and notifications are moved [µs].
    #[arg(long, default_value_t = 200, value_name = "US")]
    poll_us: u64,
    /// How often the services on both hosts are listed [ms].
    #[arg(long, default_value_t = 20, value_name = "MS")]
    discover_ms: u64,
}

fn main() -> std::process::ExitCode {
    match run(Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sc-link: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    if cli.poll_us == 0 || cli.discover_ms == 0 {
        bail!("--poll-us and --discover-ms must be positive");
    }
    let run_id = match &cli.run_id {
        Some(id) => id.clone(),
        None => std::env::var(RUN_ID_ENV)
            .with_context(|| format!("no --run-id and no ${RUN_ID_ENV}"))?,
    };
    let scope = RunScope::new(&run_id)?;
    let zenoh = zenoh_config(&cli)?;
    let allow = if cli.allow.is_empty() {
        AllowList::all()
    } else {
        AllowList::new(&cli.allow)
    };
    let mut link = open_link(&scope, zenoh, &allow)?;
    eprintln!(
        "sc-link: run {} (prefix {}), listening on {:?}, connecting to {:?}",
        scope.run_id(),
        scope.prefix(),
        cli.listen,
        cli.connect
    );
    let outcome = spin(
        &mut link,
        &allow,
        Duration::from_micros(cli.poll_us),
        Duration::from_millis(cli.discover_ms),
    );
    eprintln!("sc-link: stopped ({outcome:?})");
    outcome.map(|_| ())
}

/// The Zenoh configuration: the file, or a peer that reaches only the named endpoints.
fn zenoh_config(cli: &Cli) -> Result<zenoh::Config> {
    if let Some(path) = &cli.zenoh_config {
        return zenoh::Config::from_file(path)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("zenoh config {}", path.display()));
    }
    if cli.listen.is_empty() && cli.connect.is_empty() {
        bail!("name the link's endpoints: --listen and/or --connect (or --zenoh-config)");
    }
    if let Some(bad) = cli
        .listen
        .iter()
        .chain(&cli.connect)
        .find(|e| e.contains(['"', '\\']))
    {
        bail!("endpoint {bad:?}: no quotes or backslashes");
    }
    let mut c = zenoh::Config::default();
    let json = |v: &[String]| serde_json_list(v);
    for (key, value) in [
        ("mode", "\"peer\"".to_string()),
        ("listen/endpoints", json(&cli.listen)),
        ("connect/endpoints", json(&cli.connect)),
        ("scouting/multicast/enabled", "false".to_string()),
        ("scouting/gossip/enabled", "false".to_string()),
    ] {
        c.insert_json5(key, &value)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("zenoh config {key} = {value}"))?;
    }
    Ok(c)
}

/// `["a", "b"]` (endpoints contain no quotes or backslashes: checked).
fn serde_json_list(v: &[String]) -> String {
    let items: Vec<String> = v.iter().map(|s| format!("\"{s}\"")).collect();
    format!("[{}]", items.join(", "))
}

/// The link of the run: a node under the run's prefix, the Zenoh tunnel, and the
/// filter that bridges only services existing on this host (and admitted by `allow`).
fn open_link(scope: &RunScope, zenoh: zenoh::Config, allow: &AllowList) -> Result<ZenohLink> {
    let config = scope.config().clone();
    let node = NodeBuilder::new()
        .name(&NodeName::new("link")?)
        .config(&config)
        .create::<ipc::Service>()
        .map_err(|e| anyhow::anyhow!("{e:?}"))
        .context("the link's node")?;
    let carrier = ZenohCarrier::create(zenoh)
        .map_err(|e| anyhow::anyhow!("{e:?}"))
        .context("the zenoh session")?;
    let allow = allow.clone();
    let link = Link::new(node, Tunnel::new(carrier, &config))
        .with_filter(move |name| bridged(&allow, name, &config));
    Ok(link)
}

/// Whether the link bridges `name`: admitted, and created by a process of this host.
fn bridged(allow: &AllowList, name: &ServiceName, config: &iceoryx2::config::Config) -> bool {
    allow.admits(name.as_str()) && exists_here(name, config)
}

/// Whether a process of this host created the service (either pattern).
fn exists_here(name: &ServiceName, config: &iceoryx2::config::Config) -> bool {
    [MessagingPattern::PublishSubscribe, MessagingPattern::Event]
        .into_iter()
        .any(|p| ipc::Service::does_exist(name, config, p).unwrap_or(false))
}

/// Moves samples every `poll` and on every wake from the other host (then rings the
/// doorbells, `doorbell.rs`), lists the services every `discover`, until SIGINT/SIGTERM.
fn spin(
    link: &mut ZenohLink,
    allow: &AllowList,
    poll: Duration,
    discover: Duration,
) -> Result<WaitSetRunResult> {
    let wake = link
        .listener()
        .map_err(|e| anyhow::anyhow!("{e:?}"))
        .context("the link's wake listener")?;
    let waitset = WaitSetBuilder::new()
        .create::<iceoryx2_link_backend::WakeService>()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let _interval = waitset
        .attach_interval(poll)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let _woken = waitset
        .attach_notification(&wake)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let mut listed = Instant::now() - discover;
    let mut failure: Option<anyhow::Error> = None;
    let mut doorbells = Doorbells::default();
    let link_node = *link.node().id();
    let config = link.node().config().clone();
    let result = waitset
        .wait_and_process(|_| {
            let _ = wake.try_wait(|_| {});
            if listed.elapsed() >= discover {
                listed = Instant::now();
                if let Err(e) = link.discover() {
                    eprintln!("sc-link: discovery failed: {e}");
                }
                let admits = |n: &ServiceName| bridged(allow, n, &config);
                if let Err(e) = doorbells.discover(link.node(), &admits) {
                    eprintln!("sc-link: {e:#}");
                }
            }
            let moved = link
                .propagate()
                .map_err(|e| anyhow::anyhow!("propagation failed: {e}"))
                .and_then(|()| doorbells.ring(&link_node));
            match moved {
                Ok(_) => CallbackProgression::Continue,
                Err(e) => {
                    failure = Some(e);
                    CallbackProgression::Stop
                }
            }
        })
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    eprintln!("sc-link: {} doorbells", doorbells.len());
    drop(doorbells);
    match failure {
        Some(e) => Err(e),
        None => Ok(result),
    }
}
