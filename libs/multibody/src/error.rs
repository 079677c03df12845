//! Errors raised while loading and validating a servicer URDF.

use std::path::PathBuf;

/// A URDF that cannot be turned into a valid 7-DoF servicer model. Every variant names the
/// offending link/joint, the value found and the rule it breaks.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    #[error("cannot read URDF file '{path}': {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot parse URDF: {0}")]
    Parse(String),
    #[error("link '{link}': mass {value} kg is invalid (rule: mass must be finite and >= 0)")]
    InvalidMass { link: String, value: f64 },
    #[error(
        "link '{link}': inertia has principal moments {moments:?} kg m^2 (rule: inertia must be \
         finite and positive definite for a link with mass > 0, and all zero for a massless link)"
    )]
    NonPositiveDefiniteInertia { link: String, moments: [f64; 3] },
    #[error(
        "link '{link}': principal moments {moments:?} kg m^2 violate the triangle inequality \
         (rule: I1 + I2 >= I3 for every permutation)"
    )]
    TriangleInequality { link: String, moments: [f64; 3] },
    #[error("{element}: non-finite value {value} in '{field}' (rule: all numbers must be finite)")]
    NonFinite {
        element: String,
        field: &'static str,
        value: f64,
    },
    #[error("joint '{joint}': axis {axis:?} has (near-)zero length (rule: |axis| > 1e-9)")]
    ZeroAxis { joint: String, axis: [f64; 3] },
    #[error(
        "joint '{joint}': lower limit {lower} rad > upper limit {upper} rad (rule: lower <= upper, both finite)"
    )]
    LimitOrder {
        joint: String,
        lower: f64,
        upper: f64,
    },
    #[error("joint '{joint}': velocity limit {value} rad/s (rule: finite and > 0)")]
    InvalidVelocityLimit { joint: String, value: f64 },
    #[error("joint '{joint}': effort limit {value} N m (rule: finite and > 0)")]
    InvalidEffortLimit { joint: String, value: f64 },
    #[error(
        "joint '{joint}': type '{kind}' is not supported (rule: only 'revolute' and 'fixed' joints)"
    )]
    UnsupportedJoint { joint: String, kind: String },
    #[error("found {found} revolute joints (rule: exactly {expected} revolute joints)")]
    JointCount { found: usize, expected: usize },
    #[error(
        "joint '{joint}' refers to unknown link '{link}' (rule: parent/child links must exist)"
    )]
    UnknownLink { joint: String, link: String },
    #[error("duplicate {what} name '{name}' (rule: names must be unique)")]
    DuplicateName { what: &'static str, name: String },
    #[error("link '{link}' is the child of more than one joint (rule: the links must form a tree)")]
    NotATree { link: String },
    #[error("found {count} root links {names:?} (rule: exactly one link without parent joint)")]
    RootCount { count: usize, names: Vec<String> },
    #[error("links {names:?} are not connected to the root (rule: the links must form one tree)")]
    Disconnected { names: Vec<String> },
    #[error(
        "joint '{joint}': a second revolute joint on the same moving body (rule: the 7 revolute \
         joints must form one serial chain from the root)"
    )]
    NotSerialChain { joint: String },
    #[error(
        "body of link '{link}' has total mass {mass} kg (rule: the base and every arm body need mass > 0)"
    )]
    MasslessBody { link: String, mass: f64 },
    #[error(
        "link '{link}': collision #{index}: {detail} (rule: collision geometry must be spheres with finite radius > 0)"
    )]
    InvalidCollision {
        link: String,
        index: usize,
        detail: String,
    },
}
