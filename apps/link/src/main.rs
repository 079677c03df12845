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
use iceoryx2::service::service_hash::ServiceHash;
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
    /// How often the services on both hosts are listed [ms] while bridges come and go.
    #[arg(long, default_value_t = 20, value_name = "MS")]
    discover_ms: u64,
    /// How often they are listed once some bridges are up and they have not changed for
    /// 0.5 s [ms]; 0: never again. A partition creates every service before its first
    /// tick, and a listing costs: it stalls the link's passes for tens of milliseconds,
    /// and it can re-open a bridge (iceoryx2-link re-resolves a service that one pass of
    /// its listing missed), losing what is in flight on it. Rare listings still bridge a
    /// service that came late.
    #[arg(long, default_value_t = 5000, value_name = "MS")]
    rediscover_ms: u64,
    /// SCHED_FIFO priority of the link and of every thread it starts (Zenoh's), 1..=99;
    /// 0: normal scheduling. In real time the launcher gives it the roles'
    /// `real_time_priority`: at normal priority beside SCHED_FIFO roles it waits behind
    /// them (measured: 39 deadline misses in 978 ticks).
    #[arg(long, default_value_t = 0, value_name = "PRIO")]
    priority: u32,
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
    sc_bus::init_logging();
    if cli.priority > 99 {
        bail!(
            "--priority {}: 1..=99, or 0 for normal scheduling",
            cli.priority
        );
    }
    if cli.priority > 0 {
        set_fifo(cli.priority);
    }
    if cli.poll_us == 0 || cli.discover_ms == 0 {
        bail!("--poll-us and --discover-ms must be positive");
    }
    let run_id = match &cli.run_id {
        Some(id) => id.clone(),
        None => std::env::var(RUN_ID_ENV)
            .with_context(|| format!("no --run-id and no ${RUN_ID_ENV}"))?,
    };
    let scope = RunScope::new(&run_id)?;
    let zenoh = zenoh_config(&cli, scope.run_id())?;
    let allow = if cli.allow.is_empty() {
        AllowList::all()
    } else {
        AllowList::new(&cli.allow)
    };
    let (mut link, mut peers) = open_link(&scope, zenoh, &allow)?;
    eprintln!(
        "sc-link: run {} (prefix {}), listening on {:?}, connecting to {:?}",
        scope.run_id(),
        scope.prefix(),
        cli.listen,
        cli.connect
    );
    let outcome = spin(
        &mut link,
        &mut peers,
        Duration::from_micros(cli.poll_us),
        Discovery::new(
            Duration::from_millis(cli.discover_ms),
            (cli.rediscover_ms > 0).then(|| Duration::from_millis(cli.rediscover_ms)),
        ),
    );
    eprintln!("sc-link: stopped ({outcome:?})");
    match outcome? {
        WaitSetRunResult::StopRequest => bail!(
            "the other host left (no Zenoh peer for {:?})",
            PeerWatch::GONE_AFTER
        ),
        _ => Ok(()),
    }
}

/// SCHED_FIFO at `prio` for this process, before it starts any thread (they inherit it);
/// a refusal (no CAP_SYS_NICE) is a warning.
fn set_fifo(prio: u32) {
    let param = libc::sched_param {
        sched_priority: prio as libc::c_int,
    };
    // SAFETY: sched_setscheduler on this process with a valid, initialised param.
    if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) } != 0 {
        eprintln!(
            "sc-link: warning: SCHED_FIFO priority {prio} refused ({}); normal scheduling",
            std::io::Error::last_os_error()
        );
    }
}

/// The Zenoh configuration: the file, or a peer that reaches only the named endpoints;
/// either way every key of the link under the run's own namespace `sc/<run id>`, so that
/// the links of two runs sharing an endpoint never bridge into each other (a file's own
/// `namespace` is kept).
fn zenoh_config(cli: &Cli, run_id: &str) -> Result<zenoh::Config> {
    let mut c = match &cli.zenoh_config {
        Some(path) => zenoh::Config::from_file(path)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("zenoh config {}", path.display()))?,
        None => endpoints_only(cli)?,
    };
    if c.get_json("namespace").is_ok_and(|v| v == "null") {
        // a run id is [A-Za-z0-9.-] (sc_bus::RunScope): a valid key chunk
        let ns = format!("\"sc/{run_id}\"");
        c.insert_json5("namespace", &ns)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("zenoh config namespace = {ns}"))?;
    }
    Ok(c)
}

