//! The scene of Foxglove's 3D panel on [`SCENE_TOPIC`] (`foxglove.SceneUpdate`): the
//! scenario's safety geometry — approach corridor, collision-avoidance zone, line of
//! sight, grasping point — each entity locked to its frame on `/tf`.

use super::NS_PER_S;
use super::frames::{FRAME_REFERENCE, FRAME_SERVICER_COM, FRAME_TARGET};
use super::json::JsonMsg;
use serde_json::{Value, json};

/// Topic of the 3D scene's entities (`foxglove.SceneUpdate`).
pub const SCENE_TOPIC: &str = "/scene";
/// Entity id of the approach-corridor cone.
pub const ENTITY_CORRIDOR: &str = "approach_corridor";
/// Entity id of the collision-avoidance-zone sphere.
pub const ENTITY_ZONE: &str = "collision_avoidance_zone";
/// Entity id of the line-of-sight cone.
pub const ENTITY_LINE_OF_SIGHT: &str = "line_of_sight";
/// Entity id of the grasping point (a sphere of the capture tolerance).
pub const ENTITY_GRASP: &str = "grasp_point";

/// An RGBA colour, each component in [0, 1] (Foxglove's `foxglove.Color`).
type Rgba = [f64; 4];
/// Display colours of the scene (translucent, so the frames stay visible inside).
const COLOR_CORRIDOR: Rgba = [0.2, 0.6, 1.0, 0.25];
const COLOR_ZONE: Rgba = [1.0, 0.3, 0.2, 0.25];
const COLOR_LINE_OF_SIGHT: Rgba = [1.0, 0.85, 0.1, 0.25];
const COLOR_GRASP: Rgba = [0.2, 0.9, 0.3, 0.8];
const COLOR_LABEL: Rgba = [1.0, 1.0, 1.0, 1.0];
/// Label height on screen [px] (Foxglove's `scale_invariant` text).
const LABEL_FONT_PX: f64 = 14.0;

/// A cone with its apex at the origin of its frame, around the unit `axis`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cone {
    /// Unit axis from the apex into the cone, in the entity's frame [-].
    pub axis: [f64; 3],
    /// Half angle [rad].
    pub half_angle_rad: f64,
    /// Length along the axis [m].
    pub length_m: f64,
}

impl Cone {
    /// Foxglove's `CylinderPrimitive` of the cone: a cylinder whose local z is the
    /// axis, centred half a length along it, its bottom face (the apex) scaled to 0.
    fn cylinder(&self, color: Rgba) -> Value {
        let d = unit(self.axis);
        let l = self.length_m;
        let diameter = 2.0 * l * self.half_angle_rad.tan();
        json!({
            "pose": pose([d[0] * l / 2.0, d[1] * l / 2.0, d[2] * l / 2.0], z_onto(d)),
            "size": {"x": diameter, "y": diameter, "z": l},
            "bottom_scale": 0.0,
            "top_scale": 1.0,
            "color": color_json(color),
        })
    }
}

/// `v / ‖v‖`; `v` itself when it has no finite positive length (never NaN from here).
fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n.is_finite() && n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        v
    }
}

