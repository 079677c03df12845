//! The Foxglove kit (docs/FOXGLOVE.md) against a real partition run's recording.mcap:
//! - every field of every channel's JSON schema has a description (walked recursively
//!   through the schemas read back from the file);
//! - the shipped layout (docs/foxglove/) refers only to what the recording holds: every
//!   plotted message path names a channel, a field of its schema and an index inside
//!   the array, with data there; the 3D panel's topics are channels and its display
//!   frame and every scene entity's frame are frames on `/tf` — so the layout cannot rot;
//! - the scene goes out at the first state and at each phase change;
//! - an independent reader, the `mcap` package of PyPI (scripts/mcap_check.py), reads
//!   the summary, the chunk indexes, the counts, the metadata record and every message
//!   against its schema, and the partner SDK's minimal reader reads the same messages.
//!   Its interpreter is `SC_PYTHON` (set by scripts/test.sh; then a missing `mcap`
//!   package fails the test), else scripts/.venv/bin/python; without either that part
//!   is skipped with the reason printed.

mod common;
use common::*;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Mission time of the run [s]: short, yet long enough for several MCAP chunks, with
/// every phase in it (the test moves the phases' starts into it, keeping their order).
const DURATION_S: f64 = 12.0;

/// One channel of the recording: its schema and its messages.
struct Channel {
    schema: Value,
    messages: Vec<(u64, Value)>,
}

fn read_recording(path: &Path) -> BTreeMap<String, Channel> {
    let bytes = std::fs::read(path).unwrap();
    let mut channels: BTreeMap<String, Channel> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let topic = m.channel.topic.clone();
        let ch = channels.entry(topic.clone()).or_insert_with(|| {
            let schema = m.channel.schema.as_ref().expect("a schema per channel");
            assert_eq!(schema.encoding, "jsonschema", "{topic}");
            Channel {
                schema: serde_json::from_slice(&schema.data).unwrap(),
                messages: Vec::new(),
            }
        });
        let v: Value = serde_json::from_slice(&m.data)
            .unwrap_or_else(|e| panic!("{topic}: message not JSON: {e}"));
        ch.messages.push((m.log_time, v));
    }
    channels
}

/// Properties without a non-empty description in `schema`, recursively (through
/// nested objects and array items), as paths.
fn undescribed(schema: &Value, path: &str, out: &mut Vec<String>) {
    if let Some(props) = schema.get("properties").and_then(Value::as_object) {
        for (k, v) in props {
            let p = format!("{path}.{k}");
            if v["description"]
                .as_str()
                .is_none_or(|d| d.trim().is_empty())
            {
                out.push(p.clone());
            }
            undescribed(v, &p, out);
        }
    }
    if let Some(items) = schema.get("items") {
        undescribed(items, &format!("{path}[]"), out);
    }
}

/// A Plot message path `topic.field[index]` split up (the only form the layout uses).
fn split_path(p: &str) -> Option<(&str, &str, usize)> {
    let (topic, rest) = p.rsplit_once('.')?;
    let (field, index) = rest.strip_suffix(']')?.split_once('[')?;
    Some((topic, field, index.parse().ok()?))
}

/// The frame ids on `/tf`.
fn tf_frames(channels: &BTreeMap<String, Channel>) -> BTreeSet<String> {
    let mut frames = BTreeSet::new();
    if let Some(tf) = channels.get(sc_ground::mcap_out::TF_TOPIC) {
        for (_, m) in &tf.messages {
            for k in ["parent_frame_id", "child_frame_id"] {
                frames.insert(m[k].as_str().unwrap_or_default().to_string());
            }
        }
    }
    frames
}

