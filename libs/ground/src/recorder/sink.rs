//! Where the recorder's decisions go: the telemetry CSVs, `latency.csv`, the MCAP
//! recording, `summary.json` and `recorder.json` in the run's output folder.

use super::{LATENCY_CSV_HEADER, MCAP_METADATA_NAME, RecorderReport};
use crate::mcap_out::McapOut;
use sc_flight::Message;
use sc_flight::process::Proc;
use sc_mission::{StepRecord, Summary, TelemetryWriter};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why the recorder could not write its outputs.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("recording.mcap: {0}")]
    Mcap(String),
}

/// What the recorder writes.
pub trait RecordSink {
    /// The run started (every process joined): open what is opened only then.
    fn begin(&mut self) -> Result<(), SinkError>;
    /// A message as it arrived, at mission time `log_ns` [ns since the start].
    fn message(&mut self, log_ns: u64, m: &Message) -> Result<(), SinkError>;
    /// One step: its telemetry row and its line of `latency.csv`.
    fn step(&mut self, rec: &StepRecord, latency_line: &str) -> Result<(), SinkError>;
    /// The end: `navigation.csv` from the records (with a declared uncertainty), the
    /// summary and the recorder's report; everything flushed and closed.
    fn finish(
        &mut self,
        records: &[StepRecord],
        summary: &Summary,
        report: &RecorderReport,
    ) -> Result<(), SinkError>;
}

/// The files of a partition run's output folder.
pub struct FileSink {
    out: PathBuf,
    telemetry: TelemetryWriter<BufWriter<File>>,
    latency: BufWriter<File>,
    mcap: Option<McapOut>,
    /// The scenario (for the MCAP's scene) and the run's metadata record.
    scenario: sc_scenario::Scenario,
    metadata: BTreeMap<String, String>,
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> SinkError + '_ {
    move |source| SinkError::Io {
        path: path.display().to_string(),
        source,
    }
}

fn create(out: &Path, name: &str) -> Result<BufWriter<File>, SinkError> {
    let path = out.join(name);
    Ok(BufWriter::new(File::create(&path).map_err(io(&path))?))
}

fn mcap_err(e: impl std::fmt::Display) -> SinkError {
    SinkError::Mcap(e.to_string())
}

impl FileSink {
    /// Creates the CSV files in the process's output folder (the MCAP is created only once
    /// the partition has started: a start that fails leaves no recording.mcap behind).
    pub fn new(p: &Proc) -> Result<Self, SinkError> {
        std::fs::create_dir_all(&p.out).map_err(io(&p.out))?;
        let telemetry = TelemetryWriter::new(
            create(&p.out, "telemetry.csv")?,
            create(&p.out, "timing.csv")?,
        )
        .map_err(io(&p.out))?;
        let mut latency = create(&p.out, "latency.csv")?;
        writeln!(latency, "{LATENCY_CSV_HEADER}").map_err(io(&p.out))?;
        Ok(Self {
            out: p.out.clone(),
            telemetry,
            latency,
            mcap: None,
            scenario: p.setup.scenario.clone(),
            metadata: run_metadata(p)?,
        })
    }

    fn write_json(&self, name: &str, v: &impl serde::Serialize) -> Result<(), SinkError> {
        let path = self.out.join(name);
        let text = serde_json::to_string_pretty(v).unwrap_or_default() + "\n";
        std::fs::write(&path, text).map_err(io(&path))
    }
}

impl RecordSink for FileSink {
    fn begin(&mut self) -> Result<(), SinkError> {
        let mut mcap = McapOut::create(&self.out.join("recording.mcap")).map_err(mcap_err)?;
        mcap.write_metadata(MCAP_METADATA_NAME, self.metadata.clone())
            .map_err(mcap_err)?;
        // the scenario's corridor, zone, line of sight and grasping point for the 3D panel
        mcap.set_scene(&self.scenario);
        self.mcap = Some(mcap);
        Ok(())
    }