/// The rotation `[x, y, z, w]` that turns the local z axis onto the unit vector `d`
/// (the half-way quaternion; a half turn about x when `d` is −z).
fn z_onto(d: [f64; 3]) -> [f64; 4] {
    // q = (1 + z·d, z × d) normalised, z = (0, 0, 1): z × d = (−d_y, d_x, 0)
    let w = 1.0 + d[2];
    let (x, y) = (-d[1], d[0]);
    let n = (w * w + x * x + y * y).sqrt();
    if n > f64::EPSILON * 4.0 && n.is_finite() {
        [x / n, y / n, 0.0, w / n]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

fn pose(position: [f64; 3], orientation: [f64; 4]) -> Value {
    json!({
        "position": {"x": position[0], "y": position[1], "z": position[2]},
        "orientation": {"x": orientation[0], "y": orientation[1], "z": orientation[2], "w": orientation[3]},
    })
}

fn color_json(c: Rgba) -> Value {
    json!({"r": c[0], "g": c[1], "b": c[2], "a": c[3]})
}

fn stamp(ns: u64) -> Value {
    json!({"sec": ns / NS_PER_S, "nsec": ns % NS_PER_S})
}

/// The scenario's safety geometry as the 3D panel shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneGeometry {
    /// Approach corridor: apex at the target's CoM (F_R's origin), axis d_R fixed in
    /// F_R, half angle ψ_AC (`safety.translational`).
    pub corridor: Cone,
    /// Collision-avoidance zone R_CAZ about the target's CoM [m].
    pub zone_radius_m: f64,
    /// Line of sight: apex at the servicer's centre of mass, axis the boresight d_B
    /// (F_B), half angle β_ATT (`safety.attitude`).
    pub line_of_sight: Cone,
    /// Grasping point in F_T [m] (`target.grasp_point_m`, or where `[world] grasp_point_m`
    /// puts the true one).
    pub grasp_t: [f64; 3],
    /// Capture tolerance: the radius of the grasping point's sphere [m].
    pub capture_tolerance_m: f64,
}

impl SceneGeometry {
    /// From the scenario. Both cones reach the servicer's initial range ‖p_0‖ (at least
    /// the zone's radius), so that the corridor contains the start of the approach
    /// and the line of sight reaches the target from it.
    pub fn from_scenario(s: &sc_scenario::Scenario) -> Self {
        let tr = &s.safety.translational;
        let p0 = s.servicer.initial_position_m;
        let range = (p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]).sqrt();
        let range = if range.is_finite() {
            range.max(tr.caz_radius_m)
        } else {
            tr.caz_radius_m
        };
        Self {
            corridor: Cone {
                axis: unit(tr.corridor_axis),
                half_angle_rad: tr.corridor_half_angle_deg.to_radians(),
                length_m: range,
            },
            zone_radius_m: tr.caz_radius_m,
            line_of_sight: Cone {
                axis: unit(s.servicer.boresight_body),
                half_angle_rad: s.safety.attitude.los_half_angle_deg.to_radians(),
                length_m: range,
            },
            // the true fixture: the world's where it differs from the declared one
            grasp_t: s
                .world
                .as_ref()
                .and_then(|w| w.grasp_point_m)
                .unwrap_or(s.target.grasp_point_m),
            capture_tolerance_m: s.mission.capture_tolerance_m,
        }
    }
}

/// One `foxglove.SceneUpdate`: every entity of [`SceneGeometry`], with lifetime 0 (kept
/// until replaced) and `frame_locked` (each follows its frame on `/tf`).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneUpdate {
    /// Mission time [ns].
    pub log_ns: u64,
    pub geometry: SceneGeometry,
    /// The mission phase it was written for (entity metadata).
    pub phase: String,
}

impl SceneUpdate {
    fn entity(&self, frame: &str, id: &str, meta: &[(&str, String)], prims: Value) -> Value {
        let mut e = json!({
            "timestamp": stamp(self.log_ns),
            "frame_id": frame,
            "id": id,
            "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": true,
            "metadata": meta.iter().chain([("phase", self.phase.clone())].iter())
                .map(|(k, v)| json!({"key": k, "value": v})).collect::<Vec<_>>(),
            "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
            "lines": [], "triangles": [], "texts": [], "models": [],
        });
        if let (Some(e), Value::Object(p)) = (e.as_object_mut(), prims) {
            e.extend(p);
        }
        e
    }

    fn label(at: [f64; 3], text: String) -> Value {
        json!({
            "pose": pose(at, [0.0, 0.0, 0.0, 1.0]),
            "billboard": true,
            "font_size": LABEL_FONT_PX,
            "scale_invariant": true,
            "color": color_json(COLOR_LABEL),
            "text": text,
        })
    }

