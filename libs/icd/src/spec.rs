//! The ICD as data: every message, constant group and service described once, with
//! the units, frames and meaning of every field. The messages' Rust types and these
//! descriptions come from the same declaration ([`icd_message!`](crate::icd_message),
//! [`icd_constants!`](crate::icd_constants), [`icd_services!`](crate::icd_services)), so
//! they cannot drift apart; the ground crate `sc-icd-gen` renders them as the C header,
//! the Python module, the MCAP JSON schemas and the tables of docs/ICD.md.
//!
//! Everything here is `const` data: the flight software pays nothing for it.

use crate::ServiceName;
use sc_core::Subsystem;

/// A scalar type a message field may have (the ICD's rules allow no other).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Scalar {
    /// IEEE-754 binary64.
    F64,
    /// Unsigned 64-bit integer.
    U64,
    /// Unsigned 32-bit integer.
    U32,
    /// Signed 32-bit integer.
    I32,
}

impl Scalar {
    /// Size [B].
    pub const fn size(self) -> usize {
        match self {
            Scalar::F64 | Scalar::U64 => 8,
            Scalar::U32 | Scalar::I32 => 4,
        }
    }

    /// The Rust spelling (`f64`, `u64`, `u32`, `i32`).
    pub const fn rust_name(self) -> &'static str {
        match self {
            Scalar::F64 => "f64",
            Scalar::U64 => "u64",
            Scalar::U32 => "u32",
            Scalar::I32 => "i32",
        }
    }
}

/// A Rust type a message field may have: a [`Scalar`] or a fixed array of one.
pub trait FieldType {
    /// The scalar (the element type of an array).
    const SCALAR: Scalar;
    /// Array length; `None` for a scalar.
    const LEN: Option<usize>;
}

macro_rules! scalar_field_type {
    ($($t:ty => $s:ident),*) => {$(
        impl FieldType for $t {
            const SCALAR: Scalar = Scalar::$s;
            const LEN: Option<usize> = None;
        }
        impl<const N: usize> FieldType for [$t; N] {
            const SCALAR: Scalar = Scalar::$s;
            const LEN: Option<usize> = Some(N);
        }
    )*};
}
scalar_field_type!(f64 => F64, u64 => U64, u32 => U32, i32 => I32);

/// The frame a field's vector is expressed in (or the frames a quaternion relates).
/// F_I Earth-centred inertial frame, F_H Hill (LVLH) frame of the target orbit, F_R reference frame, F_B servicer base
/// (body) frame, F_T target body frame, M manipulator joint space. Quaternions are
/// scalar-first `[w, x, y, z]`; `q_XY` rotates F_Y vectors into F_X.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Frame {
    /// Not a vector in space: a time, a stamp, a counter, a flag, a barrier value.
    None,
    /// F_H, the Hill (LVLH) frame of the target orbit.
    Hill,
    /// F_R, the reference frame.
    Reference,
    /// F_B, the servicer base (body) frame.
    Base,
    /// F_T, the target body frame.
    Target,
    /// M, the manipulator's joint space (one entry per joint).
    Joints,
    /// q_HR: rotates F_R vectors into F_H.
    HillFromReference,
    /// q_RB: rotates F_B vectors into F_R.
    ReferenceFromBase,
    /// q_RT: rotates F_T vectors into F_R.
    ReferenceFromTarget,
    /// F_I, the Earth-centred inertial frame the simulator propagates in.
    Inertial,
    /// q_IB: rotates F_B vectors into F_I.
    InertialFromBase,
    /// q_IT: rotates F_T vectors into F_I.
    InertialFromTarget,
}

impl Frame {
    /// The symbol (`F_H`, `F_R → F_H` for a rotation, empty for [`Frame::None`]).
    pub const fn symbol(self) -> &'static str {
        match self {
            Frame::None => "",
            Frame::Hill => "F_H",
            Frame::Reference => "F_R",
            Frame::Base => "F_B",
            Frame::Target => "F_T",
            Frame::Joints => "M",
            Frame::HillFromReference => "F_R → F_H",
            Frame::ReferenceFromBase => "F_B → F_R",
            Frame::ReferenceFromTarget => "F_T → F_R",
            Frame::Inertial => "F_I",
            Frame::InertialFromBase => "F_B → F_I",
            Frame::InertialFromTarget => "F_T → F_I",
        }
    }
}

