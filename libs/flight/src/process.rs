//! What every process of the partition shares: arguments, run scope, config and
//! scenario loading, real-time placement (SCHED_FIFO, CPU affinity), service settings.

use crate::config::{PartitionConfig, Schedule};
use crate::error::FlightError;
use sc_bus::{BusNode, RunScope, ServiceSettings};
use sc_mission::Setup;
use std::path::PathBuf;
use std::time::Duration;

/// Environment variable with the config path (alternative to `--config`).
pub const CONFIG_ENV: &str = "SC_PARTITION_CONFIG";
/// Environment variable with the output directory (alternative to `--out`).
pub const OUT_ENV: &str = "SC_OUT_DIR";
/// Environment variable with the role the launcher started the process as (e.g.
/// `nominal_attitude`): a partner's process checks that it is the role it implements.
pub const ROLE_ENV: &str = "SC_ROLE";

/// A started process: its run, node, config and scenario.
pub struct Proc {
    pub role: &'static str,
    pub run: RunScope,
    pub node: BusNode,
    pub cfg: PartitionConfig,
    /// The partition config file this process was started with (`--config`).
    pub config_path: PathBuf,
    pub schedule: Schedule,
    pub setup: Setup,
    pub out: PathBuf,
    /// The SCHED_FIFO priority this process runs at (real-time mode), if granted.
    pub fifo_priority: Option<u32>,
}

/// Service settings of the partition's data services: no sample is ever lost
/// silently, and no subscriber can make a flight publisher wait. A subscriber whose
/// queue is full (dead, hung, or one that never reads) loses that sample at once, alone,
/// and the publisher reports it: the causal chain's timing never depends on a reader.
/// The queue (16) holds more than the recorder is allowed to lag in lock-step
/// (`recorder_window_ticks` ≤ 14), so a healthy run loses nothing. Every
/// service has exactly one publisher, its owner (docs/ICD.md): a second one is refused
/// by iceoryx2, a service created with room for more is refused by `sc_bus`, and
/// subscribers accept samples only from the first publisher they heard.
pub fn qos() -> ServiceSettings {
    ServiceSettings {
        subscriber_buffer: 16,
        max_publishers: 1,
        backpressure_timeout: std::time::Duration::ZERO,
        ..ServiceSettings::lock_step()
    }
}

/// Service settings of the services a partner's nominal controller publishes on
/// (`safe_capture/nominal/*`): newest wins. A partner that floods cannot make anyone
/// wait — not itself, not the filter, not the recorder: a full queue drops its oldest
/// sample (the filters use the newest of the tick anyway, docs/PARTITION.md).
pub fn partner_qos() -> ServiceSettings {
    ServiceSettings {
        safe_overflow: true,
        backpressure_timeout: std::time::Duration::ZERO,
        ..qos()
    }
}

/// Ports the link (`sc-link`, iceoryx2's tunnel) opens on every service it bridges, on
/// each host: one publisher (what the other host's processes publish arrives through
/// it) and two subscribers (the tunnel's own and its doorbell's, apps/link).
pub const LINK_PUBLISHERS: usize = 1;
/// See [`LINK_PUBLISHERS`].
pub const LINK_SUBSCRIBERS: usize = 2;

/// The settings a run's processes open the partition's services with: [`qos`] and
/// [`partner_qos`], and in a run across hosts the same with room for the link's ports.
/// The link is then a known second publisher of every service; a subscriber still takes
/// samples only from the first publisher it heard — the owner on its own host, the link
/// on the other (docs/PARTITION.md, "Across hosts").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Qos {
    /// The flight services'.
    pub flight: ServiceSettings,
    /// The services a partner's process publishes on.
    pub partner: ServiceSettings,
    /// Across hosts, whom each service's subscribers accept ([`Qos::expected`]); empty
    /// on one host (there the owner is the first publisher heard).
    pub publishers: Vec<(sc_icd::ServiceName, sc_bus::ExpectedPublisher)>,
}