    /// The entities, as JSON.
    pub fn entities(&self) -> Vec<Value> {
        let g = &self.geometry;
        let deg = |r: f64| format!("{:.2}", r.to_degrees());
        let tip = |c: &Cone| {
            let d = unit(c.axis);
            [d[0] * c.length_m, d[1] * c.length_m, d[2] * c.length_m]
        };
        let sphere = |at: [f64; 3], r: f64, color: Rgba| {
            json!({"pose": pose(at, [0.0, 0.0, 0.0, 1.0]),
                   "size": {"x": 2.0 * r, "y": 2.0 * r, "z": 2.0 * r},
                   "color": color_json(color)})
        };
        vec![
            self.entity(
                FRAME_REFERENCE,
                ENTITY_CORRIDOR,
                &[
                    ("half_angle_deg", deg(g.corridor.half_angle_rad)),
                    ("length_m", g.corridor.length_m.to_string()),
                ],
                json!({
                    "cylinders": [g.corridor.cylinder(COLOR_CORRIDOR)],
                    "texts": [Self::label(tip(&g.corridor), format!("approach corridor ψ_AC = {}°", deg(g.corridor.half_angle_rad)))],
                }),
            ),
            self.entity(
                FRAME_REFERENCE,
                ENTITY_ZONE,
                &[("radius_m", g.zone_radius_m.to_string())],
                json!({
                    "spheres": [sphere([0.0; 3], g.zone_radius_m, COLOR_ZONE)],
                    "texts": [Self::label([0.0, 0.0, g.zone_radius_m], format!("collision-avoidance zone R = {} m", g.zone_radius_m))],
                }),
            ),
            self.entity(
                FRAME_SERVICER_COM,
                ENTITY_LINE_OF_SIGHT,
                &[
                    ("half_angle_deg", deg(g.line_of_sight.half_angle_rad)),
                    ("length_m", g.line_of_sight.length_m.to_string()),
                ],
                json!({
                    "cylinders": [g.line_of_sight.cylinder(COLOR_LINE_OF_SIGHT)],
                    "texts": [Self::label(tip(&g.line_of_sight), format!("line of sight β = {}°", deg(g.line_of_sight.half_angle_rad)))],
                }),
            ),
            self.entity(
                FRAME_TARGET,
                ENTITY_GRASP,
                &[("capture_tolerance_m", g.capture_tolerance_m.to_string())],
                json!({"spheres": [sphere(g.grasp_t, g.capture_tolerance_m, COLOR_GRASP)]}),
            ),
        ]
    }
}

impl JsonMsg for SceneUpdate {
    fn write_json(&self, out: &mut Vec<u8>) {
        let _ = serde_json::to_writer(
            &mut *out,
            &json!({"deletions": [], "entities": self.entities()}),
        );
    }
    fn json_schema() -> Value {
        super::schemas::scene_update()
    }
    fn name() -> &'static str {
        "foxglove.SceneUpdate"
    }
}

/// What the recorder writes for the 3D panel besides the frames: the scene of the
/// scenario, once at the first state and again at every change of mission phase (so
/// that a seek into any phase finds it in that phase; Foxglove keeps the newest
/// entity per id).
#[derive(Debug, Clone)]
pub struct Scene {
    geometry: SceneGeometry,
    scenario: sc_scenario::Scenario,
    /// Phase index of the last update written.
    written: Option<usize>,
}

impl Scene {
    pub fn new(scenario: &sc_scenario::Scenario) -> Self {
        Self {
            geometry: SceneGeometry::from_scenario(scenario),
            scenario: scenario.clone(),
            written: None,
        }
    }