/// What the entries of an array field are, one by one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Components {
    /// A scalar field (no entries).
    One,
    /// `x, y, z` of a vector.
    Xyz,
    /// `w, x, y, z` of a scalar-first quaternion.
    Wxyz,
    /// One entry per manipulator joint, joints 1..N in order.
    Joints,
    /// Every barrier of the safety layer in telemetry order (`sc_mission::constraint_names`).
    Barriers,
    /// The constraints of one subsystem's safety filter, in its report's order
    /// (`sc_cbf::names`); `per_second`: the entries are rates (Φ_i, units of h per s).
    Constraints {
        /// Whose filter.
        subsystem: Subsystem,
        /// Units of h per second rather than units of h.
        per_second: bool,
    },
}

/// Unit of an array whose entries carry the unit of their constraint (see
/// [`Components::Barriers`], [`Components::Constraints`]).
pub const UNIT_PER_CONSTRAINT: &str = "unit per constraint";
/// Unit of an array of constraint rates: the unit of each constraint per second.
pub const UNIT_PER_CONSTRAINT_PER_S: &str = "unit per constraint / s";

/// One field of a message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldSpec {
    /// Name (the same in Rust, C, Python and the MCAP JSON).
    pub name: &'static str,
    /// Scalar type (the element type of an array).
    pub scalar: Scalar,
    /// Array length; `None` for a scalar.
    pub len: Option<usize>,
    /// Offset in the `#[repr(C)]` struct [B] (`core::mem::offset_of!`).
    pub offset: usize,
    /// SI unit (`-` for a dimensionless number, a count, a flag or a bitset).
    pub unit: &'static str,
    /// Frame of a vector, or [`Frame::None`].
    pub frame: Frame,
    /// What the entries of an array are.
    pub components: Components,
    /// The constant group whose values (or bits) the field carries, if any.
    pub values: Option<&'static ConstGroup>,
    /// What the field means (its doc comment, without the unit).
    pub meaning: &'static str,
}

impl FieldSpec {
    /// Size [B].
    pub const fn size(&self) -> usize {
        match self.len {
            Some(n) => n * self.scalar.size(),
            None => self.scalar.size(),
        }
    }

    /// An explicit padding field (`_pad*`, always 0): in the layout, not in telemetry.
    pub fn is_padding(&self) -> bool {
        self.name.starts_with("_pad")
    }
}

/// One message: a `#[repr(C)]` struct that crosses process boundaries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageSpec {
    /// Rust name (C: `Sc<name>`, Python: the same).
    pub name: &'static str,
    /// iceoryx2 type name (`#[type_name]`), versioned: `safe_capture::vN::<name>`.
    pub type_name: &'static str,
    /// What it is, who sends it to whom (its doc comment).
    pub doc: &'static str,
    /// `size_of` [B].
    pub size: usize,
    /// `align_of` [B].
    pub align: usize,
    /// Every field, in declaration (= memory) order.
    pub fields: &'static [FieldSpec],
}

impl MessageSpec {
    /// The field named `name`.
    pub fn field(&self, name: &str) -> Option<&'static FieldSpec> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// True when the fields follow one another without a gap and fill the struct: no
    /// byte of the message is padding the compiler inserted. Checked at compile time
    /// for every message by [`icd_message!`](crate::icd_message).
    pub const fn fields_fill_every_byte(&self) -> bool {
        let mut end = 0;
        let mut i = 0;
        while i < self.fields.len() {
            if self.fields[i].offset != end {
                return false;
            }
            end += self.fields[i].size();
            i += 1;
        }
        end == self.size
    }
}

