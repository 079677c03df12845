//! `[hosts]` of the partition config: the partition across hosts (docs/PARTITION.md,
//! "Across hosts"). Each host runs its share of the roles and one `sc-link` (iceoryx2's
//! Zenoh link) through which the services cross; the home host runs the scheduler, the
//! simulator and the recorder — the run's clock, truth and outputs — and every role
//! that names no `host`.
//!
//! ```toml
//! [hosts]
//! home = "ground"
//! link = { ground = "tcp/127.201.0.1:7447", flight = "tcp/127.201.0.2:7447" }
//! [roles.safety_translational]
//! host = "flight"
//! ```

use crate::config::ConfigError;
use sc_icd::{ROLES, Role, RoleKind};
use serde::Deserialize;
use std::collections::BTreeMap;

/// Environment variable the launcher sets (to `1`) for every process of a run that
/// crosses hosts: a partner's process in another language (scripts/python/sc_partner)
/// opens the services with the link's ports counted in ([`crate::process::Qos`]).
pub const ACROSS_HOSTS_ENV: &str = "SC_ACROSS_HOSTS";

/// Environment variable the launcher sets (to `1`) for every process away from the home
/// host: a partner's process in another language marks its start (`all_ready`) there, as
/// the Rust roles do (the scheduler's mark is in the home host's folder).
pub const AWAY_FROM_HOME_ENV: &str = "SC_AWAY_FROM_HOME";

/// The roles that always run on the home host: the run's clock (scheduler), its truth
/// (simulator) and its outputs (recorder).
pub const HOME_ROLES: [RoleKind; 3] =
    [RoleKind::Scheduler, RoleKind::Simulator, RoleKind::Recorder];

/// `[hosts]`: which hosts the run spans and where each one's link listens.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Hosts {
    /// The host with the scheduler, the simulator, the recorder and every role whose
    /// `[roles.<name>]` names no `host`; its launch writes the run's outputs.
    pub home: String,
    /// Per host (by name) the Zenoh endpoint its `sc-link` listens on, e.g.
    /// `tcp/10.0.0.2:7447`; each host's link connects to every other host's.
    pub link: BTreeMap<String, String>,
}

fn err<T>(msg: impl Into<String>) -> Result<T, ConfigError> {
    Err(ConfigError(msg.into()))
}

/// A host name: `[A-Za-z0-9_-]+` (it appears in file names and on command lines).
fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

impl Hosts {
    /// At least two hosts with sane names and endpoints, the home among them, every
    /// role's `host` one of them and the home roles at home.
    pub fn validate<'a>(
        &self,
        role_hosts: impl Iterator<Item = (&'a str, Option<&'a str>)>,
    ) -> Result<(), ConfigError> {
        if self.link.len() < 2 {
            return err(format!(
                "hosts.link names {} host(s): a run across hosts needs at least two (remove [hosts] to run on one)",
                self.link.len()
            ));
        }
        for (name, endpoint) in &self.link {
            if !valid_name(name) {
                return err(format!(
                    "hosts.link.{name}: a host name is letters, digits, '-' and '_'"
                ));
            }
            if endpoint.trim().is_empty() || endpoint.contains(['"', '\\', ' ']) {
                return err(format!(
                    "hosts.link.{name} = {endpoint:?}: a Zenoh endpoint like \"tcp/10.0.0.2:7447\" (no spaces, quotes or backslashes)"
                ));
            }
        }
        let mut endpoints: Vec<&str> = self.link.values().map(|e| e.trim()).collect();
        endpoints.sort_unstable();
        if let Some(w) = endpoints.windows(2).find(|w| w[0] == w[1]) {
            return err(format!(
                "hosts.link: two hosts listen on {:?} (each host's link needs its own endpoint)",
                w[0]
            ));
        }
        if !self.link.contains_key(&self.home) {
            return err(format!(
                "hosts.home = {:?}: not a host of hosts.link ({})",
                self.home,
                self.names().join(", ")
            ));
        }
        for (role, host) in role_hosts {
            let Some(host) = host else { continue };
            if !self.link.contains_key(host) {
                return err(format!(
                    "roles.{role}.host = {host:?}: not a host of hosts.link ({})",
                    self.names().join(", ")
                ));
            }
            let kind = Role::named(role).map(|r| r.kind);
            if host != self.home && kind.is_some_and(|k| HOME_ROLES.contains(&k)) {
                return err(format!(
                    "roles.{role}.host = {host:?}: the scheduler, the simulator and the recorder run on the home host {:?} (the run's clock, truth and outputs)",
                    self.home
                ));
            }
        }
        Ok(())
    }

    /// The host names, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.link.keys().map(String::as_str).collect()
    }

    /// The endpoints of every host but `host` (what its link connects to).
    pub fn others(&self, host: &str) -> Vec<&str> {
        self.link
            .iter()
            .filter(|(n, _)| *n != host)
            .map(|(_, e)| e.as_str())
            .collect()
    }
}