    fn message(&mut self, log_ns: u64, m: &Message) -> Result<(), SinkError> {
        let Some(mcap) = self.mcap.as_mut() else {
            return Ok(());
        };
        let topic = m.service().as_str();
        match m {
            Message::Tick(x) | Message::Control(x) => mcap.write(topic, log_ns, x.send_ns, x),
            // the 3D panel's frames (and scene) from the truth: the state itself, or with
            // a declared uncertainty (the state is then the estimate) the truth's message
            Message::State(x) | Message::PartnerState(x) if self.scenario.uncertainty.is_some() => {
                mcap.write(topic, log_ns, x.publish_ns, x)
            }
            Message::State(x) | Message::PartnerState(x) | Message::Truth(x) => mcap
                .write(topic, log_ns, x.publish_ns, x)
                .and_then(|_| mcap.write_3d(log_ns, x.publish_ns, x)),
            Message::NavigationError(x) => mcap.write(topic, log_ns, 0, x),
            // what the navigation got and answered (the offline harness replays them)
            Message::Measurement(x) | Message::Estimate(x) => {
                mcap.write(topic, log_ns, x.publish_ns, x)
            }
            Message::NominalTranslational(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::NominalAttitude(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::NominalRobotic(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::SafeTranslational(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::SafeAttitude(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::SafeRobotic(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            Message::StepResult(x) => mcap.write(topic, log_ns, x.publish_ns, x),
            // not recorded: the recorder's own progress
            Message::Health(_) => Ok(()),
        }
        .map_err(mcap_err)
    }

    fn step(&mut self, rec: &StepRecord, latency_line: &str) -> Result<(), SinkError> {
        let e = io(&self.out);
        self.telemetry.write(rec).map_err(&e)?;
        self.telemetry.flush().map_err(&e)?;
        writeln!(self.latency, "{latency_line}").map_err(&e)
    }

    fn finish(
        &mut self,
        records: &[StepRecord],
        summary: &Summary,
        report: &RecorderReport,
    ) -> Result<(), SinkError> {
        let e = io(&self.out);
        self.telemetry.flush().map_err(&e)?;
        self.latency.flush().map_err(&e)?;
        if let Some(m) = self.mcap.as_mut() {
            m.finish().map_err(mcap_err)?;
        }
        self.write_json("summary.json", summary)?;
        self.write_json("recorder.json", report)?;
        let knowledge = self.out.join("navigation.csv");
        sc_mission::record::write_knowledge(&knowledge, records).map_err(io(&knowledge))
    }
}

/// The run as MCAP metadata: the build (`version`, `git_commit`), the scenario (its
/// resolved path and full text, so a recording replays without the file) and the
/// partition config (its path and full text).
fn run_metadata(p: &Proc) -> Result<BTreeMap<String, String>, SinkError> {
    let build = sc_mission::build::current();
    let scenario_path = p.cfg.scenario_path();
    let read = |path: &Path| std::fs::read_to_string(path).map_err(io(path));
    Ok(BTreeMap::from([
        ("version".to_string(), build.version),
        ("git_commit".to_string(), build.git_commit),
        (
            "scenario_path".to_string(),
            scenario_path.display().to_string(),
        ),
        ("scenario".to_string(), read(&scenario_path)?),
        (
            "partition_config_path".to_string(),
            path_in_out(&p.config_path, &p.out),
        ),
        ("partition_config".to_string(), read(&p.config_path)?),
    ]))
}

/// `path` as the recording names it: relative to the output folder `out` when it is in
/// it (the launcher's effective config), since the launcher renames that folder after
/// the run (`OUT.incomplete` → `OUT`); as given otherwise.
pub fn path_in_out(path: &Path, out: &Path) -> String {
    path.strip_prefix(out).unwrap_or(path).display().to_string()
}

#[cfg(test)]
mod tests {
    use super::path_in_out;
    use std::path::Path;

    /// The effective config is named relative to the output folder, which the launcher
    /// renames after the run; a file elsewhere keeps its path.
    #[test]
    fn a_path_in_the_output_folder_is_relative_to_it() {
        let out = Path::new("/runs/out.incomplete");
        assert_eq!(
            path_in_out(&out.join("partition.effective.toml"), out),
            "partition.effective.toml"
        );
        assert_eq!(
            path_in_out(Path::new("/etc/partition.toml"), out),
            "/etc/partition.toml"
        );
        // a sibling whose name starts like the folder's is not in it
        assert_eq!(
            path_in_out(Path::new("/runs/out.incomplete2/p.toml"), out),
            "/runs/out.incomplete2/p.toml"
        );
    }
}