/// A message type of the ICD, with its description.
///
/// # Safety
/// `Self` is `#[repr(C)]` and every byte of it belongs to a field of [`Self::SPEC`]
/// (no padding; checked at compile time by [`icd_message!`](crate::icd_message), the
/// only place that implements this trait), so [`Message::as_bytes`] reads only
/// initialised memory.
pub unsafe trait Message: Copy + 'static {
    /// The description: fields with offsets, units, frames, meaning.
    const SPEC: MessageSpec;

    /// The message's bytes in memory (native byte order), [`MessageSpec::size`] long.
    fn as_bytes(&self) -> &[u8] {
        // SAFETY: `Self` has no padding (trait contract), so all `size_of::<Self>()`
        // bytes behind the reference are initialised, and they live as long as `self`.
        unsafe {
            core::slice::from_raw_parts(
                (self as *const Self).cast::<u8>(),
                core::mem::size_of::<Self>(),
            )
        }
    }
}

/// One named constant of a [`ConstGroup`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConstSpec {
    /// Rust name inside its group (`TRANSLATIONAL` of `due`).
    pub name: &'static str,
    /// Value.
    pub value: u64,
    /// What it means.
    pub doc: &'static str,
}

/// A group of constants a partner needs: the values of one field (`Tick.command`), the
/// bits of a bitset (`due_mask`) or the array lengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConstGroup {
    /// Rust module (`due`).
    pub module: &'static str,
    /// Prefix of the constants' names in C (`SC_<prefix>_<NAME>`) and Python
    /// (`<prefix>_<NAME>`); empty for none.
    pub prefix: &'static str,
    /// What the group is and which fields carry it.
    pub doc: &'static str,
    /// Every constant, in declaration order.
    pub items: &'static [ConstSpec],
}

impl ConstGroup {
    /// The name of `item` outside Rust, without the C prefix `SC_` (`DUE_ROBOTIC`).
    pub fn qualified(&self, item: &ConstSpec) -> String {
        if self.prefix.is_empty() {
            item.name.to_string()
        } else {
            format!("{}_{}", self.prefix, item.name)
        }
    }
}

/// Quality of service of a service: how a full subscriber is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Qos {
    /// The flight side: never silently lossy; a full subscriber loses the sample at once,
    /// alone, and the publisher reports it — a flight publisher never waits for a reader
    /// (`sc_flight::process::qos`, Python `sc_bus.PARTITION`).
    Flight,
    /// Partner-facing: newest wins, nobody ever waits (`sc_flight::process::partner_qos`,
    /// Python `sc_bus.NOMINAL`).
    Partner,
    /// An event service only: no payload.
    EventOnly,
}

impl Qos {
    /// Lower-case name (`flight`, `partner`, `event only`).
    pub const fn name(self) -> &'static str {
        match self {
            Qos::Flight => "flight",
            Qos::Partner => "partner",
            Qos::EventOnly => "event only",
        }
    }
}

/// One service of the partition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServiceSpec {
    /// Rust constant in [`crate::services`] (`SIM_STATE`).
    pub constant: &'static str,
    /// The service name.
    pub name: ServiceName,
    /// The message it carries; `None` for an event-only service.
    pub message: Option<&'static MessageSpec>,
    /// How a full subscriber is treated.
    pub qos: Qos,
    /// Event services under this name (`<name>/<sub>`), e.g. the handshake's `ready`, `go`.
    pub sub_services: &'static [&'static str],
    /// What it is for, who wakes on it.
    pub doc: &'static str,
}

impl ServiceSpec {
    /// The roles that publish (or notify) it, from the role table.
    pub fn publishers(&self) -> impl Iterator<Item = &'static crate::Role> {
        let name = self.name;
        crate::ROLES
            .iter()
            .filter(move |r| r.publishes.contains(&name))
    }

    /// The roles that subscribe to (or listen on) it, from the role table.
    pub fn subscribers(&self) -> impl Iterator<Item = &'static crate::Role> {
        let name = self.name;
        crate::ROLES
            .iter()
            .filter(move |r| r.subscribes.contains(&name))
    }
}

/// The meaning of a field from its doc lines (`concat!` of `///` lines): the text
/// without the leading space rustdoc keeps.
#[doc(hidden)]
pub const fn doc_text(doc: &'static str) -> &'static str {
    doc.trim_ascii()
}
