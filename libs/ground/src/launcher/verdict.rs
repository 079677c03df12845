//! What a finished run says: the mission's verdict, losses in transport, the end of an
//! interrupted run.

use super::LaunchError;
use std::path::Path;

/// The files of a run that name its end ([`sc_mission::MissionEnd::name`]).
const END_FILES: [&str; 2] = ["summary.json", "recorder.json"];

/// Names the end of an interrupted run: the recorder saw the run stop before the
/// mission ended ("stopped") but cannot tell a signal from the scheduler's stop; the
/// launcher, that caught SIGINT/SIGTERM, rewrites it as "interrupted" in summary.json and
/// recorder.json. A mission that had ended before the signal keeps its end; a file the
/// recorder did not write is left absent.
pub(super) fn mark_interrupted(out: &Path) -> Result<(), LaunchError> {
    use sc_mission::MissionEnd;
    for name in END_FILES {
        let path = out.join(name);
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let bad = |what: &str| LaunchError::Output(format!("{}: {what}", path.display()));
        let mut v: serde_json::Value = serde_json::from_str(&text).map_err(|_| bad("not JSON"))?;
        let Some(fields) = v.as_object_mut() else {
            return Err(bad("not a JSON object"));
        };
        let t = fields
            .get("final_time_s")
            .and_then(|t| t.as_f64())
            .unwrap_or(f64::NAN);
        let end = fields.get("end").and_then(|e| e.as_str());
        if let Some(MissionEnd::Stopped { t }) = end.and_then(|e| MissionEnd::from_name(e, t)) {
            fields.insert("end".into(), MissionEnd::Interrupted { t }.name().into());
            let text = serde_json::to_string_pretty(&v).unwrap_or_default() + "\n";
            std::fs::write(&path, text).map_err(|e| LaunchError::io(&path, e))?;
        }
    }
    Ok(())
}

/// The run's exit code and error: 3 when it is broken (a process failed, a signal, a
/// failed start, files left behind), else the mission's verdict (0 captured safely, 1
/// not, 3 no result), and 4 when the flight side lost samples in transport.
pub(super) fn judge(out: &Path, broken: bool, error: Option<String>) -> (i32, Option<String>) {
    let code = if broken {
        3
    } else {
        match mission_verdict(&out.join("summary.json")) {
            Some(true) => 0,
            Some(false) => 1,
            // every process ended well and yet the recorder left no result
            None => 3,
        }
    };
    // every process ended well, yet the flight side lost samples: the transport failed
    // (e.g. a publisher gave up on a full queue under load), not the mission
    let lost = std::fs::read_to_string(out.join("recorder.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .map(|v| infrastructure_losses(&v))
        .unwrap_or_default();
    if code <= 1 && !lost.is_empty() {
        let e = format!(
            "infrastructure: flight-side samples lost in transport ({}); the run's result is not the mission's",
            lost.join(", ")
        );
        return (4, Some(e));
    }
    (code, error)
}

/// The mission's verdict from a run's summary.json: captured with every barrier
/// satisfied, no fault and (with a declared uncertainty) the realised errors within the
/// declared bounds, as `safe-capture run` judges; `None` without a readable summary.
pub fn mission_verdict(summary: &Path) -> Option<bool> {
    let s: sc_mission::Summary =
        serde_json::from_str(&std::fs::read_to_string(summary).ok()?).ok()?;
    Some(s.passed())
}

/// The flight-side services (everything but the partners' `safe_capture/nominal/*`) of
/// which the recorder missed samples, from its `recorder.json`, as `service: count`.
pub fn infrastructure_losses(recorder: &serde_json::Value) -> Vec<String> {
    recorder["missing"]
        .as_object()
        .map(|m| {
            m.iter()
                .filter(|(svc, _)| !svc.starts_with("safe_capture/nominal/"))
                .filter_map(|(svc, n)| n.as_u64().filter(|n| *n > 0).map(|n| format!("{svc}: {n}")))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod infrastructure_tests {
    use super::infrastructure_losses;

    #[test]
    fn only_flight_side_losses_count() {
        let r = serde_json::json!({"missing": {
            "safe_capture/nominal/attitude": 550,
            "safe_capture/sim/state": 0,
            "safe_capture/safe/robotic": 3,
        }});
        assert_eq!(
            infrastructure_losses(&r),
            vec!["safe_capture/safe/robotic: 3"]
        );
        let healthy = serde_json::json!({"missing": {"safe_capture/nominal/robotic": 9}});
        assert!(infrastructure_losses(&healthy).is_empty());
        assert!(infrastructure_losses(&serde_json::json!({})).is_empty());
    }
}

#[cfg(test)]
mod end_tests {
    use super::{END_FILES, mark_interrupted};
    use serde_json::json;

    fn end_of(dir: &std::path::Path, name: &str) -> serde_json::Value {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()["end"].clone()
    }

    /// An interrupted run that the recorder saw stopped is named interrupted; a mission
    /// that had ended keeps its end; absent files stay absent.
    #[test]
    fn an_interrupted_run_is_named_so_unless_the_mission_had_ended() {
        let dir = std::env::temp_dir().join(format!("sc-mark-interrupted-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (end, want) in [
            ("stopped", "interrupted"),
            ("captured", "captured"),
            ("timeout", "timeout"),
        ] {
            for name in END_FILES {
                let v = json!({"end": end, "final_time_s": 4.9, "steps": 50});
                std::fs::write(dir.join(name), v.to_string()).unwrap();
            }
            mark_interrupted(&dir).unwrap();
            for name in END_FILES {
                assert_eq!(end_of(&dir, name), want, "{name} of a run that ended {end}");
            }
        }
        for name in END_FILES {
            std::fs::remove_file(dir.join(name)).unwrap();
        }
        mark_interrupted(&dir).unwrap();
        assert!(END_FILES.iter().all(|n| !dir.join(n).exists()));
        // a file that is not a JSON object is named, not overwritten
        std::fs::write(dir.join(END_FILES[0]), "[]").unwrap();
        let err = mark_interrupted(&dir).unwrap_err().to_string();
        assert!(err.contains("not a JSON object"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
