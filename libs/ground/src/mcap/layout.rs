//! The Foxglove layout of a partition recording (`docs/foxglove/safe-capture-layout.json`):
//! the 3D panel, the barrier plots of the three safety filters and the nominal against
//! the safe commands.

use super::frames::{FRAME_REFERENCE, TF_TOPIC};
use super::scene::SCENE_TOPIC;
use sc_core::Subsystem;
use sc_icd::ServiceName;
use sc_icd::services as svc;
use sc_icd_gen::barriers::{barrier_unit, constraint_names};
use serde_json::{Map, Value, json};
use std::ops::Range;

/// The Foxglove layout shipped in `docs/foxglove/safe-capture-layout.json` (relative to the
/// repository; the test `layout_file_is_current` keeps the file equal to
/// [`foxglove_layout`], `SC_WRITE_FOXGLOVE_LAYOUT=1` rewrites it).
pub const LAYOUT_FILE: &str = "docs/foxglove/safe-capture-layout.json";

/// One plotted message path of a Plot panel, against mission time (the log time).
fn plot_path(topic: &str, field: &str, index: usize, label: String) -> Value {
    json!({
        "value": format!("{topic}.{field}[{index}]"),
        "enabled": true,
        "timestampMethod": "receiveTime",
        "label": label,
    })
}

fn plot_panel(title: &str, paths: Vec<Value>) -> Value {
    json!({
        "title": title,
        "paths": paths,
        "showXAxisLabels": true,
        "showYAxisLabels": true,
        "showLegend": true,
        "legendDisplay": "floating",
        "isSynced": true,
        "xAxisVal": "timestamp",
    })
}

/// Panels stacked in a column (Foxglove's mosaic tree), equal heights.
fn column(ids: &[String]) -> Value {
    match ids {
        [] => Value::Null,
        [one] => Value::String(one.clone()),
        [first, rest @ ..] => json!({
            "direction": "column",
            "first": first,
            "second": column(rest),
            "splitPercentage": 100.0 / ids.len() as f64,
        }),
    }
}

/// One panel of barrier plots: the barriers `range` of `subsystem`'s filter report.
struct BarrierPlot {
    id: &'static str,
    title: &'static str,
    service: ServiceName,
    subsystem: Subsystem,
    range: Range<usize>,
}

/// The barrier panels: the translational and attitude filters' barriers each in one,
/// the robotic filter's by kind (joint angles, joint rates, link–base spheres, link–target
/// spheres).
fn barrier_plots() -> [BarrierPlot; 6] {
    let nj = sc_icd::N_JOINTS;
    let plot = |id, title, service, subsystem, range| BarrierPlot {
        id,
        title,
        service,
        subsystem,
        range,
    };
    let all = |s| 0..constraint_names(s).len();
    [
        plot(
            "barriers_translational",
            "Barriers h: translational (corridor, zone)",
            svc::SAFE_TRANSLATIONAL,
            Subsystem::Translational,
            all(Subsystem::Translational),
        ),
        plot(
            "barriers_attitude",
            "Barriers h: attitude (line of sight, rate limits)",
            svc::SAFE_ATTITUDE,
            Subsystem::Attitude,
            all(Subsystem::Attitude),
        ),
        plot(
            "barriers_joint_angles",
            "Barriers h: joint angles",
            svc::SAFE_ROBOTIC,
            Subsystem::Robotic,
            0..nj,
        ),
        plot(
            "barriers_joint_rates",
            "Barriers h: joint rates",
            svc::SAFE_ROBOTIC,
            Subsystem::Robotic,
            nj..3 * nj,
        ),
        plot(
            "barriers_link_base",
            "Barriers h: link-base spheres",
            svc::SAFE_ROBOTIC,
            Subsystem::Robotic,
            3 * nj..sc_cbf::robotic::LINK_TARGET,
        ),
        plot(
            "barriers_link_target",
            "Barriers h: link-target spheres",
            svc::SAFE_ROBOTIC,
            Subsystem::Robotic,
            sc_cbf::robotic::LINK_TARGET..all(Subsystem::Robotic).end,
        ),
    ]
}

/// Adds the barrier panels to `config` (each barrier's name and unit in the legend);
/// their ids.
fn barrier_panels(config: &mut Map<String, Value>) -> Vec<String> {
    let mut ids = Vec::new();
    for p in barrier_plots() {
        let names = constraint_names(p.subsystem);
        let paths = p
            .range
            .map(|i| {
                let unit = barrier_unit(names[i]).unwrap_or("?");
                plot_path(p.service.as_str(), "h", i, format!("{} [{unit}]", names[i]))
            })
            .collect();
        let id = format!("Plot!{}", p.id);
        config.insert(id.clone(), plot_panel(p.title, paths));
        ids.push(id);
    }
    ids
}

/// One panel of a subsystem's nominal command (`field` of `nominal`) against its safe
/// command (`u` of `safe`), component by component.
struct CommandPlot {
    id: &'static str,
    title: &'static str,
    nominal: ServiceName,
    field: &'static str,
    safe: ServiceName,
    symbol: &'static str,
    subsystem: Subsystem,
}

