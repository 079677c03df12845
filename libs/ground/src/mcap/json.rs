//! Messages as JSON with their JSON schema. Every ICD message (`sc_icd::Message`) is
//! written by one generic writer that walks its description: each field but the
//! `_pad*` ones, in declaration order, read from the message's bytes at its offset —
//! integers as integers, `f64` in serde_json's shortest round-trip form, NaN and inf
//! as `null`, arrays as JSON arrays. Written straight into the output buffer (no
//! intermediate `serde_json::Value`: the recorder writes every message of a run).

use sc_icd::Message;
use sc_icd::spec::{FieldSpec, MessageSpec, Scalar};
use serde_json::Value;

/// A message written as one JSON object, with its JSON schema.
pub trait JsonMsg {
    /// Writes the message as one JSON object to `out`.
    fn write_json(&self, out: &mut Vec<u8>);
    /// The JSON schema of what [`JsonMsg::write_json`] writes.
    fn json_schema() -> Value;
    /// The schema's name (an ICD message: its iceoryx2 type name).
    fn name() -> &'static str;
}

impl<T: Message> JsonMsg for T {
    fn write_json(&self, out: &mut Vec<u8>) {
        write_message(&T::SPEC, self.as_bytes(), out);
    }
    fn json_schema() -> Value {
        sc_icd_gen::json_schema::message_schema(&T::SPEC)
    }
    fn name() -> &'static str {
        T::SPEC.type_name
    }
}

/// Writes the message of `spec` held in `bytes` (its memory, native byte order) as one
/// JSON object. A field outside `bytes` (never, for a message of `spec`) is `null`.
pub fn write_message(spec: &MessageSpec, bytes: &[u8], out: &mut Vec<u8>) {
    out.push(b'{');
    for (i, f) in spec.fields.iter().filter(|f| !f.is_padding()).enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.push(b'"');
        out.extend_from_slice(f.name.as_bytes());
        out.extend_from_slice(b"\":");
        write_field(f, bytes, out);
    }
    out.push(b'}');
}

/// One field: a scalar, or an array of its scalars.
fn write_field(f: &FieldSpec, bytes: &[u8], out: &mut Vec<u8>) {
    let Some(n) = f.len else {
        write_scalar(f.scalar, bytes, f.offset, out);
        return;
    };
    out.push(b'[');
    for k in 0..n {
        if k > 0 {
            out.push(b',');
        }
        write_scalar(f.scalar, bytes, f.offset + k * f.scalar.size(), out);
    }
    out.push(b']');
}

/// The `N` bytes at `offset`, if `bytes` holds them.
fn word<const N: usize>(bytes: &[u8], offset: usize) -> Option<[u8; N]> {
    bytes.get(offset..offset.checked_add(N)?)?.try_into().ok()
}

/// One scalar of type `s` at `offset`.
fn write_scalar(s: Scalar, bytes: &[u8], offset: usize, out: &mut Vec<u8>) {
    let written = match s {
        Scalar::F64 => word(bytes, offset).map(|b| write_f64(f64::from_ne_bytes(b), out)),
        Scalar::U64 => word(bytes, offset).map(|b| write_int(u64::from_ne_bytes(b), out)),
        Scalar::U32 => word(bytes, offset).map(|b| write_int(u32::from_ne_bytes(b), out)),
        Scalar::I32 => word(bytes, offset).map(|b| write_int(i32::from_ne_bytes(b), out)),
    };
    if written.is_none() {
        out.extend_from_slice(b"null");
    }
}

fn write_int<I: serde::Serialize>(x: I, out: &mut Vec<u8>) {
    let _ = serde_json::to_writer(&mut *out, &x);
}

/// A finite `f64` in serde_json's shortest round-trip form; NaN and inf, which are no
/// JSON numbers, as `null`.
fn write_f64(x: f64, out: &mut Vec<u8>) {
    if x.is_finite() {
        let _ = serde_json::to_writer(&mut *out, &x);
    } else {
        out.extend_from_slice(b"null");
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::matches_schema;
    use super::*;
    use serde_json::json;

    /// A message's JSON holds every field but the padding, in declaration order, with
    /// the message's values: integers exact, floats round-tripping, NaN/inf null.
    #[test]
    fn json_holds_every_field_with_its_value() {
        let mut s = sc_icd::SafeRobotic {
            tick: u64::MAX,
            solve_cpu_ns: u32::MAX,
            slack: 0.1 + 0.2,
            ..Default::default()
        };
        s.h[0] = f64::NAN;
        s.h[41] = -1.5e-300;
        s.u[6] = f64::NEG_INFINITY;
        let mut buf = Vec::new();
        s.write_json(&mut buf);
        let text = String::from_utf8(buf.clone()).unwrap();
        assert!(text.starts_with("{\"tick\":18446744073709551615,\"t\":0.0,"));
        let v: Value = serde_json::from_slice(&buf).unwrap();
        assert_eq!(v["solve_cpu_ns"], u32::MAX);
        assert_eq!(v["slack"].as_f64(), Some(0.1 + 0.2));
        assert_eq!(v["h"][0], Value::Null);
        assert_eq!(v["h"][41].as_f64(), Some(-1.5e-300));
        assert_eq!(v["u"][6], Value::Null);
        assert_eq!(
            v["h"].as_array().unwrap().len(),
            sc_icd::N_CONSTRAINTS_ROBOTIC
        );
        // keys in declaration order, no padding
        let keys: Vec<&str> = text[1..]
            .split(",\"")
            .filter_map(|p| p.trim_start_matches('"').split_once("\":").map(|k| k.0))
            .filter(|k| k.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
            .collect();
        let names: Vec<&str> = sc_icd::SafeRobotic::SPEC
            .fields
            .iter()
            .map(|f| f.name)
            .collect();
        assert_eq!(keys, names);
        let mut tick = Vec::new();
        sc_icd::Tick::default().write_json(&mut tick);
        assert!(!String::from_utf8(tick).unwrap().contains("_pad0"));
    }

    /// Every ICD message's JSON is described completely by its schema.
    #[test]
    fn every_message_matches_its_schema() {
        fn check<T: Message + Default>() {
            let mut buf = Vec::new();
            T::default().write_json(&mut buf);
            let v: Value = serde_json::from_slice(&buf).unwrap();
            matches_schema(&T::json_schema(), &v, T::SPEC.name);
        }
        check::<sc_icd::Tick>();
        check::<sc_icd::SimState>();
        check::<sc_icd::NominalTranslational>();
        check::<sc_icd::NominalAttitude>();
        check::<sc_icd::NominalRobotic>();
        check::<sc_icd::SafeTranslational>();
        check::<sc_icd::SafeAttitude>();
        check::<sc_icd::SafeRobotic>();
        check::<sc_icd::StepResult>();
        check::<sc_icd::Health>();
        assert_eq!(
            sc_icd::Health::name(),
            "safe_capture::v1::Health",
            "the schema is named by the type name"
        );
    }

    /// A field the bytes do not hold is written as null, never a panic.
    #[test]
    fn short_bytes_give_null() {
        let mut out = Vec::new();
        write_message(&sc_icd::Tick::SPEC, &[0u8; 12], &mut out);
        let v: Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(v["tick"], 0);
        assert_eq!(v["due_mask"], 0);
        assert_eq!(v["t"], Value::Null);
        assert_eq!(v["command"], json!(null));
    }
}