/// Environment variable the launcher sets for every role of a run across hosts: the
/// process id of this host's `sc-link` (the only process allowed to publish here what
/// the other host's roles publish).
pub const LINK_PID_ENV: &str = "SC_LINK_PID";

/// The node name of `sc-link` (apps/link).
pub const LINK_NODE: &str = "link";

impl Qos {
    /// On one host: [`qos`] and [`partner_qos`].
    pub fn one_host() -> Self {
        Self {
            flight: qos(),
            partner: partner_qos(),
            publishers: Vec::new(),
        }
    }

    /// Across hosts: room for the link's ports on every service.
    pub fn across_hosts() -> Self {
        let with_link = |s: ServiceSettings| ServiceSettings {
            max_publishers: s.max_publishers + LINK_PUBLISHERS,
            max_subscribers: s.max_subscribers + LINK_SUBSCRIBERS,
            ..s
        };
        Self {
            flight: with_link(qos()),
            partner: with_link(partner_qos()),
            publishers: Vec::new(),
        }
    }

    /// The settings of `role`'s process in a run with config `cfg`. Across hosts each
    /// service's subscribers accept only its owner's node when the owner runs on this
    /// host, else only this host's link (by its process id, [`LINK_PID_ENV`], when the
    /// launcher gave it): a process of this host that grabbed a publisher port first —
    /// the link takes one on every service, so there is room — is not taken for the
    /// owner.
    pub fn of(cfg: &PartitionConfig, role: &str) -> Self {
        if !cfg.across_hosts() {
            return Self::one_host();
        }
        let here = cfg.host_of(role);
        // a malformed value accepts no link at all (every sample across is refused,
        // counted and logged), not any node named `link`
        let link_pid = std::env::var(LINK_PID_ENV)
            .ok()
            .map(|p| p.parse::<i32>().unwrap_or(-1));
        let publishers = sc_icd::ROLES
            .iter()
            .flat_map(|owner| owner.publishes.iter().map(move |s| (*s, owner.name)))
            .map(|(service, owner)| {
                let expected = if cfg.host_of(owner) == here {
                    sc_bus::ExpectedPublisher {
                        node_name: owner.to_string(),
                        pid: None,
                    }
                } else {
                    sc_bus::ExpectedPublisher {
                        node_name: LINK_NODE.to_string(),
                        pid: link_pid,
                    }
                };
                (service, expected)
            })
            .collect();
        Self {
            publishers,
            ..Self::across_hosts()
        }
    }

    /// Whom the subscribers of `service` accept (`None`: the first publisher heard).
    pub fn expected(&self, service: sc_icd::ServiceName) -> Option<&sc_bus::ExpectedPublisher> {
        self.publishers
            .iter()
            .find(|(s, _)| *s == service)
            .map(|(_, e)| e)
    }
}

impl Proc {
    /// Parses `--config FILE --out DIR` (or the environment), joins the run of
    /// `SC_RUN_ID` and creates the node `role`.
    pub fn start(role: &'static str) -> Result<Self, FlightError> {
        sc_bus::init_logging();
        let (config, out) = arguments(role)?;
        let cfg = PartitionConfig::load(&config)?;
        let schedule = cfg.schedule()?;
        let setup = Setup::load(&cfg.scenario_path())?;
        let run = RunScope::from_env().ok_or_else(|| {
            FlightError::Usage(
                "SC_RUN_ID is not set (processes are started by the launcher)".into(),
            )
        })??;
        let prio = cfg.priority_of(role);
        let fifo_priority = (cfg.clock == crate::ClockMode::RealTime && prio > 0)
            .then(|| set_fifo(role, prio).then_some(prio))
            .flatten();
        if let Some(e) = cfg.roles.get(role)
            && cfg.clock == crate::ClockMode::RealTime
            && !e.cpus.is_empty()
        {
            set_cpus(role, &e.cpus);
        }
        let node = run.node(role)?;
        Ok(Self {
            role,
            run,
            node,
            cfg,
            config_path: config,
            schedule,
            setup,
            out,
            fifo_priority,
        })
    }

