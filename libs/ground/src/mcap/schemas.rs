//! JSON schemas of the Foxglove types the recorder writes (`foxglove.FrameTransform`,
//! `foxglove.SceneUpdate` and what they hold; docs.foxglove.dev), every property
//! described, with its unit where it has one. The ICD messages' schemas are generated
//! from their description (`sc_icd_gen::json_schema`).

use serde_json::{Value, json};

fn num(d: &str) -> Value {
    json!({"type": "number", "description": d})
}
fn string(d: &str) -> Value {
    json!({"type": "string", "description": d})
}
fn boolean(d: &str) -> Value {
    json!({"type": "boolean", "description": d})
}
fn time(d: &str) -> Value {
    let int = |d: &str| json!({"type": "integer", "minimum": 0, "description": d});
    json!({"type": "object", "title": "time", "description": d,
           "properties": {"sec": int("seconds [s]"), "nsec": int("nanoseconds [ns]")}})
}
fn vector3(d: &str, unit: &str) -> Value {
    json!({"type": "object", "title": "foxglove.Vector3", "description": d,
           "properties": {"x": num(&format!("x [{unit}]")), "y": num(&format!("y [{unit}]")),
                          "z": num(&format!("z [{unit}]"))}})
}
fn quaternion(d: &str) -> Value {
    json!({"type": "object", "title": "foxglove.Quaternion", "description": d,
           "properties": {"x": num("x [-]"), "y": num("y [-]"), "z": num("z [-]"), "w": num("w [-]")}})
}
fn pose(d: &str) -> Value {
    json!({"type": "object", "title": "foxglove.Pose", "description": d,
    "properties": {
        "position": vector3("position in the entity's frame", "m"),
        "orientation": quaternion("orientation (rotates local vectors into the entity's frame)"),
    }})
}
fn color(d: &str) -> Value {
    json!({"type": "object", "title": "foxglove.Color", "description": d,
           "properties": {"r": num("red, 0-1 [-]"), "g": num("green, 0-1 [-]"),
                          "b": num("blue, 0-1 [-]"), "a": num("alpha, 0-1 [-]")}})
}
fn array(d: &str, items: Value) -> Value {
    json!({"type": "array", "description": d, "items": items})
}
/// A primitive type this recording does not use (its lists are empty).
fn unused(d: &str, title: &str) -> Value {
    array(
        d,
        json!({"type": "object", "title": title,
                    "description": "not used by this recording (always empty)"}),
    )
}
fn sphere() -> Value {
    json!({"type": "object", "title": "foxglove.SpherePrimitive",
    "description": "A primitive representing a sphere or ellipsoid",
    "properties": {
        "pose": pose("position of the center of the sphere and orientation of the sphere"),
        "size": vector3("size (diameter) of the sphere along each axis", "m"),
        "color": color("color of the sphere"),
    }})
}
fn cylinder() -> Value {
    json!({"type": "object", "title": "foxglove.CylinderPrimitive",
    "description": "A primitive representing a cylinder, elliptic cylinder, or truncated cone",
    "properties": {
        "pose": pose("position of the center of the cylinder and orientation of the cylinder; the flat faces are perpendicular to its z axis"),
        "size": vector3("size of the cylinder's bounding box", "m"),
        "bottom_scale": num("ratio of the bottom face's (min z) diameter to the bounding box, 0-1 [-]"),
        "top_scale": num("ratio of the top face's (max z) diameter to the bounding box, 0-1 [-]"),
        "color": color("color of the cylinder"),
    }})
}
fn text() -> Value {
    json!({"type": "object", "title": "foxglove.TextPrimitive",
    "description": "A primitive representing a text label",
    "properties": {
        "pose": pose("position of the center of the text box and orientation of the text"),
        "billboard": boolean("whether the text always faces the camera (true) or respects pose.orientation (false)"),
        "font_size": num("font size: line height, in screen pixels when scale_invariant [px], else [m]"),
        "scale_invariant": boolean("whether font_size is in screen pixels (true) or in world units (false)"),
        "color": color("color of the text"),
        "text": string("text"),
    }})
}

/// Foxglove's `foxglove.FrameTransform` JSON schema (docs.foxglove.dev).
pub fn frame_transform() -> Value {
    json!({
        "title": "foxglove.FrameTransform",
        "description": "A transform between two reference frames in 3D space",
        "type": "object",
        "properties": {
            "timestamp": time("Timestamp of transform (mission time)"),
            "parent_frame_id": string("Name of the parent frame"),
            "child_frame_id": string("Name of the child frame"),
            "translation": vector3("Translation component of the transform [m]", "m"),
            "rotation": quaternion("Rotation component of the transform (rotates child-frame vectors into the parent frame)"),
        }
    })
}

