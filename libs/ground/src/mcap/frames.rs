//! The frames of Foxglove's 3D panel: every state's frame transforms on [`TF_TOPIC`]
//! (`foxglove.FrameTransform`), in the project's conventions turned into Foxglove's.

use super::NS_PER_S;
use super::json::JsonMsg;
use serde_json::{Value, json};

/// Topic of the frame transforms (Foxglove's 3D panel reads `foxglove.FrameTransform`).
pub const TF_TOPIC: &str = "/tf";
/// Frame id of the reference frame F_R (origin at the target's centre of mass).
pub const FRAME_REFERENCE: &str = "reference";
/// Frame id of the servicer body frame F_B (origin at the base origin).
pub const FRAME_SERVICER: &str = "servicer_body";
/// Frame id of the target body frame F_T (origin at the target's centre of mass).
pub const FRAME_TARGET: &str = "target_body";
/// Frame id of the end effector (its position only: see [`FrameTransform`]).
pub const FRAME_END_EFFECTOR: &str = "end_effector";
/// Frame id of the servicer system's centre of mass with the body's orientation: the
/// point the corridor, the zone and the line of sight constrain (`sc_cbf::monitor`).
pub const FRAME_SERVICER_COM: &str = "servicer_com";

/// One `foxglove.FrameTransform`: the pose of `child` in `parent`. `rotation` is
/// Foxglove's `[x, y, z, w]`, rotating child-frame vectors into the parent frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTransform {
    /// Mission time [ns].
    pub log_ns: u64,
    pub parent: &'static str,
    pub child: &'static str,
    /// Child origin in the parent frame [m].
    pub translation: [f64; 3],
    /// Unit quaternion `[x, y, z, w]` [-].
    pub rotation: [f64; 4],
}

/// A project quaternion q_AB (scalar first, rotates F_B vectors into F_A) as
/// Foxglove's rotation of child B in parent A: the same rotation, scalar last.
pub fn foxglove_rotation(q_ab: [f64; 4]) -> [f64; 4] {
    [q_ab[1], q_ab[2], q_ab[3], q_ab[0]]
}

impl FrameTransform {
    /// The frames a state message carries: reference → servicer body (`r_r`, `q_rb`),
    /// reference → target body (the target's centre of mass is F_R's origin; `q_rt`) and
    /// servicer body → end effector (`ee_b`; the state carries no end-effector
    /// attitude, so this frame keeps the body's orientation) and reference → servicer
    /// centre of mass (`com_r`, `q_rb`: the apex of the line of sight).
    pub fn of_state(s: &sc_icd::SimState, log_ns: u64) -> [Self; 4] {
        const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];
        [
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_SERVICER,
                translation: s.r_r,
                rotation: foxglove_rotation(s.q_rb),
            },
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_TARGET,
                translation: [0.0; 3],
                rotation: foxglove_rotation(s.q_rt),
            },
            Self {
                log_ns,
                parent: FRAME_SERVICER,
                child: FRAME_END_EFFECTOR,
                translation: s.ee_b,
                rotation: IDENTITY,
            },
            Self {
                log_ns,
                parent: FRAME_REFERENCE,
                child: FRAME_SERVICER_COM,
                translation: s.com_r,
                rotation: foxglove_rotation(s.q_rb),
            },
        ]
    }
}

impl JsonMsg for FrameTransform {
    fn write_json(&self, out: &mut Vec<u8>) {
        let [x, y, z] = self.translation;
        let [qx, qy, qz, qw] = self.rotation;
        let _ = serde_json::to_writer(
            &mut *out,
            &json!({
                "timestamp": {"sec": self.log_ns / NS_PER_S, "nsec": self.log_ns % NS_PER_S},
                "parent_frame_id": self.parent,
                "child_frame_id": self.child,
                "translation": {"x": x, "y": y, "z": z},
                "rotation": {"x": qx, "y": qy, "z": qz, "w": qw},
            }),
        );
    }
    fn json_schema() -> Value {
        super::schemas::frame_transform()
    }
    fn name() -> &'static str {
        "foxglove.FrameTransform"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::scene::SCENE_TOPIC;
    use crate::mcap::test_util::foxglove_rotate;
    use crate::mcap::writer::McapOut;