    /// The update to write with a state at time `t` [s] (mission time `log_ns`), if due.
    pub(crate) fn due(&mut self, t: f64, log_ns: u64) -> Option<SceneUpdate> {
        let phase = self.scenario.phase_index(t);
        if self.written == Some(phase) {
            return None;
        }
        self.written = Some(phase);
        Some(SceneUpdate {
            log_ns,
            geometry: self.geometry.clone(),
            phase: self
                .scenario
                .mission
                .phases
                .get(phase)
                .map(|p| p.name.clone())
                .unwrap_or_default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::test_util::{assert_cone, matches_schema, scenario};

    /// The scene is the scenario's geometry: the corridor cone (apex at the target's
    /// CoM, axis d_R, ψ_AC) and the zone sphere (R_CAZ) in the reference frame, the line
    /// of sight (boresight d_B, β) at the servicer's centre of mass, the grasping point
    /// (capture tolerance) on the target; each kept (lifetime 0) and frame-locked; its
    /// JSON is described completely by its schema.
    #[test]
    fn scene_is_the_scenario_geometry() {
        let sc = scenario();
        let upd = SceneUpdate {
            log_ns: 3 * NS_PER_S + 5,
            geometry: SceneGeometry::from_scenario(&sc),
            phase: "final_approach".into(),
        };
        let mut buf = Vec::new();
        upd.write_json(&mut buf);
        let v: Value = serde_json::from_slice(&buf).unwrap();
        matches_schema(&SceneUpdate::json_schema(), &v, "SceneUpdate");
        let ents = v["entities"].as_array().unwrap();
        let by_id = |id: &str| {
            ents.iter()
                .find(|e| e["id"] == id)
                .unwrap_or_else(|| panic!("{id}"))
        };
        for e in ents {
            assert_eq!(e["lifetime"], json!({"sec": 0, "nsec": 0}));
            assert_eq!(e["frame_locked"], true);
            assert_eq!(e["timestamp"], json!({"sec": 3, "nsec": 5}));
        }
        let tr = &sc.safety.translational;
        let p0 = nalgebra::Vector3::from(sc.servicer.initial_position_m).norm();
        let corridor = by_id(ENTITY_CORRIDOR);
        assert_eq!(corridor["frame_id"], FRAME_REFERENCE);
        assert_cone(
            &corridor["cylinders"][0],
            tr.corridor_axis,
            tr.corridor_half_angle_deg.to_radians(),
            p0,
        );
        let zone = by_id(ENTITY_ZONE);
        assert_eq!(zone["frame_id"], FRAME_REFERENCE);
        let sphere = &zone["spheres"][0];
        assert_eq!(
            sphere["size"],
            json!({"x": 2.0 * tr.caz_radius_m, "y": 2.0 * tr.caz_radius_m, "z": 2.0 * tr.caz_radius_m})
        );
        assert_eq!(
            sphere["pose"]["position"],
            json!({"x": 0.0, "y": 0.0, "z": 0.0})
        );
        let los = by_id(ENTITY_LINE_OF_SIGHT);
        assert_eq!(los["frame_id"], FRAME_SERVICER_COM);
        assert_cone(
            &los["cylinders"][0],
            sc.servicer.boresight_body,
            sc.safety.attitude.los_half_angle_deg.to_radians(),
            p0,
        );
        let grasp = by_id(ENTITY_GRASP);
        assert_eq!(grasp["frame_id"], FRAME_TARGET);
        let g = &grasp["spheres"][0];
        let gp = sc.target.grasp_point_m;
        assert_eq!(
            g["pose"]["position"],
            json!({"x": gp[0], "y": gp[1], "z": gp[2]})
        );
        assert_eq!(g["size"]["x"], 2.0 * sc.mission.capture_tolerance_m);
        assert!(
            corridor["metadata"]
                .as_array()
                .unwrap()
                .contains(&json!({"key": "phase", "value": "final_approach"}))
        );
        // another scenario, another scene: nothing is fixed in the code
        let mut other = sc.clone();
        other.safety.translational.corridor_axis = [0.0, 0.0, -1.0];
        other.safety.translational.corridor_half_angle_deg = 12.0;
        other.safety.attitude.los_half_angle_deg = 7.5;
        other.servicer.boresight_body = [0.0, 1.0, 0.0];
        let g = SceneGeometry::from_scenario(&other);
        let upd = SceneUpdate {
            log_ns: 0,
            geometry: g,
            phase: String::new(),
        };
        let ents = upd.entities();
        assert_cone(
            &ents[0]["cylinders"][0],
            [0.0, 0.0, -1.0],
            12f64.to_radians(),
            p0,
        );
        assert_cone(
            &ents[2]["cylinders"][0],
            [0.0, 1.0, 0.0],
            7.5f64.to_radians(),
            p0,
        );
    }
}