    /// Runs a pre-tick rehearsal one SCHED_FIFO priority below this process's own,
    /// so that the tick's causal chain preempts a rehearsal that is still running
    /// instead of waiting behind it. Without SCHED_FIFO (or at priority 1) it runs
    /// as is.
    pub fn rehearse<R>(&self, f: impl FnOnce() -> R) -> R {
        let Some(prio) = self.fifo_priority.filter(|p| *p >= 2) else {
            return f();
        };
        let lowered = set_priority(prio - 1);
        let r = f();
        if lowered {
            set_priority(prio);
        }
        r
    }

    /// The scenario with the control period of a subsystem's rate group (the
    /// nominal controllers' MPC step) or of the simulator (the base period).
    pub fn scenario_with_period(&self, period_s: f64) -> sc_scenario::Scenario {
        let mut s = self.setup.scenario.clone();
        s.mission.control_period_s = period_s;
        s
    }

    /// Deadline of a stage [ms in config] in this clock mode.
    pub fn deadline(&self, ms: f64) -> Duration {
        Duration::from_secs_f64(self.cfg.deadline_s(ms))
    }
}

/// `--config FILE --out DIR` (or `SC_PARTITION_CONFIG`, `SC_OUT_DIR`).
fn arguments(role: &str) -> Result<(PathBuf, PathBuf), FlightError> {
    let mut config: Option<PathBuf> = std::env::var_os(CONFIG_ENV).map(PathBuf::from);
    let mut out: Option<PathBuf> = std::env::var_os(OUT_ENV).map(PathBuf::from);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--config" => config = args.next().map(PathBuf::from),
            "--out" => out = args.next().map(PathBuf::from),
            other => {
                return Err(FlightError::Usage(format!(
                    "{role}: unknown argument `{other}` (usage: --config FILE --out DIR)"
                )));
            }
        }
    }
    let config = config.ok_or_else(|| FlightError::Usage("missing --config FILE".into()))?;
    Ok((
        config,
        out.unwrap_or_else(|| PathBuf::from("out/partition")),
    ))
}

/// True if this run has the pre-tick warm-up (real-time mode, `warmup_lead_us > 0`).
pub fn warmup_enabled(cfg: &PartitionConfig) -> bool {
    cfg.clock == crate::ClockMode::RealTime && cfg.warmup_lead_us > 0
}

/// Changes this process's SCHED_FIFO priority; false if refused.
fn set_priority(prio: u32) -> bool {
    let param = libc::sched_param {
        sched_priority: prio as libc::c_int,
    };
    // SAFETY: sched_setparam on this process with a valid, initialised param.
    unsafe { libc::sched_setparam(0, &param) == 0 }
}

/// Puts this process in the SCHED_FIFO class (real-time mode); a refusal is a
/// warning (and false).
pub fn set_fifo(role: &str, prio: u32) -> bool {
    let param = libc::sched_param {
        sched_priority: prio as libc::c_int,
    };
    // SAFETY: sched_setscheduler on this process with a valid, initialised param.
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc != 0 {
        eprintln!(
            "warning: {role}: SCHED_FIFO priority {prio} refused ({}); normal scheduling",
            std::io::Error::last_os_error()
        );
    }
    rc == 0
}

/// Restricts this process to `cpus` (real-time mode); a refusal (e.g. a CPU the
/// machine does not have) is a warning.
pub fn set_cpus(role: &str, cpus: &[usize]) {
    // SAFETY: cpu_set_t is plain data; CPU_ZERO/CPU_SET write inside it (cpus were
    // validated < 1024 = CPU_SETSIZE); sched_setaffinity reads it.
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_ZERO(&mut set);
        for c in cpus {
            libc::CPU_SET(*c, &mut set);
        }
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if rc != 0 {
        eprintln!(
            "warning: {role}: CPU affinity {cpus:?} refused ({}); any CPU",
            std::io::Error::last_os_error()
        );
    }
}
