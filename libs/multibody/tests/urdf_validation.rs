//! URDF validation: each rule has one test with a bad URDF string; errors name the element,
//! the value and the rule; nothing panics on bad input.

mod common;

use std::path::Path;

use sc_multibody::{ModelError, Robot};

const GOOD: &str = include_str!("../../../config/servicer.urdf");

/// The servicer URDF with one textual substitution (must match exactly once).
fn bad(from: &str, to: &str) -> String {
    assert_eq!(
        GOOD.matches(from).count(),
        1,
        "pattern '{from}' must be unique"
    );
    GOOD.replacen(from, to, 1)
}

fn err(urdf: &str) -> ModelError {
    match Robot::from_urdf_str(urdf) {
        Ok(_) => panic!("bad URDF accepted"),
        Err(e) => {
            eprintln!("{e}");
            e
        }
    }
}

#[test]
fn good_urdf_loads() {
    let r = Robot::from_urdf_str(GOOD).unwrap();
    assert_eq!(r.name(), "servicer");
    assert_eq!(r.body_names()[0], "base");
    assert_eq!(r.ee_frame().name, "end_effector");
}

#[test]
fn negative_mass() {
    let e = err(&bad(
        r#"<mass value="3.5"/>
      <inertia ixx="0.0053""#,
        r#"<mass value="-3.5"/>
      <inertia ixx="0.0053""#,
    ));
    assert!(
        matches!(&e, ModelError::InvalidMass { link, value } if link == "link2" && *value == -3.5)
    );
    let msg = e.to_string();
    assert!(msg.contains("link2") && msg.contains("-3.5") && msg.contains("rule"));
}

#[test]
fn non_positive_definite_inertia() {
    let e = err(&bad(
        r#"ixx="0.00375" ixy="0.0001""#,
        r#"ixx="-0.00375" ixy="0.0001""#,
    ));
    assert!(matches!(&e, ModelError::NonPositiveDefiniteInertia { link, .. } if link == "link4"));
    assert!(e.to_string().contains("positive definite"));
}

#[test]
fn triangle_inequality() {
    let e = err(&bad(
        r#"ixx="0.0015" ixy="0" ixz="0.00004" iyy="0.0020""#,
        r#"ixx="0.0001" ixy="0" ixz="0.00004" iyy="0.0010""#,
    ));
    assert!(matches!(&e, ModelError::TriangleInequality { link, .. } if link == "link6"));
    assert!(e.to_string().contains("triangle"));
}

#[test]
fn zero_axis() {
    let from = r#"<child link="link3"/>
    <axis xyz="1 0 0"/>"#;
    let e = err(&bad(
        from,
        r#"<child link="link3"/>
    <axis xyz="0 0 0"/>"#,
    ));
    assert!(matches!(&e, ModelError::ZeroAxis { joint, .. } if joint == "joint_3"));
}

#[test]
fn lower_above_upper() {
    let e = err(&bad(
        r#"lower="-2.792526803190927" upper="2.792526803190927""#,
        r#"lower="1.5" upper="-1.5""#,
    ));
    assert!(matches!(&e, ModelError::LimitOrder { joint, lower, upper }
        if joint == "joint_4" && *lower == 1.5 && *upper == -1.5));
    let msg = e.to_string();
    assert!(msg.contains("joint_4") && msg.contains("1.5") && msg.contains("lower <= upper"));
}