/// A peer that reaches only `--listen`/`--connect`.
fn endpoints_only(cli: &Cli) -> Result<zenoh::Config> {
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
    let json = |v: &[String]| json_list(v);
    for (key, value) in [
        ("mode", "\"peer\"".to_string()),
        ("listen/endpoints", json(&cli.listen)),
        ("connect/endpoints", json(&cli.connect)),
        ("scouting/multicast/enabled", "false".to_string()),
        ("scouting/gossip/enabled", "false".to_string()),
        ("qos/publication", LOSSLESS_AND_AT_ONCE.to_string()),
    ] {
        c.insert_json5(key, &value)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("zenoh config {key} = {value}"))?;
    }
    Ok(c)
}

/// Zenoh's publication settings for the link's keys (`iox2/…`, the Zenoh carrier's):
/// - `congestion_control: "block"`: a frame waits for room in the transmission queue
///   instead of being dropped (Zenoh's default for a put). Measured with the default: a
///   lock-step split mission lost one nominal command at tick 953 of 1255 on this 2-core
///   machine (the filter's deadline passed with it missing);
/// - `express: true`: each frame goes out at once instead of waiting to be batched.
const LOSSLESS_AND_AT_ONCE: &str =
    r#"[{ key_exprs: ["iox2/**"], config: { congestion_control: "block", express: true } }]"#;

/// `["a", "b"]` (endpoints contain no quotes or backslashes: checked).
fn json_list(v: &[String]) -> String {
    let items: Vec<String> = v.iter().map(|s| format!("\"{s}\"")).collect();
    format!("[{}]", items.join(", "))
}

/// The link of the run: a node under the run's prefix, the Zenoh tunnel, and the
/// filter that bridges only services existing on this host (and admitted by `allow`).
fn open_link(
    scope: &RunScope,
    zenoh: zenoh::Config,
    allow: &AllowList,
) -> Result<(ZenohLink, PeerWatch)> {
    let config = link_config(scope);
    let node = NodeBuilder::new()
        .name(&NodeName::new("link")?)
        .config(&config)
        .create::<ipc::Service>()
        .map_err(|e| anyhow::anyhow!("{e:?}"))
        .context("the link's node")?;
    use zenoh::Wait;
    let session = zenoh::open(zenoh)
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
        .context("the zenoh session")?;
    let peers = PeerWatch::new(session.clone());
    let carrier = ZenohCarrier::open(session)
        .map_err(|e| anyhow::anyhow!("{e:?}"))
        .context("the zenoh carrier")?;
    let allow = allow.clone();
    let link = Link::new(node, Tunnel::new(carrier, &config))
        .with_filter(move |name| bridged(&allow, name, &config));
    Ok((link, peers))
}

/// Whether the other host is still there: the Zenoh session's peers, once one was
/// connected. A link whose peer is gone for [`PeerWatch::GONE_AFTER`] ends (exit 1,
/// "the other host left"), and its host's launch tears that host's roles down — so a
/// host whose other side died (or whose stop never came) does not wait for ever.
struct PeerWatch {
    session: zenoh::Session,
    /// Every peer seen connected so far (each other host's link).
    known: Vec<zenoh::session::ZenohId>,
    missing_since: Option<Instant>,
    looked: Option<Instant>,
}

impl PeerWatch {
    const GONE_AFTER: Duration = Duration::from_secs(3);
    /// How often the peers are looked at.
    const EVERY: Duration = Duration::from_millis(100);

    /// Whether a look is due now (and if so, it counts as done).
    fn due(&mut self) -> bool {
        if self.looked.is_some_and(|t| t.elapsed() < Self::EVERY) {
            return false;
        }
        self.looked = Some(Instant::now());
        true
    }

    fn new(session: zenoh::Session) -> Self {
        Self {
            session,
            known: Vec::new(),
            missing_since: None,
            looked: None,
        }
    }

    /// `true` once a peer that was connected has been gone for `GONE_AFTER` (with
    /// three hosts, one that left is noticed while the third is still there). Only
    /// peers are watched: a `--zenoh-config` in client mode or through a router has
    /// none, and then the link never ends by itself.
    fn gone(&mut self) -> bool {
        use zenoh::Wait;
        let now: Vec<zenoh::session::ZenohId> = self.session.info().peers_zid().wait().collect();
        for z in &now {
            if !self.known.contains(z) {
                self.known.push(*z);
            }
        }
        if self.known.iter().all(|z| now.contains(z)) {
            self.missing_since = None;
            return false;
        }
        let since = *self.missing_since.get_or_insert_with(Instant::now);
        since.elapsed() >= Self::GONE_AFTER
    }
}

/// Whether the link bridges `name`: admitted, and created by a process of this host.
fn bridged(allow: &AllowList, name: &ServiceName, config: &iceoryx2::config::Config) -> bool {
    allow.admits(name.as_str()) && exists_here(name, config)
}

/// The link's own publishers never wait for a full subscriber on this host: one hung
/// reader would otherwise stop every bridge (iceoryx2's default retries until delivered).
fn link_config(scope: &RunScope) -> iceoryx2::config::Config {
    let mut config = scope.config().clone();
    config.defaults.publish_subscribe.backpressure_strategy =
        iceoryx2::port::backpressure_strategy::BackpressureStrategy::DiscardData;
    config
}

