//! The navigation process of the partition (the default navigation: the declared error
//! model); a partner replaces it with its own estimator.
use sc_flight::roles::NavigationRole;
use sc_icd::RoleKind;

fn main() -> std::process::ExitCode {
    sc_flight::runner::main(RoleKind::Navigation, NavigationRole::from_process)
}