/// Foxglove's `foxglove.SceneUpdate` JSON schema (docs.foxglove.dev, "SceneUpdate",
/// "SceneEntity" and the primitives), with units in the descriptions.
pub fn scene_update() -> Value {
    let kv = json!({"type": "object", "title": "foxglove.KeyValuePair",
                    "description": "a key with its value",
                    "properties": {"key": string("key"), "value": string("value")}});
    let deletion = json!({"type": "object", "title": "foxglove.SceneEntityDeletion",
    "description": "command to remove previously published entities",
    "properties": {
        "timestamp": time("only matching entities earlier than this are deleted (mission time)"),
        "type": {"type": "integer", "description": "0 MATCHING_ID (the entity with `id`), 1 ALL [-]"},
        "id": string("identifier that must match if type is MATCHING_ID"),
    }});
    let entity = json!({"type": "object", "title": "foxglove.SceneEntity",
    "description": "a visual element in a 3D scene; its primitives share its frame",
    "properties": {
        "timestamp": time("timestamp of the entity (mission time)"),
        "frame_id": string("frame of reference"),
        "id": string("identifier; replaces any prior entity on the topic with the same id"),
        "lifetime": {"type": "object", "title": "duration",
            "description": "time after timestamp when the entity is removed; 0 = kept until replaced",
            "properties": {
                "sec": {"type": "integer", "description": "seconds [s]"},
                "nsec": {"type": "integer", "minimum": 0, "description": "nanoseconds [ns]"},
            }},
        "frame_locked": boolean("whether the entity follows its frame as the frame moves (true) or stays where it was in the fixed frame (false)"),
        "metadata": array("user metadata (scenario values behind the entity, and the phase)", kv),
        "arrows": unused("arrow primitives", "foxglove.ArrowPrimitive"),
        "cubes": unused("cube primitives", "foxglove.CubePrimitive"),
        "spheres": array("sphere primitives", sphere()),
        "cylinders": array("cylinder primitives (the cones)", cylinder()),
        "lines": unused("line primitives", "foxglove.LinePrimitive"),
        "triangles": unused("triangle list primitives", "foxglove.TriangleListPrimitive"),
        "texts": array("text primitives (labels)", text()),
        "models": unused("model primitives", "foxglove.ModelPrimitive"),
    }});
    json!({
        "title": "foxglove.SceneUpdate",
        "description": "An update to the entities displayed in a 3D scene",
        "type": "object",
        "properties": {
            "deletions": array("scene entities to delete", deletion),
            "entities": array("scene entities to add or replace", entity),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::frames::FrameTransform;
    use crate::mcap::json::JsonMsg;
    use crate::mcap::scene::SceneUpdate;

    /// The JSON schema of every message type the recorder writes.
    pub(crate) fn all_schemas() -> Vec<Value> {
        vec![
            sc_icd::Tick::json_schema(),
            sc_icd::SimState::json_schema(),
            sc_icd::NominalTranslational::json_schema(),
            sc_icd::NominalAttitude::json_schema(),
            sc_icd::NominalRobotic::json_schema(),
            sc_icd::SafeTranslational::json_schema(),
            sc_icd::SafeAttitude::json_schema(),
            sc_icd::SafeRobotic::json_schema(),
            sc_icd::StepResult::json_schema(),
            sc_icd::NavigationError::json_schema(),
            sc_icd::NavState::json_schema(),
            FrameTransform::json_schema(),
            SceneUpdate::json_schema(),
        ]
    }

    /// Every property of `schema` (recursively, through objects and array items) without
    /// a non-empty description, or (when `unit`) without a `[unit]` in it, as paths.
    fn undescribed(schema: &Value, path: &str, unit: bool, bad: &mut Vec<String>) {
        if let Some(props) = schema.get("properties").and_then(Value::as_object) {
            for (k, v) in props {
                let p = format!("{path}.{k}");
                let d = v.get("description").and_then(Value::as_str).unwrap_or("");
                let leaf = v.get("properties").is_none();
                // a number (or an array of numbers) has a unit whatever the schema
                let numeric = |s: &Value| {
                    let t = &s["type"];
                    t == "number"
                        || t == "integer"
                        || t.as_array().is_some_and(|a| a.contains(&json!("number")))
                };
                let needs_unit = leaf && (unit || numeric(v) || numeric(&v["items"]));
                if d.trim().is_empty() || (needs_unit && !(d.contains('[') && d.contains(']'))) {
                    bad.push(p.clone());
                }
                undescribed(v, &p, unit, bad);
            }
        }
        if let Some(items) = schema.get("items") {
            undescribed(items, &format!("{path}[]"), unit, bad);
        }
    }

    /// Every field of every channel's schema has a description; every ICD field (and
    /// every numeric field of the Foxglove types) names its unit in brackets.
    #[test]
    fn every_schema_field_has_a_description_with_its_unit() {
        let mut bad = Vec::new();
        for s in all_schemas() {
            let title = s["title"].as_str().unwrap_or("?").to_string();
            assert!(s.get("description").is_some(), "{title}: no description");
            let icd = title.starts_with("safe_capture::");
            undescribed(&s, &title, icd, &mut bad);
        }
        assert!(bad.is_empty(), "fields without description/unit: {bad:?}");
        // the check can fail: a field without one is found
        let mut s = sc_icd::Tick::json_schema();
        s["properties"]["t"]
            .as_object_mut()
            .unwrap()
            .remove("description");
        let mut bad = Vec::new();
        undescribed(&s, "Tick", true, &mut bad);
        assert_eq!(bad, ["Tick.t"]);
        // the units are those of the ICD
        let st = sc_icd::SafeTranslational::json_schema();
        assert!(
            st["properties"]["actuated"]["description"]
                .as_str()
                .unwrap()
                .contains("f_B")
        );
        assert!(
            st["properties"]["h"]["items"]["description"]
                .as_str()
                .unwrap()
                .contains("0 approach_corridor [m], 1 collision_avoidance_zone [m²]")
        );
    }
}