/// Whether a process of this host created the service. Every service of the partition
/// has an event of its name, created last (`sc_bus`: the data service, then its event),
/// so a service counts once its event exists: a pass between the two cannot mirror the
/// other host's event with iceoryx2's defaults.
fn exists_here(name: &ServiceName, config: &iceoryx2::config::Config) -> bool {
    ipc::Service::does_exist(name, config, MessagingPattern::Event).unwrap_or(false)
}

/// Moves samples every `poll` and on every wake from the other host (then rings the
/// doorbells, `doorbell.rs`), lists the services every `discover`, until SIGINT/SIGTERM.
/// When to list the services: every `fast` until some bridges are up and have not changed
/// for [`Discovery::STABLE`], then every `slow` (or never).
struct Discovery {
    fast: Duration,
    slow: Option<Duration>,
    listed: Option<Instant>,
    bridged: usize,
    changed: Instant,
}

impl Discovery {
    const STABLE: Duration = Duration::from_millis(500);

    fn new(fast: Duration, slow: Option<Duration>) -> Self {
        Self {
            fast,
            slow,
            listed: None,
            bridged: 0,
            changed: Instant::now(),
        }
    }

    /// Whether a listing is due now (and if so, it counts as done).
    fn due(&mut self) -> bool {
        // nothing bridged yet (the other host not started): keep looking
        let every = if self.bridged > 0 && self.changed.elapsed() >= Self::STABLE {
            match self.slow {
                Some(slow) => slow,
                None => return false,
            }
        } else {
            self.fast
        };
        if self.listed.is_some_and(|t| t.elapsed() < every) {
            return false;
        }
        self.listed = Some(Instant::now());
        true
    }

    /// After a listing: how many bridged data services there are now.
    fn bridges(&mut self, n: usize) {
        if n != self.bridged {
            self.bridged = n;
            self.changed = Instant::now();
        }
    }
}

fn spin(
    link: &mut ZenohLink,
    peers: &mut PeerWatch,
    poll: Duration,
    mut discovery: Discovery,
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
    let mut doorbells = Doorbells::default();
    let mut complaints = Complaints::default();
    let link_node = *link.node().id();
    let result = waitset
        .wait_and_process(|_| {
            let _ = wake.try_wait(|_| {});
            if discovery.due() {
                if let Err(e) = link.discover() {
                    complaints.say(&format!("discovery failed: {e}"));
                }
                let bridges = link.bridges();
                let is_bridged = |h: &ServiceHash| bridges.contains(h);
                if let Err(e) = doorbells.discover(link.node(), &is_bridged) {
                    complaints.say(&format!("{e:#}"));
                }
                // the bridged data services, each with its doorbell: stable once all are up
                discovery.bridges(doorbells.len());
            }
            if peers.due() && peers.gone() {
                return CallbackProgression::Stop;
            }
            // a failed pass leaves the link usable (iceoryx2-link): say so, go on
            if let Err(e) = link.propagate() {
                complaints.say(&format!("propagation failed: {e}"));
            }
            if let Err(e) = doorbells.ring(&link_node) {
                complaints.say(&format!("{e:#}"));
            }
            CallbackProgression::Continue
        })
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    if complaints.count > 0 {
        eprintln!("sc-link: {} failures in all", complaints.count);
    }
    eprintln!("sc-link: {} doorbells", doorbells.len());
    drop(doorbells);
    Ok(result)
}

/// Failures of a pass, said on stderr: the first ten, then every thousandth (a pass
/// runs every few hundred microseconds).
#[derive(Default)]
struct Complaints {
    count: u64,
}

impl Complaints {
    const SAID_AT_FIRST: u64 = 10;
    const THEN_EVERY: u64 = 1000;

    fn say(&mut self, what: &str) {
        self.count += 1;
        if self.count <= Self::SAID_AT_FIRST || self.count.is_multiple_of(Self::THEN_EVERY) {
            eprintln!("sc-link: {what} (failure {})", self.count);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_run_has_its_own_zenoh_namespace() {
        let cli = Cli::parse_from(["sc-link", "--listen", "tcp/127.0.0.1:7447"]);
        let c = zenoh_config(&cli, "run-1.a").unwrap();
        assert_eq!(c.get_json("namespace").unwrap(), "\"sc/run-1.a\"");
        let c = zenoh_config(&cli, "run-2").unwrap();
        assert_eq!(c.get_json("namespace").unwrap(), "\"sc/run-2\"");
        // publications block instead of dropping
        let qos = c.get_json("qos/publication").unwrap();
        assert!(qos.contains("\"block\""), "{qos}");
    }
}
