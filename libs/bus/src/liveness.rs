//! Liveness: detect that a peer process of the run died.
//!
//! iceoryx2 does not notice a `kill -9`'d process by itself: its ports just go
//! silent. Someone has to look at the node list of the prefix; a node whose process
//! is gone shows up as dead. Reaping it (removing its stale resources) also makes
//! iceoryx2 emit the `notifier dead` event on the event services the dead node
//! notified on, so subscribers of that peer wake up with
//! [`crate::Events::publisher_died`].
//!
//! ```no_run
//! use sc_bus::{PeerMonitor, RunScope};
//! let run = RunScope::unique("doc")?;
//! let mut monitor = PeerMonitor::new(&["simulator", "filter_t"]);
//! // in the scheduler's 100 ms interval handler:
//! for lost in monitor.poll(&run)? {
//!     eprintln!("peer {} (pid {}) died", lost.name, lost.pid);
//! }
//! # Ok::<(), sc_bus::BusError>(())
//! ```

use crate::error::{BusError, Result, reason};
use crate::run::RunScope;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

/// One node of the run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PeerInfo {
    /// Node name (the role name by convention).
    pub name: String,
    /// Process id of the node's process.
    pub pid: i32,
}

/// Result of [`reap_dead_nodes`].
#[derive(Debug, Clone, Default)]
pub struct NodeReport {
    /// Nodes whose process is alive.
    pub alive: Vec<PeerInfo>,
    /// Nodes found dead; their resources were removed (or were being removed by another process).
    pub dead: Vec<PeerInfo>,
    /// Dead nodes whose cleanup failed, with the reason.
    pub cleanup_failed: Vec<(PeerInfo, String)>,
}

fn info(details: &Option<iceoryx2::node::NodeDetails>) -> PeerInfo {
    match details {
        Some(d) => PeerInfo {
            name: d.name().to_string(),
            pid: d.process_id().value(),
        },
        None => PeerInfo {
            name: String::from("<unknown>"),
            pid: -1,
        },
    }
}

/// Lists the nodes of the run and removes the resources of every dead one.
pub fn reap_dead_nodes(run: &RunScope) -> Result<NodeReport> {
    let mut dead_views = Vec::new();
    let mut report = NodeReport::default();
    Node::<ipc::Service>::list(run.config(), |state| {
        match state {
            NodeState::Alive(v) => report.alive.push(info(v.details())),
            NodeState::Dead(v) => dead_views.push(v),
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => {}
        }
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::NodeList {
        prefix: run.prefix().to_string(),
        reason: reason(e),
    })?;
    for view in dead_views {
        let who = info(view.details());
        match view.try_remove_stale_resources() {
            Ok(())
            | Err(iceoryx2::node::NodeCleanupFailure::ResourcesAlreadyCleanedUp)
            | Err(iceoryx2::node::NodeCleanupFailure::AnotherInstanceIsCleaningUpTheNode) => {
                report.dead.push(who)
            }
            Err(e) => report.cleanup_failed.push((who, reason(e))),
        }
    }
    Ok(report)
}

/// Tracks the expected peers of a run by node name and reports each one once
/// when it disappears (died, reaped by someone else, or left).
#[derive(Debug, Clone)]
pub struct PeerMonitor {
    expected: Vec<String>,
    seen: Vec<Option<PeerInfo>>,
    lost: Vec<bool>,
}

impl PeerMonitor {
    /// Watch nodes with these names.
    pub fn new(names: &[&str]) -> Self {
        Self {
            expected: names.iter().map(|s| s.to_string()).collect(),
            seen: vec![None; names.len()],
            lost: vec![false; names.len()],
        }
    }

    /// Reaps dead nodes of the run and returns the watched peers that were seen
    /// alive before and are not alive any more (each reported once).
    pub fn poll(&mut self, run: &RunScope) -> Result<Vec<PeerInfo>> {
        let report = reap_dead_nodes(run)?;
        let mut newly_lost = Vec::new();
        for (i, name) in self.expected.iter().enumerate() {
            let alive = report.alive.iter().find(|p| &p.name == name);
            match (alive, &self.seen[i]) {
                (Some(p), _) => {
                    self.seen[i] = Some(p.clone());
                    self.lost[i] = false;
                }
                (None, Some(p)) if !self.lost[i] => {
                    self.lost[i] = true;
                    newly_lost.push(p.clone());
                }
                _ => {}
            }
        }
        Ok(newly_lost)
    }

    /// Watched peers currently alive (as of the last poll).
    pub fn alive(&self) -> Vec<&str> {
        self.expected
            .iter()
            .enumerate()
            .filter(|(i, _)| self.seen[*i].is_some() && !self.lost[*i])
            .map(|(_, n)| n.as_str())
            .collect()
    }
}