fn command_plots() -> [CommandPlot; 3] {
    [
        CommandPlot {
            id: "commands_translational",
            title: "Force f_H [N]: nominal vs safe",
            nominal: svc::NOMINAL_TRANSLATIONAL,
            field: "f_h",
            safe: svc::SAFE_TRANSLATIONAL,
            symbol: "f_H",
            subsystem: Subsystem::Translational,
        },
        CommandPlot {
            id: "commands_attitude",
            title: "Torque τ_B [N·m]: nominal vs safe",
            nominal: svc::NOMINAL_ATTITUDE,
            field: "tau_b",
            safe: svc::SAFE_ATTITUDE,
            symbol: "τ_B",
            subsystem: Subsystem::Attitude,
        },
        CommandPlot {
            id: "commands_robotic",
            title: "Joint torques τ_M [N·m]: nominal vs safe",
            nominal: svc::NOMINAL_ROBOTIC,
            field: "tau_m",
            safe: svc::SAFE_ROBOTIC,
            symbol: "τ_M",
            subsystem: Subsystem::Robotic,
        },
    ]
}

/// Adds the command panels to `config`; their ids.
fn command_panels(config: &mut Map<String, Value>) -> Vec<String> {
    let xyz = ["x", "y", "z"];
    let mut ids = Vec::new();
    for p in command_plots() {
        let n = p.subsystem.command_dim();
        let component = |i: usize| {
            if n == 3 {
                xyz[i].to_string()
            } else {
                (i + 1).to_string()
            }
        };
        let mut paths = Vec::new();
        for i in 0..n {
            let c = component(i);
            let label = format!("{} {c} nominal", p.symbol);
            paths.push(plot_path(p.nominal.as_str(), p.field, i, label));
            let label = format!("{} {c} safe", p.symbol);
            paths.push(plot_path(p.safe.as_str(), "u", i, label));
        }
        let id = format!("Plot!{}", p.id);
        config.insert(id.clone(), plot_panel(p.title, paths));
        ids.push(id);
    }
    ids
}

/// The 3D panel: follows the reference frame, shows `/tf` and `/scene` over a grid.
fn three_d_panel() -> Value {
    json!({
        "followTf": FRAME_REFERENCE,
        "followMode": "follow-pose",
        "scene": {"transforms": {"showLabel": true}},
        "transforms": {},
        "topics": {
            TF_TOPIC: {"visible": true},
            SCENE_TOPIC: {"visible": true},
        },
        "layers": {"grid": {"visible": true, "layerId": "foxglove.Grid", "frameId": FRAME_REFERENCE}},
    })
}

/// The Foxglove layout of a partition recording: the 3D panel in the reference frame
/// with the frames of `/tf` and the scene of `/scene`; plots of every barrier h the
/// three safety filters report (by subsystem and kind, units in the legend); and per
/// subsystem the nominal command against the safe one.
pub fn foxglove_layout() -> Value {
    let mut config = Map::new();
    let barrier_ids = barrier_panels(&mut config);
    let command_ids = command_panels(&mut config);
    let three_d = "3D!scene".to_string();
    config.insert(three_d.clone(), three_d_panel());
    json!({
        "configById": Value::Object(config),
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1.0},
        "layout": {
            "direction": "row",
            "first": three_d,
            "second": {
                "direction": "row",
                "first": column(&barrier_ids),
                "second": column(&command_ids),
                "splitPercentage": 50.0,
            },
            "splitPercentage": 40.0,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped layout is the one [`foxglove_layout`] builds (SC_WRITE_FOXGLOVE_LAYOUT=1
    /// rewrites it); every panel of its mosaic is configured and every configured panel
    /// is placed; it plots every barrier of the three filters.
    #[test]
    fn layout_file_is_current() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(LAYOUT_FILE);
        let want = foxglove_layout();
        let text = serde_json::to_string_pretty(&want).unwrap() + "\n";
        if std::env::var_os("SC_WRITE_FOXGLOVE_LAYOUT").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let got = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            got == text,
            "{} is stale: SC_WRITE_FOXGLOVE_LAYOUT=1 cargo test -p sc-ground layout_file_is_current",
            path.display()
        );
        fn placed(node: &Value, out: &mut Vec<String>) {
            match node {
                Value::String(s) => out.push(s.clone()),
                Value::Object(o) => {
                    placed(&o["first"], out);
                    placed(&o["second"], out);
                }
                _ => panic!("mosaic node {node}"),
            }
        }
        let mut ids = Vec::new();
        placed(&want["layout"], &mut ids);
        ids.sort();
        let configured: Vec<String> = want["configById"]
            .as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect();
        assert_eq!(ids, configured);
        let h_paths = want["configById"]
            .as_object()
            .unwrap()
            .values()
            .flat_map(|p| p["paths"].as_array().cloned().unwrap_or_default())
            .filter(|p| p["value"].as_str().unwrap().contains(".h["))
            .count();
        // every filter's barrier (the monitor-only `base_target` is in no filter report)
        assert_eq!(h_paths, sc_icd::N_BARRIERS - sc_icd::N_BARRIERS_MONITORED);
    }
}