#[test]
fn missing_file() {
    let e = Robot::from_urdf_file(Path::new("/nonexistent/servicer.urdf")).unwrap_err();
    assert!(matches!(e, ModelError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/servicer.urdf"));
}

#[test]
fn wrong_joint_count() {
    // turn joint 7 into a fixed joint: 6 revolute joints
    let from = r#"<joint name="joint_7" type="revolute">"#;
    let e = err(&bad(from, r#"<joint name="joint_7" type="fixed">"#));
    assert!(matches!(
        e,
        ModelError::JointCount {
            found: 6,
            expected: 7
        }
    ));
}

#[test]
fn unsupported_joint_type() {
    let e = err(&bad(
        r#"<joint name="joint_5" type="revolute">"#,
        r#"<joint name="joint_5" type="prismatic">"#,
    ));
    assert!(matches!(&e, ModelError::UnsupportedJoint { joint, .. } if joint == "joint_5"));
}

#[test]
fn invalid_velocity_and_effort_limits() {
    let from = r#"<child link="link1"/>
    <axis xyz="1 0 0"/>
    <limit lower="-2.9670597283903604" upper="2.9670597283903604" velocity="0.3" effort="10.0"/>"#;
    let e = err(&bad(
        from,
        &from.replace(r#"velocity="0.3""#, r#"velocity="0""#),
    ));
    assert!(matches!(&e, ModelError::InvalidVelocityLimit { joint, .. } if joint == "joint_1"));
    let e = err(&bad(
        from,
        &from.replace(r#"effort="10.0""#, r#"effort="-1""#),
    ));
    assert!(matches!(&e, ModelError::InvalidEffortLimit { joint, .. } if joint == "joint_1"));
}

#[test]
fn branch_is_not_a_serial_chain() {
    // joint_3 hangs on link1 (already carrying joint_2): branch
    let e = err(&bad(
        r#"<parent link="link2"/>
    <child link="link3"/>"#,
        r#"<parent link="link1"/>
    <child link="link3"/>"#,
    ));
    assert!(matches!(e, ModelError::NotSerialChain { .. }), "{e}");
}

#[test]
fn unknown_link_and_tree_errors() {
    let e = err(&bad(
        r#"<parent link="link6"/>"#,
        r#"<parent link="link66"/>"#,
    ));
    assert!(matches!(&e, ModelError::UnknownLink { link, .. } if link == "link66"));
    let e = err(&bad(
        r#"<link name="end_effector"/>"#,
        r#"<link name="end_effector"/><link name="stray"/>"#,
    ));
    assert!(matches!(e, ModelError::RootCount { count: 2, .. }));
}

#[test]
fn non_sphere_collision_and_bad_radius() {
    let e = err(&bad(
        r#"<geometry><sphere radius="0.60"/></geometry>"#,
        r#"<geometry><box size="1 1 1"/></geometry>"#,
    ));
    assert!(matches!(&e, ModelError::InvalidCollision { link, .. } if link == "base"));
    let e = err(&bad(
        r#"<geometry><sphere radius="0.60"/></geometry>"#,
        r#"<geometry><sphere radius="-0.60"/></geometry>"#,
    ));
    assert!(matches!(&e, ModelError::InvalidCollision { .. }));
}

#[test]
fn massless_arm_body() {
    let from = r#"<mass value="2.0"/>
      <inertia ixx="0.0025" ixy="0" ixz="0" iyy="0.0050" iyz="0.00003" izz="0.0051"/>"#;
    let e = err(&bad(
        from,
        r#"<mass value="0"/>
      <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>"#,
    ));
    assert!(matches!(&e, ModelError::MasslessBody { link, .. } if link == "link7"));
}

#[test]
fn non_finite_values() {
    let e = err(&bad(
        r#"<origin xyz="0.30 0 0" rpy="0 0 0"/>
    <parent link="link5"/>"#,
        r#"<origin xyz="NaN 0 0" rpy="0 0 0"/>
    <parent link="link5"/>"#,
    ));
    assert!(matches!(e, ModelError::NonFinite { .. }), "{e}");
}

#[test]
fn garbage_never_panics() {
    for s in [
        "",
        "not xml",
        "<robot/>",
        "<robot name='x'><link name='a'/></robot>",
        "<robot name='x'><joint name='j' type='revolute'><parent link='a'/><child link='b'/></joint></robot>",
        GOOD.get(..GOOD.len() / 2).unwrap_or(""),
    ] {
        assert!(Robot::from_urdf_str(s).is_err());
    }
    // truncations at many points must not panic either
    for cut in (0..GOOD.len()).step_by(997) {
        if let Some(s) = GOOD.get(..cut) {
            let _ = Robot::from_urdf_str(s);
        }
    }
}

#[test]
fn unnormalized_axis_is_normalized() {
    let from = r#"<child link="link3"/>
    <axis xyz="1 0 0"/>"#;
    let r2 = Robot::from_urdf_str(&bad(
        from,
        r#"<child link="link3"/>
    <axis xyz="3 0 0"/>"#,
    ))
    .unwrap();
    let r1 = Robot::from_urdf_str(GOOD).unwrap();
    let th = sc_multibody::Vector7::from_column_slice(&[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]);
    assert!((r1.mass_matrix(&th) - r2.mass_matrix(&th)).amax() < 1e-15);
}