/// What in `layout` the recording does not hold.
fn layout_problems(layout: &Value, channels: &BTreeMap<String, Channel>) -> Vec<String> {
    let mut bad = Vec::new();
    let Some(panels) = layout["configById"].as_object() else {
        return vec!["no configById".into()];
    };
    let frames = tf_frames(channels);
    for (id, cfg) in panels {
        if id.starts_with("Plot!") {
            let paths = cfg["paths"].as_array().cloned().unwrap_or_default();
            if paths.is_empty() {
                bad.push(format!("{id}: no paths"));
            }
            for p in paths {
                let value = p["value"].as_str().unwrap_or_default();
                let Some((topic, field, i)) = split_path(value) else {
                    bad.push(format!("{id}: cannot read path {value:?}"));
                    continue;
                };
                let Some(ch) = channels.get(topic) else {
                    bad.push(format!("{id}: {value}: no channel {topic}"));
                    continue;
                };
                let prop = &ch.schema["properties"][field];
                if prop.is_null() {
                    bad.push(format!(
                        "{id}: {value}: no field {field} in {topic}'s schema"
                    ));
                    continue;
                }
                if prop["type"] != "array"
                    || prop["maxItems"].as_u64().is_none_or(|n| i as u64 >= n)
                {
                    bad.push(format!("{id}: {value}: index {i} outside {field} ({prop})"));
                    continue;
                }
                // the data is there: a number at that index in some message
                if !ch.messages.iter().any(|(_, m)| m[field][i].is_number()) {
                    bad.push(format!("{id}: {value}: no number in any message"));
                }
            }
        } else if id.starts_with("3D!") {
            let topics = cfg["topics"].as_object().cloned().unwrap_or_default();
            for t in topics.keys() {
                if !channels.contains_key(t) {
                    bad.push(format!("{id}: topic {t} not in the recording"));
                }
            }
            let f = cfg["followTf"].as_str().unwrap_or_default();
            if !frames.contains(f) {
                bad.push(format!(
                    "{id}: followTf {f:?} is no frame on /tf ({frames:?})"
                ));
            }
        } else {
            bad.push(format!("{id}: a panel kind this check does not know"));
        }
    }
    bad
}

