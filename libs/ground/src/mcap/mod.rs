//! MCAP output of the recorder: one channel per service, JSON-encoded messages with a
//! JSON schema each (Foxglove plots every numeric field), the frames and the scene of
//! Foxglove's 3D panel, and the Foxglove layout shipped with the project. By concern:
//!
//! * [`writer`]: [`McapOut`], the file being written (channels, metadata, summary);
//! * [`json`]: [`JsonMsg`], a message as JSON with its schema; every ICD message is
//!   written by one generic writer over its description (`sc_icd::spec`), its schema
//!   generated from the same description (`sc_icd_gen::json_schema`);
//! * [`frames`]: the frame transforms of a state on [`TF_TOPIC`];
//! * [`scene`]: the scenario's safety geometry on [`SCENE_TOPIC`];
//! * [`schemas`]: the JSON schemas of the Foxglove types written (`foxglove.*`);
//! * [`layout`]: the Foxglove layout of a recording ([`LAYOUT_FILE`]).

pub mod frames;
pub mod json;
pub mod layout;
pub mod scene;
pub mod schemas;
pub mod writer;

#[cfg(test)]
mod test_util;

pub use frames::{
    FRAME_END_EFFECTOR, FRAME_REFERENCE, FRAME_SERVICER, FRAME_SERVICER_COM, FRAME_TARGET,
    FrameTransform, TF_TOPIC, foxglove_rotation,
};
pub use json::JsonMsg;
pub use layout::{LAYOUT_FILE, foxglove_layout};
pub use sc_icd_gen::barriers::barrier_unit;
pub use scene::{
    Cone, ENTITY_CORRIDOR, ENTITY_GRASP, ENTITY_LINE_OF_SIGHT, ENTITY_ZONE, SCENE_TOPIC, Scene,
    SceneGeometry, SceneUpdate,
};
pub use writer::{McapError, McapOut};

/// Nanoseconds per second, for Foxglove's `{sec, nsec}` timestamps.
const NS_PER_S: u64 = 1_000_000_000;
