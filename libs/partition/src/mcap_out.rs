//! MCAP output of the recorder: one channel per service, JSON-encoded messages with
//! a JSON schema each (Foxglove plots every numeric field).

use anyhow::Context;
use serde_json::{Map, Value, json};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// A message field as JSON, written straight into the output buffer (no
/// intermediate `serde_json::Value`: the recorder writes every message of a run).
pub trait JsonField {
    fn write_json(&self, out: &mut Vec<u8>);
    fn schema() -> Value;
}
impl JsonField for u64 {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(&mut *out, self);
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for u32 {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(&mut *out, self);
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for f64 {
    // NaN/inf are not JSON numbers: written as null
    fn write_json(&self, out: &mut Vec<u8>) {
        if self.is_finite() {
            // serde_json's shortest round-trip formatting of a finite f64
            let _ = serde_json::to_writer(&mut *out, self);
        } else {
            out.extend_from_slice(b"null");
        }
    }
    fn schema() -> Value {
        json!({"type": ["number", "null"]})
    }
}
impl<const N: usize> JsonField for [f64; N] {
    fn write_json(&self, out: &mut Vec<u8>) {
        out.push(b'[');
        for (i, x) in self.iter().enumerate() {
            if i > 0 {
                out.push(b',');
            }
            x.write_json(out);
        }
        out.push(b']');
    }
    fn schema() -> Value {
        json!({"type": "array", "items": {"type": ["number", "null"]}, "minItems": N, "maxItems": N})
    }
}

/// An ICD message as a JSON object, with its JSON schema.
pub trait JsonMsg {
    /// Writes the message as one JSON object (fields in declaration order) to `out`.
    fn write_json(&self, out: &mut Vec<u8>);
    fn json_schema() -> Value;
    fn name() -> &'static str;
}

macro_rules! json_msg {
    ($t:ident { $first:ident $(, $f:ident)* $(,)? }) => {
        impl JsonMsg for sc_icd::$t {
            fn write_json(&self, out: &mut Vec<u8>) {
                out.extend_from_slice(concat!("{\"", stringify!($first), "\":").as_bytes());
                JsonField::write_json(&self.$first, out);
                $(
                    out.extend_from_slice(concat!(",\"", stringify!($f), "\":").as_bytes());
                    JsonField::write_json(&self.$f, out);
                )*
                out.push(b'}');
            }
            fn json_schema() -> Value {
                let mut p = Map::new();
                p.insert(stringify!($first).into(), field_schema(&|s: &sc_icd::$t| s.$first));
                $( p.insert(stringify!($f).into(), field_schema(&|s: &sc_icd::$t| s.$f)); )*
                json!({"title": sc_icd::type_name_of::<sc_icd::$t>(), "type": "object", "properties": Value::Object(p)})
            }
            fn name() -> &'static str { sc_icd::type_name_of::<sc_icd::$t>() }
        }
    };
}

fn field_schema<T, F: JsonField>(_: &dyn Fn(&T) -> F) -> Value {
    F::schema()
}

json_msg!(Tick {
    tick,
    due_mask,
    clock_mode,
    t,
    send_ns,
    command
});
json_msg!(SimState {
    tick,
    t,
    due_mask,
    tick_send_ns,
    recv_ns,
    publish_ns,
    step,
    r_h,
    v_h,
    r_r,
    v_r,
    q_hr,
    omega_h,
    omega_dot_h,
    mean_motion,
    q_rb,
    omega_b,
    theta,
    theta_dot,
    q_rt,
    omega_t,
    omega_dot_t,
    grasp_r,
    grasp_v_r,
    grasp_a_r,
    grasp_b,
    ee_b,
    ee_r,
    ee_v_r
});
json_msg!(NominalTranslational {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    f_h
});
json_msg!(NominalAttitude {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    tau_b
});
json_msg!(NominalRobotic {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    tau_m
});
json_msg!(SafeTranslational {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solve_cpu_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(SafeAttitude {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solve_cpu_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(SafeRobotic {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solve_cpu_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(StepResult {
    tick,
    t,
    end,
    fallback_mask,
    held_mask,
    fault_flags,
    safe_recv_ns,
    publish_ns,
    force_b,
    torque_b,
    tau
});

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
/// Nanoseconds per second, for Foxglove's `{sec, nsec}` timestamps.
const NS_PER_S: u64 = 1_000_000_000;

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
    /// attitude, so this frame keeps the body's orientation).
    pub fn of_state(s: &sc_icd::SimState, log_ns: u64) -> [Self; 3] {
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
    /// Foxglove's `foxglove.FrameTransform` JSON schema (docs.foxglove.dev).
    fn json_schema() -> Value {
        let num = |d: &str| json!({"type": "number", "description": d});
        let int = |d: &str| json!({"type": "integer", "minimum": 0, "description": d});
        let string = |d: &str| json!({"type": "string", "description": d});
        json!({
            "title": "foxglove.FrameTransform",
            "description": "A transform between two reference frames in 3D space",
            "type": "object",
            "properties": {
                "timestamp": {
                    "type": "object",
                    "title": "time",
                    "description": "Timestamp of transform (mission time)",
                    "properties": {"sec": int("seconds"), "nsec": int("nanoseconds")}
                },
                "parent_frame_id": string("Name of the parent frame"),
                "child_frame_id": string("Name of the child frame"),
                "translation": {
                    "type": "object",
                    "title": "foxglove.Vector3",
                    "description": "Translation component of the transform [m]",
                    "properties": {"x": num("x [m]"), "y": num("y [m]"), "z": num("z [m]")}
                },
                "rotation": {
                    "type": "object",
                    "title": "foxglove.Quaternion",
                    "description": "Rotation component of the transform (rotates child-frame vectors into the parent frame)",
                    "properties": {"x": num("x [-]"), "y": num("y [-]"), "z": num("z [-]"), "w": num("w [-]")}
                }
            }
        })
    }
    fn name() -> &'static str {
        "foxglove.FrameTransform"
    }
}

/// The MCAP file being written.
pub struct McapOut {
    w: mcap::Writer<BufWriter<std::fs::File>>,
    channels: BTreeMap<String, u16>,
    seq: u32,
    /// The JSON of the message being written (reused).
    buf: Vec<u8>,
    /// Messages written per topic.
    pub written: BTreeMap<String, u64>,
}

impl McapOut {
    /// Creates `path`.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let f = std::fs::File::create(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        // LZ4 chunks on the recorder's own thread: zstd (the crate's default) took a
        // fifth of the recorder's CPU time and ran worker threads beside the
        // partition's processes on a 2-core machine; Foxglove reads both.
        let w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Lz4))
            .create(BufWriter::new(f))
            .context("mcap header")?;
        Ok(Self {
            w,
            channels: BTreeMap::new(),
            seq: 0,
            buf: Vec::with_capacity(4096),
            written: BTreeMap::new(),
        })
    }

    /// Writes one message on topic `topic`: `log_ns` is its mission time [ns since the
    /// mission's start] (what Foxglove's timeline shows), `publish_ns` the host's monotonic
    /// clock when it was published (kept in the record's `publish_time`).
    pub fn write<T: JsonMsg>(
        &mut self,
        topic: &str,
        log_ns: u64,
        publish_ns: u64,
        msg: &T,
    ) -> anyhow::Result<()> {
        let id = match self.channels.get(topic) {
            Some(id) => *id,
            None => {
                let schema = serde_json::to_vec(&T::json_schema())?;
                let sid = self
                    .w
                    .add_schema(T::name(), "jsonschema", &schema)
                    .context("mcap schema")?;
                let cid = self
                    .w
                    .add_channel(sid, topic, "json", &BTreeMap::new())
                    .context("mcap channel")?;
                self.channels.insert(topic.to_string(), cid);
                cid
            }
        };
        self.seq = self.seq.wrapping_add(1);
        self.buf.clear();
        msg.write_json(&mut self.buf);
        self.w
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: self.seq,
                    log_time: log_ns,
                    publish_time: publish_ns,
                },
                &self.buf,
            )
            .context("mcap write")?;
        *self.written.entry(topic.to_string()).or_default() += 1;
        Ok(())
    }

    /// Writes the frame transforms of state `s` on [`TF_TOPIC`] ([`FrameTransform::of_state`]).
    pub fn write_frames(
        &mut self,
        log_ns: u64,
        publish_ns: u64,
        s: &sc_icd::SimState,
    ) -> anyhow::Result<()> {
        for f in FrameTransform::of_state(s, log_ns) {
            self.write(TF_TOPIC, log_ns, publish_ns, &f)?;
        }
        Ok(())
    }

    /// Writes an MCAP `Metadata` record `name` with the key/value pairs `entries`
    /// (Foxglove shows them in its "Metadata" panel of the file).
    pub fn write_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> anyhow::Result<()> {
        self.w
            .write_metadata(&mcap::records::Metadata {
                name: name.to_string(),
                metadata: entries,
            })
            .context("mcap metadata")?;
        Ok(())
    }

    /// Writes the summary section and closes the file.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        self.w.finish().context("mcap finish")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the recorder writes reads back as MCAP: one channel per topic with its
    /// JSON schema, every message valid JSON with all fields, NaN as null.
    #[test]
    fn messages_read_back_as_json_with_schemas() {
        let dir = std::env::temp_dir().join(format!("sc-mcap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.mcap");
        let mut state = sc_icd::SimState {
            tick: 7,
            t: 0.7,
            ..Default::default()
        };
        state.theta[6] = -1.25e-3;
        state.r_h = [1.0, f64::NAN, f64::INFINITY];
        let mut safe = sc_icd::SafeRobotic {
            tick: 7,
            ..Default::default()
        };
        safe.h[41] = 0.5;
        let mut out = McapOut::create(&path).unwrap();
        for k in 0..3u64 {
            state.tick = k;
            out.write("sim/state", 100 + k, 5000 + k, &state).unwrap();
        }
        out.write("safe/robotic", 200, 6000, &safe).unwrap();
        out.finish().unwrap();
        assert_eq!(out.written["sim/state"], 3);
        drop(out);

        let bytes = std::fs::read(&path).unwrap();
        let mut seen = Vec::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.encoding, "jsonschema");
            assert_eq!(m.channel.message_encoding, "json");
            let sch: Value = serde_json::from_slice(&schema.data).unwrap();
            let v: Value = serde_json::from_slice(&m.data).unwrap();
            // every schema property is in the message and nothing else
            let props = sch["properties"].as_object().unwrap();
            let obj = v.as_object().unwrap();
            assert_eq!(
                props.keys().collect::<Vec<_>>(),
                obj.keys().collect::<Vec<_>>()
            );
            seen.push((m.channel.topic.clone(), m.log_time, v));
            assert!(
                m.publish_time >= 5000,
                "publish_time keeps the host's clock"
            );
        }
        assert_eq!(seen.len(), 4);
        let (topic, log_time, v) = &seen[2];
        assert_eq!((topic.as_str(), *log_time), ("sim/state", 102));
        assert_eq!(v["tick"], 2);
        assert_eq!(v["t"], 0.7);
        assert_eq!(v["theta"][6], -1.25e-3);
        assert_eq!(v["r_h"], json!([1.0, null, null]));
        assert_eq!(v["theta"].as_array().unwrap().len(), sc_icd::N_JOINTS);
        let (topic, _, v) = &seen[3];
        assert_eq!(topic, "safe/robotic");
        assert_eq!(
            v["h"].as_array().unwrap().len(),
            sc_icd::N_CONSTRAINTS_ROBOTIC
        );
        assert_eq!(v["h"][41], 0.5);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A metadata record reads back by name with its key/value pairs, beside messages.
    #[test]
    fn metadata_record_reads_back() {
        let dir = std::env::temp_dir().join(format!("sc-mcap-meta-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.mcap");
        let entries = BTreeMap::from([
            ("version".to_string(), "1.2.3".to_string()),
            (
                "scenario".to_string(),
                "[mission]\nname = \"x\"\n".to_string(),
            ),
        ]);
        let mut out = McapOut::create(&path).unwrap();
        out.write_metadata("safe-capture", entries.clone()).unwrap();
        let state = sc_icd::SimState::default();
        out.write("sim/state", 0, 1, &state).unwrap();
        out.finish().unwrap();
        drop(out);

        let bytes = std::fs::read(&path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert_eq!(summary.metadata_indexes.len(), 1);
        let idx = &summary.metadata_indexes[0];
        assert_eq!(idx.name, "safe-capture");
        let m = mcap::read::metadata(&bytes, idx).unwrap();
        assert_eq!(m.name, "safe-capture");
        assert_eq!(m.metadata, entries);
        assert_eq!(mcap::MessageStream::new(&bytes).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Foxglove's rotation of a child frame, `[x, y, z, w]` applied as `v' = q v q*`
    /// (its convention: child-frame vectors into the parent frame).
    fn foxglove_rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
        let [x, y, z, w] = q;
        let u = nalgebra::Vector3::new(x, y, z);
        let v = nalgebra::Vector3::new(v[0], v[1], v[2]);
        let t = 2.0 * u.cross(&v);
        let r = v + w * t + u.cross(&t);
        [r[0], r[1], r[2]]
    }

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

        let dir = std::env::temp_dir().join(format!("sc-mcap-tf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tf.mcap");
        let mut out = McapOut::create(&path).unwrap();
        out.write_frames(log_ns, 7, &state).unwrap();
        out.finish().unwrap();
        assert_eq!(out.written[TF_TOPIC], 3);
        drop(out);
        let bytes = std::fs::read(&path).unwrap();
        let msgs: Vec<_> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(|m| m.unwrap())
            .collect();
        assert_eq!(msgs.len(), 3);
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
