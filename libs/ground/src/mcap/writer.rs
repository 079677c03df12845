//! The MCAP file the recorder writes: one channel per topic, created with its JSON
//! schema at the topic's first message; LZ4 chunks; metadata records; the summary.

use super::frames::{FrameTransform, TF_TOPIC};
use super::json::JsonMsg;
use super::scene::{SCENE_TOPIC, Scene};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// What can go wrong writing the MCAP file.
#[derive(Debug, thiserror::Error)]
pub enum McapError {
    /// The file cannot be created.
    #[error("cannot create {path}: {source}")]
    Create {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The MCAP writer failed at `what` (header, schema, channel, message, metadata, finish).
    #[error("mcap {what}: {source}")]
    Mcap {
        what: &'static str,
        source: mcap::McapError,
    },
    /// A schema could not be serialised.
    #[error("mcap schema: {0}")]
    Schema(#[from] serde_json::Error),
}

/// `result` with its MCAP error named by `what`.
fn at<T>(what: &'static str, result: Result<T, mcap::McapError>) -> Result<T, McapError> {
    result.map_err(|source| McapError::Mcap { what, source })
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
    /// The scene written with the states ([`McapOut::write_3d`]), once set.
    scene: Option<Scene>,
}

impl McapOut {
    /// Creates `path`.
    pub fn create(path: &Path) -> Result<Self, McapError> {
        let f = std::fs::File::create(path).map_err(|source| McapError::Create {
            path: path.to_path_buf(),
            source,
        })?;
        // LZ4 chunks on the recorder's own thread: zstd (the crate's default) took a
        // fifth of the recorder's CPU time and ran worker threads beside the
        // partition's processes on a 2-core machine; Foxglove reads both.
        let w = at(
            "header",
            mcap::WriteOptions::new()
                .compression(Some(mcap::Compression::Lz4))
                .create(BufWriter::new(f)),
        )?;
        Ok(Self {
            w,
            channels: BTreeMap::new(),
            seq: 0,
            buf: Vec::with_capacity(4096),
            written: BTreeMap::new(),
            scene: None,
        })
    }

    /// From now on [`McapOut::write_3d`] also writes the scene of `scenario` on
    /// [`SCENE_TOPIC`] (see [`Scene`]).
    pub fn set_scene(&mut self, scenario: &sc_scenario::Scenario) {
        self.scene = Some(Scene::new(scenario));
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
    ) -> Result<(), McapError> {
        let id = match self.channels.get(topic) {
            Some(id) => *id,
            None => {
                let schema = serde_json::to_vec(&T::json_schema())?;
                let sid = at(
                    "schema",
                    self.w.add_schema(T::name(), "jsonschema", &schema),
                )?;
                let cid = at(
                    "channel",
                    self.w.add_channel(sid, topic, "json", &BTreeMap::new()),
                )?;
                self.channels.insert(topic.to_string(), cid);
                cid
            }
        };
        self.seq = self.seq.wrapping_add(1);
        self.buf.clear();
        msg.write_json(&mut self.buf);
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: self.seq,
            log_time: log_ns,
            publish_time: publish_ns,
        };
        at("write", self.w.write_to_known_channel(&header, &self.buf))?;
        *self.written.entry(topic.to_string()).or_default() += 1;
        Ok(())
    }

    /// Writes what the 3D panel needs of state `s`: its frame transforms on
    /// [`TF_TOPIC`] ([`FrameTransform::of_state`]) and, when due, the scene on
    /// [`SCENE_TOPIC`] (after the frames it refers to; see [`Scene`]).
    pub fn write_3d(
        &mut self,
        log_ns: u64,
        publish_ns: u64,
        s: &sc_icd::SimState,
    ) -> Result<(), McapError> {
        for f in FrameTransform::of_state(s, log_ns) {
            self.write(TF_TOPIC, log_ns, publish_ns, &f)?;
        }
        if let Some(update) = self.scene.as_mut().and_then(|sc| sc.due(s.t, log_ns)) {
            self.write(SCENE_TOPIC, log_ns, publish_ns, &update)?;
        }
        Ok(())
    }

    /// Writes an MCAP `Metadata` record `name` with the key/value pairs `entries`
    /// (Foxglove shows them in its "Metadata" panel of the file).
    pub fn write_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), McapError> {
        let record = mcap::records::Metadata {
            name: name.to_string(),
            metadata: entries,
        };
        at("metadata", self.w.write_metadata(&record))
    }

    /// Writes the summary section and closes the file.
    pub fn finish(&mut self) -> Result<(), McapError> {
        at("finish", self.w.finish())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::test_util::{matches_schema, scenario};
    use serde_json::{Value, json};

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

    /// The scene goes out with the first state and again at each phase change, nowhere
    /// else, after that state's frames; it reads back as foxglove.SceneUpdate.
    #[test]
    fn scene_written_at_start_and_at_each_phase() {
        let sc = scenario();
        let dir = std::env::temp_dir().join(format!("sc-mcap-scene-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.mcap");
        let mut out = McapOut::create(&path).unwrap();
        out.set_scene(&sc);
        let period = sc.mission.control_period_s;
        let end = sc.mission.phases.last().unwrap().start_s + 3.0 * period;
        let n = (end / period).round() as u64;
        for k in 0..n {
            let s = sc_icd::SimState {
                tick: k,
                t: k as f64 * period,
                ..Default::default()
            };
            out.write_3d(k * 100, k, &s).unwrap();
        }
        out.finish().unwrap();
        assert_eq!(out.written[SCENE_TOPIC], sc.mission.phases.len() as u64);
        assert_eq!(out.written[TF_TOPIC], 4 * n);
        drop(out);
        let bytes = std::fs::read(&path).unwrap();
        let mut phases = Vec::new();
        let mut last_topic = String::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            if m.channel.topic == SCENE_TOPIC {
                assert_eq!(last_topic, TF_TOPIC, "scene after the frames");
                let schema = m.channel.schema.as_ref().unwrap();
                assert_eq!(schema.name, "foxglove.SceneUpdate");
                assert_eq!(m.channel.message_encoding, "json");
                let v: Value = serde_json::from_slice(&m.data).unwrap();
                let sch: Value = serde_json::from_slice(&schema.data).unwrap();
                matches_schema(&sch, &v, "SceneUpdate");
                let meta = &v["entities"][0]["metadata"];
                let phase = meta
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|kv| kv["key"] == "phase")
                    .unwrap();
                phases.push((m.log_time, phase["value"].as_str().unwrap().to_string()));
            }
            last_topic = m.channel.topic.clone();
        }
        let want: Vec<(u64, String)> = sc
            .mission
            .phases
            .iter()
            .map(|p| ((p.start_s / period).round() as u64 * 100, p.name.clone()))
            .collect();
        assert_eq!(phases, want);
        std::fs::remove_dir_all(&dir).ok();
    }
}
