//! Helpers of the MCAP module's tests.

use serde_json::{Value, json};

/// Foxglove's rotation of a child frame, `[x, y, z, w]` applied as `v' = q v q*`
/// (its convention: child-frame vectors into the parent frame).
pub fn foxglove_rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    let u = nalgebra::Vector3::new(x, y, z);
    let v = nalgebra::Vector3::new(v[0], v[1], v[2]);
    let t = 2.0 * u.cross(&v);
    let r = v + w * t + u.cross(&t);
    [r[0], r[1], r[2]]
}

/// Every property of `schema` that `v` has, recursively, and `v` has nothing else:
/// the schema describes the message completely.
pub fn matches_schema(schema: &Value, v: &Value, path: &str) {
    match (schema.get("properties").and_then(Value::as_object), v) {
        (Some(props), Value::Object(o)) => {
            for k in o.keys() {
                let sub = props
                    .get(k)
                    .unwrap_or_else(|| panic!("{path}.{k} not in schema"));
                matches_schema(sub, &o[k], &format!("{path}.{k}"));
            }
            for k in props.keys() {
                assert!(o.contains_key(k), "{path}.{k} missing from the message");
            }
        }
        (None, Value::Array(a)) => {
            assert_eq!(schema["type"], "array", "{path}");
            for x in a {
                matches_schema(&schema["items"], x, &format!("{path}[]"));
            }
        }
        (None, Value::Number(_)) => assert!(
            schema["type"] == "number"
                || schema["type"] == "integer"
                || schema["type"]
                    .as_array()
                    .is_some_and(|t| t.contains(&json!("number"))),
            "{path}: {schema}"
        ),
        (None, Value::String(_)) => assert_eq!(schema["type"], "string", "{path}"),
        (None, Value::Bool(_)) => assert_eq!(schema["type"], "boolean", "{path}"),
        (s, v) => panic!("{path}: {v} against {s:?}"),
    }
}

/// The project's default scenario (config/scenario.toml).
pub fn scenario() -> sc_scenario::Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenario.toml");
    sc_scenario::Scenario::load(&path).unwrap()
}

/// The cylinder of a cone, as Foxglove draws it: its apex (bottom face, scale 0) at
/// the frame's origin, its axis (local z turned by the pose) along the cone's,
/// its top face's radius `L tan(half angle)`.
pub fn assert_cone(cyl: &Value, axis: [f64; 3], half_angle_rad: f64, length: f64) {
    let p = &cyl["pose"]["position"];
    let o = &cyl["pose"]["orientation"];
    let q = [
        o["x"].as_f64().unwrap(),
        o["y"].as_f64().unwrap(),
        o["z"].as_f64().unwrap(),
        o["w"].as_f64().unwrap(),
    ];
    let z = foxglove_rotate(q, [0.0, 0.0, 1.0]);
    let size = &cyl["size"];
    let l = size["z"].as_f64().unwrap();
    assert!((l - length).abs() < 1e-12);
    let centre = [
        p["x"].as_f64().unwrap(),
        p["y"].as_f64().unwrap(),
        p["z"].as_f64().unwrap(),
    ];
    for k in 0..3 {
        assert!((z[k] - axis[k]).abs() < 1e-12, "axis {z:?} vs {axis:?}");
        assert!(
            (centre[k] - z[k] * l / 2.0).abs() < 1e-12,
            "apex not at the origin"
        );
    }
    assert_eq!(cyl["bottom_scale"], 0.0);
    assert_eq!(cyl["top_scale"], 1.0);
    let r = size["x"].as_f64().unwrap() / 2.0;
    assert!((r - l * half_angle_rad.tan()).abs() < 1e-12);
    assert_eq!(size["x"], size["y"]);
}