#[test]
fn recording_opens_with_the_shipped_layout() {
    let dir = scratch("foxglove");
    let config = write_config(&dir, Some(DURATION_S), None, 20.0);
    // every phase inside the short run, in the scenario's order
    let scenario_path = dir.join("scenario.toml");
    let text = std::fs::read_to_string(&scenario_path).unwrap();
    let mut sc = sc_scenario::Scenario::load(&scenario_path).unwrap();
    let n_phases = sc.mission.phases.len();
    let mut moved = text.clone();
    for (k, p) in sc.mission.phases.iter_mut().enumerate().skip(1) {
        let from = format!("start_s = {:.1}", p.start_s);
        p.start_s = DURATION_S * k as f64 / n_phases as f64;
        assert!(moved.contains(&from), "{from}");
        moved = moved.replacen(&from, &format!("start_s = {:?}", p.start_s), 1);
    }
    std::fs::write(&scenario_path, moved).unwrap();
    assert_eq!(sc_scenario::Scenario::load(&scenario_path).unwrap(), sc);

    let out = dir.join("out");
    let rep = sc_ground::launch(&options(&config, &out, "fox")).unwrap();
    assert_clean(&rep, &out);
    let rec = out.join("recording.mcap");
    let channels = read_recording(&rec);
    // long enough for several chunks: the independent reader walks more than one index
    let bytes = std::fs::read(&rec).unwrap();
    let chunks = mcap::Summary::read(&bytes)
        .unwrap()
        .unwrap()
        .chunk_indexes
        .len();
    assert!(chunks >= 2, "{chunks} chunk(s): run longer");

    // every channel is described, field by field
    let mut missing = Vec::new();
    for (topic, ch) in &channels {
        assert!(
            ch.schema["description"].is_string(),
            "{topic}: schema without description"
        );
        undescribed(&ch.schema, topic, &mut missing);
    }
    assert!(
        missing.is_empty(),
        "schema fields without a description: {missing:?}"
    );
    for svc in [
        sc_icd::services::SIM_STATE,
        sc_icd::services::NOMINAL_TRANSLATIONAL,
        sc_icd::services::SAFE_ROBOTIC,
        sc_icd::services::STEP_RESULT,
    ] {
        assert!(channels.contains_key(svc.as_str()), "{svc} not recorded");
    }

    // the shipped layout refers only to what is there
    let layout_path = repo().join(sc_ground::mcap_out::LAYOUT_FILE);
    let layout: Value =
        serde_json::from_str(&std::fs::read_to_string(&layout_path).unwrap()).unwrap();
    let bad = layout_problems(&layout, &channels);
    assert!(bad.is_empty(), "{}: {bad:#?}", layout_path.display());
    // ... and the check can fail: a renamed field, an index past the end, an unknown
    // topic and a frame that is not on /tf are each found
    let mut rotten = layout.clone();
    let plots: Vec<String> = rotten["configById"]
        .as_object()
        .unwrap()
        .keys()
        .filter(|k| k.starts_with("Plot!"))
        .cloned()
        .collect();
    let paths = &mut rotten["configById"][&plots[0]]["paths"];
    paths[0]["value"] = "safe_capture/safe/translational.hh[0]".into();
    paths[1]["value"] = "safe_capture/safe/translational.h[2]".into();
    rotten["configById"][&plots[1]]["paths"][0]["value"] = "safe_capture/safe/nowhere.h[0]".into();
    rotten["configById"]["3D!scene"]["followTf"] = "world".into();
    assert_eq!(
        layout_problems(&rotten, &channels).len(),
        4,
        "{:#?}",
        layout_problems(&rotten, &channels)
    );

    // the 3D panel: frames on /tf for every scene entity, the scene once per phase
    let frames = tf_frames(&channels);
    let scene = &channels[sc_ground::mcap_out::SCENE_TOPIC];
    let mut phases = Vec::new();
    for (log_ns, m) in &scene.messages {
        for e in m["entities"].as_array().unwrap() {
            let f = e["frame_id"].as_str().unwrap();
            assert!(
                frames.contains(f),
                "entity {} in frame {f}, not on /tf: {frames:?}",
                e["id"]
            );
            assert_eq!(e["frame_locked"], true);
        }
        let meta = m["entities"][0]["metadata"].as_array().unwrap();
        let phase = meta.iter().find(|kv| kv["key"] == "phase").unwrap();
        phases.push((*log_ns, phase["value"].as_str().unwrap().to_string()));
    }
    let names: Vec<String> = sc.mission.phases.iter().map(|p| p.name.clone()).collect();
    assert_eq!(
        phases.iter().map(|p| p.1.clone()).collect::<Vec<_>>(),
        names,
        "{phases:?}"
    );
    assert_eq!(
        phases[0].0, 0,
        "the scene is there from the mission's start"
    );
    let states = channels[sc_icd::services::SIM_STATE.as_str()]
        .messages
        .len();
    assert_eq!(
        channels[sc_ground::mcap_out::TF_TOPIC].messages.len(),
        4 * states
    );

    // the independent reader
    let Some(py) = python_with("mcap.reader") else {
        return;
    };
    let o = std::process::Command::new(&py)
        .arg(repo().join("scripts/mcap_check.py"))
        .arg(&rec)
        .arg("--recorder-json")
        .arg(out.join("recorder.json"))
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    eprintln!("{text}");
    assert!(o.status.success(), "{text}");
    assert!(text.contains("mcap_check: ok:"), "{text}");
}

/// The independent check fails on a recording that is not what Foxglove needs: the
/// same run's file cut short (no summary section) is refused.
#[test]
fn independent_reader_refuses_a_truncated_recording() {
    let Some(py) = python_with("mcap.reader") else {
        return;
    };
    let dir = scratch("foxglove-cut");
    let path = dir.join("cut.mcap");
    let mut out = sc_ground::mcap_out::McapOut::create(&path).unwrap();
    out.write_metadata(
        sc_ground::recorder::MCAP_METADATA_NAME,
        BTreeMap::from([("version".to_string(), "0".to_string())]),
    )
    .unwrap();
    out.write("safe_capture/sim/state", 0, 1, &sc_icd::SimState::default())
        .unwrap();
    out.finish().unwrap();
    drop(out);
    let run = |p: &Path| {
        let o = std::process::Command::new(&py)
            .arg(repo().join("scripts/mcap_check.py"))
            .arg(p)
            .output()
            .unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stdout).to_string(),
        )
    };
    // complete but without /tf, /scene and the run's metadata keys: named, one by one
    let (ok, text) = run(&path);
    assert!(!ok, "{text}");
    for want in [
        "no message on /tf",
        "no message on /scene",
        "metadata: missing",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }
    // cut short: no summary
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.join("cut2.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (ok, text) = run(&cut);
    assert!(!ok, "{text}");
}