    /// The frames of a state: the project's q_AB (scalar first) rotates a child (B)
    /// vector into the parent (A) exactly as Foxglove's rotation does; the positions are
    /// the state's; the channel reads back as `foxglove.FrameTransform` JSON.
    #[test]
    fn state_frames_follow_foxglove_convention_and_read_back() {
        let n = (0.3f64 * 0.3 + 0.5 * 0.5 + 0.1 * 0.1 + 0.8 * 0.8).sqrt();
        let q_rb = [0.8 / n, 0.3 / n, -0.5 / n, 0.1 / n];
        let q_rt = [0.6, 0.0, 0.8, 0.0];
        let state = sc_icd::SimState {
            tick: 12,
            r_r: [1.0, -2.0, 3.5],
            q_rb,
            q_rt,
            ee_b: [0.25, 0.5, -0.75],
            ..Default::default()
        };
        let log_ns = 1_200_000_123;
        let frames = FrameTransform::of_state(&state, log_ns);
        let v = [0.2, -1.0, 0.7];
        for (f, q) in [(&frames[0], q_rb), (&frames[1], q_rt)] {
            let ours = sc_models::quat::rotate(&q, &nalgebra::Vector3::new(v[0], v[1], v[2]));
            let theirs = foxglove_rotate(f.rotation, v);
            for k in 0..3 {
                assert!((ours[k] - theirs[k]).abs() < 1e-12, "{ours:?} {theirs:?}");
            }
        }
        assert_eq!(
            (frames[0].parent, frames[0].child),
            (FRAME_REFERENCE, FRAME_SERVICER)
        );
        assert_eq!(frames[0].translation, state.r_r);
        assert_eq!(
            (frames[1].parent, frames[1].child),
            (FRAME_REFERENCE, FRAME_TARGET)
        );
        assert_eq!(frames[1].translation, [0.0; 3]);
        assert_eq!(
            (frames[2].parent, frames[2].child),
            (FRAME_SERVICER, FRAME_END_EFFECTOR)
        );
        assert_eq!(frames[2].translation, state.ee_b);
        assert_eq!(
            (frames[3].parent, frames[3].child),
            (FRAME_REFERENCE, FRAME_SERVICER_COM)
        );
        assert_eq!(frames[3].translation, state.com_r);
        assert_eq!(frames[3].rotation, frames[0].rotation);

        let dir = std::env::temp_dir().join(format!("sc-mcap-tf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tf.mcap");
        let mut out = McapOut::create(&path).unwrap();
        out.write_3d(log_ns, 7, &state).unwrap();
        out.finish().unwrap();
        assert_eq!(out.written[TF_TOPIC], 4);
        assert!(!out.written.contains_key(SCENE_TOPIC), "no scene set");
        drop(out);
        let bytes = std::fs::read(&path).unwrap();
        let msgs: Vec<_> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(|m| m.unwrap())
            .collect();
        assert_eq!(msgs.len(), 4);
        let m = &msgs[0];
        assert_eq!(m.channel.topic, TF_TOPIC);
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.name, "foxglove.FrameTransform");
        let v: Value = serde_json::from_slice(&m.data).unwrap();
        assert_eq!(v["timestamp"], json!({"sec": 1, "nsec": 200_000_123}));
        assert_eq!(v["parent_frame_id"], FRAME_REFERENCE);
        assert_eq!(v["child_frame_id"], FRAME_SERVICER);
        assert_eq!(v["translation"], json!({"x": 1.0, "y": -2.0, "z": 3.5}));
        assert_eq!(v["rotation"]["w"], q_rb[0]);
        assert_eq!(v["rotation"]["x"], q_rb[1]);
        let sch: Value = serde_json::from_slice(&schema.data).unwrap();
        let props = sch["properties"].as_object().unwrap();
        assert_eq!(
            props.keys().collect::<Vec<_>>(),
            v.as_object().unwrap().keys().collect::<Vec<_>>()
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