/// A role names no host in a config without `[hosts]`.
pub fn check_no_host<'a>(
    mut role_hosts: impl Iterator<Item = (&'a str, Option<&'a str>)>,
) -> Result<(), ConfigError> {
    match role_hosts.find(|(_, h)| h.is_some()) {
        Some((role, Some(h))) => err(format!(
            "roles.{role}.host = {h:?}: no [hosts] section names the hosts and their links"
        )),
        _ => Ok(()),
    }
}

/// The roles of the table that run on `host`, in start order.
pub fn roles_on<'a>(
    host_of: impl Fn(&str) -> &'a str + 'a,
    host: &'a str,
) -> impl Iterator<Item = &'static Role> + 'a {
    ROLES.iter().filter(move |r| host_of(r.name) == host)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hosts() -> Hosts {
        Hosts {
            home: "ground".into(),
            link: [
                ("ground".to_string(), "tcp/127.0.0.1:7447".to_string()),
                ("flight".to_string(), "tcp/127.0.0.2:7447".to_string()),
            ]
            .into(),
        }
    }

    #[test]
    fn a_filter_may_run_away_from_home_but_the_simulator_may_not() {
        let h = hosts();
        let ok = [
            ("safety_robotic", Some("flight")),
            ("nominal_robotic", None),
        ];
        assert!(h.validate(ok.into_iter()).is_ok());
        let bad = [("simulator", Some("flight"))];
        let e = h.validate(bad.into_iter()).unwrap_err().0;
        assert!(
            e.contains("roles.simulator.host") && e.contains("home host"),
            "{e}"
        );
        let unknown = [("safety_robotic", Some("moon"))];
        let e = h.validate(unknown.into_iter()).unwrap_err().0;
        assert!(
            e.contains("not a host of hosts.link (flight, ground)"),
            "{e}"
        );
    }

    #[test]
    fn one_host_a_missing_home_and_bad_endpoints_are_refused() {
        let mut h = hosts();
        h.home = "moon".into();
        let e = h.validate(std::iter::empty()).unwrap_err().0;
        assert!(e.contains("hosts.home = \"moon\""), "{e}");
        let mut h = hosts();
        h.link.remove("flight");
        let e = h.validate(std::iter::empty()).unwrap_err().0;
        assert!(e.contains("at least two"), "{e}");
        let mut h = hosts();
        h.link.insert("flight".into(), "tcp/\"x".into());
        let e = h.validate(std::iter::empty()).unwrap_err().0;
        assert!(e.contains("hosts.link.flight"), "{e}");
        let mut h = hosts();
        h.link.insert("flight".into(), "tcp/127.0.0.1:7447".into());
        let e = h.validate(std::iter::empty()).unwrap_err().0;
        assert!(e.contains("two hosts listen on"), "{e}");
        let e = check_no_host([("safety_robotic", Some("flight"))].into_iter())
            .unwrap_err()
            .0;
        assert!(e.contains("no [hosts] section"), "{e}");
    }

    #[test]
    fn each_host_connects_to_the_others() {
        assert_eq!(hosts().others("ground"), ["tcp/127.0.0.2:7447"]);
        let host_of = |r: &str| {
            if r.starts_with("safety") {
                "flight"
            } else {
                "ground"
            }
        };
        let flight: Vec<&str> = roles_on(host_of, "flight").map(|r| r.name).collect();
        assert_eq!(
            flight,
            ["safety_translational", "safety_attitude", "safety_robotic"]
        );
    }
}
