//! The declarations of the ICD: each message, constant group and service is written
//! once, through these macros, which give both the Rust item and its description in
//! [`crate::spec`].

/// Declares one message: the `#[repr(C)]` struct (derives `Debug, Clone, Copy,
/// ZeroCopySend, PartialEq`, the given `#[type_name]`, `Default` and [`crate::Zeroed`]
/// all-zero) and its [`crate::spec::Message`] description. Every field has a doc
/// comment (its meaning) and, after `=`, its unit and, for an array, its frame and its
/// components: `= ["m", Hill, Xyz]` (frame: a [`crate::spec::Frame`] variant;
/// components: `Xyz`, `Wxyz`, `Joints`, `Barriers`, `Constraints(<Subsystem>)`,
/// `Rates(<Subsystem>)`), and after `=>` the constant group whose values or bits it
/// carries, if any (`=> due`). A compile-time guard checks that the fields fill every byte.
macro_rules! icd_message {
    (
        $(#[doc = $doc:literal])+
        #[type_name($type_name:literal)]
        pub struct $name:ident {
            $(
                $(#[doc = $fdoc:literal])+
                pub $field:ident : $ty:ty = [$unit:literal $(, $frame:ident, $($comp:tt)+)?]
                $(=> $values:ident)?
            ),+ $(,)?
        }
    ) => {
        $(#[doc = $doc])+
        #[derive(Debug, Clone, Copy, ZeroCopySend, PartialEq)]
        #[repr(C)]
        #[type_name($type_name)]
        pub struct $name {
            $(
                $(#[doc = $fdoc])+
                #[doc = concat!("[", $unit, "]" $(, ", frame ", stringify!($frame))?)]
                pub $field: $ty,
            )+
        }

        // SAFETY: repr(C), and the guard below proves the fields fill every byte.
        unsafe impl $crate::spec::Message for $name {
            const SPEC: $crate::spec::MessageSpec = $crate::spec::MessageSpec {
                name: stringify!($name),
                type_name: $type_name,
                doc: $crate::spec::doc_text(concat!($($doc),+)),
                size: core::mem::size_of::<$name>(),
                align: core::mem::align_of::<$name>(),
                fields: &[$(
                    $crate::spec::FieldSpec {
                        name: stringify!($field),
                        scalar: <$ty as $crate::spec::FieldType>::SCALAR,
                        len: <$ty as $crate::spec::FieldType>::LEN,
                        offset: core::mem::offset_of!($name, $field),
                        unit: $unit,
                        frame: icd_frame!($($frame)?),
                        components: icd_components!($($($comp)+)?),
                        values: icd_values!($($values)?),
                        meaning: $crate::spec::doc_text(concat!($($fdoc),+)),
                    }
                ),+],
            };
        }

        const _: () = assert!(
            <$name as $crate::spec::Message>::SPEC.fields_fill_every_byte(),
            concat!(stringify!($name), ": a gap (implicit padding) or a field missing")
        );

        impl $crate::Zeroed for $name {
            fn zeroed() -> Self {
                // SAFETY: the type is repr(C) made only of integers and f64, for which
                // the all-zero bit pattern is a valid value.
                unsafe { core::mem::zeroed() }
            }
        }

        impl Default for $name {
            fn default() -> Self {
                <$name as $crate::Zeroed>::zeroed()
            }
        }
    };
}

/// The [`crate::spec::Frame`] of a field: `Frame::None` unless one is given.
macro_rules! icd_frame {
    () => {
        $crate::spec::Frame::None
    };
    ($frame:ident) => {
        $crate::spec::Frame::$frame
    };
}

/// The constant group of a field's values: none unless one is given.
macro_rules! icd_values {
    () => {
        None
    };
    ($group:ident) => {
        Some(&$group::GROUP)
    };
}

/// The [`crate::spec::Components`] of a field: `One` for a scalar.
macro_rules! icd_components {
    () => {
        $crate::spec::Components::One
    };
    (Constraints($s:ident)) => {
        $crate::spec::Components::Constraints {
            subsystem: $crate::Subsystem::$s,
            per_second: false,
        }
    };
    (Rates($s:ident)) => {
        $crate::spec::Components::Constraints {
            subsystem: $crate::Subsystem::$s,
            per_second: true,
        }
    };
    ($c:ident) => {
        $crate::spec::Components::$c
    };
}

/// Declares one group of constants as a module: each `pub const` with its doc, and the
/// module's `GROUP`, a [`crate::spec::ConstGroup`] with the C/Python prefix given after
/// `=` (`SC_<prefix>_<NAME>` in C, `<prefix>_<NAME>` in Python).
macro_rules! icd_constants {
    (
        $(#[doc = $doc:literal])+
        pub mod $module:ident : $ty:ty = $prefix:literal {
            $(
                $(#[doc = $cdoc:literal])+
                $name:ident = $value:expr
            ),+ $(,)?
        }
    ) => {
        $(#[doc = $doc])+
        pub mod $module {
            #[allow(unused_imports)]
            use super::*;

            $(
                $(#[doc = $cdoc])+
                pub const $name: $ty = $value;
            )+

            /// This group's description (values, docs, C and Python names).
            pub const GROUP: $crate::spec::ConstGroup = $crate::spec::ConstGroup {
                module: stringify!($module),
                prefix: $prefix,
                doc: $crate::spec::doc_text(concat!($($doc),+)),
                items: &[$(
                    $crate::spec::ConstSpec {
                        name: stringify!($name),
                        value: $name as u64,
                        doc: $crate::spec::doc_text(concat!($($cdoc),+)),
                    }
                ),+],
            };
        }
    };
}

/// Declares the services: each `pub const` [`crate::ServiceName`] with its doc, and
/// `SERVICES`, their [`crate::spec::ServiceSpec`]s (pub/sub services first, with the
/// message type and the QoS class; then the event-only services, with their
/// sub-services).
macro_rules! icd_services {
    (
        pubsub {
            $(
                $(#[doc = $doc:literal])+
                $name:ident = $path:literal, $msg:ident, $qos:ident;
            )+
        }
        events {
            $(
                $(#[doc = $edoc:literal])+
                $ename:ident = $epath:literal, [$($sub:literal),*];
            )+
        }
    ) => {
        $(
            $(#[doc = $doc])+
            pub const $name: ServiceName = ServiceName($path);
        )+
        $(
            $(#[doc = $edoc])+
            pub const $ename: ServiceName = ServiceName($epath);
        )+

        /// Every service, described (pub/sub services, then event-only services).
        pub const SERVICES: &[$crate::spec::ServiceSpec] = &[
            $(
                $crate::spec::ServiceSpec {
                    constant: stringify!($name),
                    name: $name,
                    message: Some(&<$crate::$msg as $crate::spec::Message>::SPEC),
                    qos: $crate::spec::Qos::$qos,
                    sub_services: &[],
                    doc: $crate::spec::doc_text(concat!($($doc),+)),
                },
            )+
            $(
                $crate::spec::ServiceSpec {
                    constant: stringify!($ename),
                    name: $ename,
                    message: None,
                    qos: $crate::spec::Qos::EventOnly,
                    sub_services: &[$($sub),*],
                    doc: $crate::spec::doc_text(concat!($($edoc),+)),
                },
            )+
        ];
    };
}
