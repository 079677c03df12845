//! MCAP output of the recorder: one channel per service, JSON-encoded messages with
//! a JSON schema each (Foxglove plots every numeric field).

use anyhow::Context;
use serde_json::{Map, Value, json};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// A message field as JSON.
pub trait JsonField {
    fn json(&self) -> Value;
    fn schema() -> Value;
}
impl JsonField for u64 {
    fn json(&self) -> Value {
        json!(self)
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for u32 {
    fn json(&self) -> Value {
        json!(self)
    }
    fn schema() -> Value {
        json!({"type": "integer"})
    }
}
impl JsonField for f64 {
    // NaN/inf are not JSON numbers: written as null
    fn json(&self) -> Value {
        serde_json::Number::from_f64(*self)
            .map(Value::Number)
            .unwrap_or(Value::Null)
    }
    fn schema() -> Value {
        json!({"type": ["number", "null"]})
    }
}
impl<const N: usize> JsonField for [f64; N] {
    fn json(&self) -> Value {
        Value::Array(self.iter().map(|x| x.json()).collect())
    }
    fn schema() -> Value {
        json!({"type": "array", "items": {"type": ["number", "null"]}, "minItems": N, "maxItems": N})
    }
}

/// An ICD message as a JSON object, with its JSON schema.
pub trait JsonMsg {
    fn to_json(&self) -> Value;
    fn json_schema() -> Value;
    fn name() -> &'static str;
}

macro_rules! json_msg {
    ($t:ident { $($f:ident),* $(,)? }) => {
        impl JsonMsg for sc_icd::$t {
            fn to_json(&self) -> Value {
                let mut m = Map::new();
                $( m.insert(stringify!($f).into(), JsonField::json(&self.$f)); )*
                Value::Object(m)
            }
            fn json_schema() -> Value {
                let mut p = Map::new();
                $( p.insert(stringify!($f).into(), field_schema(&|s: &sc_icd::$t| s.$f)); )*
                json!({"title": sc_icd::type_name_of::<sc_icd::$t>(), "type": "object", "properties": Value::Object(p)})
            }
            fn name() -> &'static str { sc_icd::type_name_of::<sc_icd::$t>() }
        }
    };
}

fn field_schema<T, F: JsonField>(_: &dyn Fn(&T) -> F) -> Value {
    F::schema()
}

json_msg!(Tick {
    tick,
    due_mask,
    clock_mode,
    t,
    send_ns,
    command
});
json_msg!(SimState {
    tick,
    t,
    due_mask,
    tick_send_ns,
    recv_ns,
    publish_ns,
    step,
    r_h,
    v_h,
    r_r,
    v_r,
    q_hr,
    omega_h,
    omega_dot_h,
    mean_motion,
    q_rb,
    omega_b,
    theta,
    theta_dot,
    q_rt,
    omega_t,
    omega_dot_t,
    grasp_r,
    grasp_v_r,
    grasp_a_r,
    grasp_b,
    ee_b,
    ee_r,
    ee_v_r
});
json_msg!(NominalTranslational {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    f_h
});
json_msg!(NominalAttitude {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    tau_b
});
json_msg!(NominalRobotic {
    tick,
    t,
    valid,
    phase,
    recv_ns,
    publish_ns,
    tau_m
});
json_msg!(SafeTranslational {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(SafeAttitude {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(SafeRobotic {
    tick,
    t,
    recv_ns,
    publish_ns,
    active_mask,
    solve_ns,
    solver_status,
    iterations,
    fault_flags,
    n_constraints,
    phase,
    slack,
    h,
    phi,
    u,
    actuated
});
json_msg!(StepResult {
    tick,
    t,
    end,
    fallback_mask,
    held_mask,
    fault_flags,
    safe_recv_ns,
    publish_ns,
    force_b,
    torque_b,
    tau
});

/// The MCAP file being written.
pub struct McapOut {
    w: mcap::Writer<BufWriter<std::fs::File>>,
    channels: BTreeMap<String, u16>,
    seq: u32,
    /// Messages written per topic.
    pub written: BTreeMap<String, u64>,
}

impl McapOut {
    /// Creates `path`.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let f = std::fs::File::create(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        let w = mcap::Writer::new(BufWriter::new(f)).context("mcap header")?;
        Ok(Self {
            w,
            channels: BTreeMap::new(),
            seq: 0,
            written: BTreeMap::new(),
        })
    }

    /// Writes one message on topic `topic` at `log_ns` (monotonic clock).
    pub fn write<T: JsonMsg>(&mut self, topic: &str, log_ns: u64, msg: &T) -> anyhow::Result<()> {
        let id = match self.channels.get(topic) {
            Some(id) => *id,
            None => {
                let schema = serde_json::to_vec(&T::json_schema())?;
                let sid = self
                    .w
                    .add_schema(T::name(), "jsonschema", &schema)
                    .context("mcap schema")?;
                let cid = self
                    .w
                    .add_channel(sid, topic, "json", &BTreeMap::new())
                    .context("mcap channel")?;
                self.channels.insert(topic.to_string(), cid);
                cid
            }
        };
        self.seq = self.seq.wrapping_add(1);
        let data = serde_json::to_vec(&msg.to_json())?;
        self.w
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: self.seq,
                    log_time: log_ns,
                    publish_time: log_ns,
                },
                &data,
            )
            .context("mcap write")?;
        *self.written.entry(topic.to_string()).or_default() += 1;
        Ok(())
    }

    /// Writes the summary section and closes the file.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        self.w.finish().context("mcap finish")?;
        Ok(())
    }
}
