//! The JSON schema of an ICD message as the recorder's MCAP channels carry it
//! (encoding `jsonschema`): one property per field except the `_pad*` ones, in the
//! JSON the recorder writes (integers, numbers or `null` for NaN/inf, fixed-length
//! arrays), each described with its meaning, frame and unit; an array's items with
//! what each entry is (per barrier: its name and unit).

use crate::barriers::components_line;
use crate::field_line;
use sc_icd::spec::{FieldSpec, MessageSpec, Scalar};
use serde_json::{Map, Value, json};

/// The schema of one JSON value of scalar type `s` (NaN and inf are written as `null`).
fn scalar_schema(s: Scalar) -> Value {
    match s {
        Scalar::F64 => json!({"type": ["number", "null"]}),
        Scalar::U64 | Scalar::U32 | Scalar::I32 => json!({"type": "integer"}),
    }
}

/// The schema of one field, described.
pub fn field_schema(f: &FieldSpec) -> Value {
    let mut schema = match f.len {
        None => scalar_schema(f.scalar),
        Some(n) => {
            let mut items = scalar_schema(f.scalar);
            if let Some(d) = components_line(f.components) {
                items["description"] = d.into();
            }
            json!({"type": "array", "items": items, "minItems": n, "maxItems": n})
        }
    };
    schema["description"] = field_line(f).into();
    schema
}

/// The schema of a message: title its iceoryx2 type name, description its doc.
pub fn message_schema(spec: &MessageSpec) -> Value {
    let mut properties = Map::new();
    for f in spec.fields.iter().filter(|f| !f.is_padding()) {
        properties.insert(f.name.into(), field_schema(f));
    }
    json!({
        "title": spec.type_name,
        "description": spec.doc,
        "type": "object",
        "properties": Value::Object(properties),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_icd::Message;

    #[test]
    fn schema_describes_every_field_but_padding() {
        let s = message_schema(&sc_icd::Tick::SPEC);
        assert_eq!(s["title"], "safe_capture::v2::Tick");
        let props = s["properties"].as_object().unwrap();
        assert_eq!(props.len(), sc_icd::Tick::SPEC.fields.len() - 1);
        assert!(!props.contains_key("_pad0"));
        assert_eq!(props["t"]["type"], json!(["number", "null"]));
        assert_eq!(props["tick"]["type"], "integer");
        assert!(props["t"]["description"].as_str().unwrap().ends_with("[s]"));
        let st = message_schema(&sc_icd::SafeTranslational::SPEC);
        let h = &st["properties"]["h"];
        assert_eq!(
            (h["minItems"].as_u64(), h["maxItems"].as_u64()),
            (Some(2), Some(2))
        );
        assert!(
            h["items"]["description"]
                .as_str()
                .unwrap()
                .contains("0 approach_corridor [m], 1 collision_avoidance_zone [m²]")
        );
        assert!(
            st["properties"]["actuated"]["description"]
                .as_str()
                .unwrap()
                .contains("f_B")
        );
    }
}
